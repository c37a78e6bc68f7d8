/* splinewalk generate grid --model M --count N -o OUT.sws: test scenes for the culling tests. */
#include "cli.h"

#include "sw_rt.h"
#include "sw_sg_generate.h"

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk generate grid --model M --count N -o OUT.sws [--spacing S] [--dims 2|3]\n"
    "\n"
    "Writes a test scene (Kumar et al. 1997 §4.4 culling tests): N instances of the model M (any\n"
    "file `splinewalk import` reads, or a .sws) on a grid. The instances share the model's\n"
    "geometry: its faces are stored once and each instance is an instance node with a\n"
    "translation. The grid is nearly cubic (nx x ny x nz, cells filled x first, then y, then z;\n"
    "only the top layer is partial) or, with --dims 2, nearly square in the XY plane. OUT.sws is\n"
    "written to a temporary name, then renamed: a failed run leaves nothing behind. Progress is\n"
    "drawn on stderr when the run takes more than a second.\n"
    "\n"
    "options:\n"
    "  --model M           the model to repeat (required)\n"
    "  --count N           instances, 1..10000000 (required); the grid may also hold at most\n"
    "                      2^31 - 1 face occurrences (N x the model's), what the BVH holds\n"
    "  -o, --output FILE   the .sws file to write (required)\n"
    "  --spacing S         centre-to-centre distance on every axis, in model units (default: per\n"
    "                      axis the model's control-net box extent plus a quarter of its largest\n"
    "                      extent, so that neighbours never overlap)\n"
    "  --dims 2|3          a 3D grid (default) or a 2D one\n"
    "  -h, --help          this text\n";

typedef struct gen_args {
    const char *kind, *model, *out;
    int count, dims;
    double spacing;
} gen_args;

/* Numbers for one option; returns nonzero for a bad value. */
static int parse_value(const char *arg, const char *val, gen_args *a)
{
    if (!strcmp(arg, "--count"))
        return sw_cli_parse_count(val, 1, SW_SG_GRID_MAX_COUNT, &a->count);
    if (!strcmp(arg, "--dims"))
        return sw_cli_parse_count(val, 2, 3, &a->dims);
    return sw_cli_parse_positive(val, &a->spacing);
}

static int parse_args(int argc, char **argv, gen_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if ((!strcmp(arg, "-o") || !strcmp(arg, "--output")) && val) {
            a->out = val;
        } else if (!strcmp(arg, "--model") && val) {
            a->model = val;
        } else if ((!strcmp(arg, "--count") || !strcmp(arg, "--dims") ||
                    !strcmp(arg, "--spacing")) &&
                   val) {
            if (parse_value(arg, val, a)) {
                fprintf(stderr, "splinewalk generate: bad value '%s' for %s%s\n%s", val, arg,
                        !strcmp(arg, "--count") ? " (an integer in 1..10000000)" : "", k_usage);
                return 2;
            }
        } else if (arg[0] != '-' && !a->kind) {
            a->kind = arg;
            continue;
        } else {
            fprintf(stderr, "splinewalk generate: unexpected argument '%s'\n%s", arg, k_usage);
            return 2;
        }
        i++;
    }
    if (!a->kind || !a->model || !a->count || !a->out) {
        fprintf(stderr, "splinewalk generate: need grid, --model M, --count N and -o OUT.sws\n%s",
                k_usage);
        return 2;
    }
    if (strcmp(a->kind, "grid") != 0) {
        fprintf(stderr, "splinewalk generate: unknown generator '%s' (grid)\n%s", a->kind, k_usage);
        return 2;
    }
    return 0;
}

/* Progress only once the run has taken a second, or before a write that will (the .sws writer
 * reports none; ~280 MB/s measured here): small grids stay quiet. */
typedef struct quiet_progress {
    double t0;
    int on;
} quiet_progress;

enum { SLOW_WRITE_BYTES = 256 << 20 };

static void progress(void *user_data, double fraction, const char *stage)
{
    quiet_progress *q = user_data;
    q->on = q->on || sw_cli_now_ms() - q->t0 > 1000.0;
    if (q->on)
        sw_cli_progress(NULL, fraction, stage);
}

/* Generates and writes the grid of an acquired model. */
static sw_result write_grid(const gen_args *a, const sw_rt_scene *model, sw_sg_grid_report *rep,
                            double ms[2], sw_status *status)
{
    quiet_progress q = {sw_cli_now_ms(), 0};
    sw_sg_grid_desc d = {(uint32_t)a->count, a->dims, a->spacing, progress, &q};
    sw_sg_scene *grid = NULL;
    sw_result r = sw_sg_generate_grid(model->sg, &d, &grid, rep, status);
    const double t1 = sw_cli_now_ms();
    if (r == SW_OK) {
        q.on = q.on || sw_sg_scene_memory(grid) >= SLOW_WRITE_BYTES;
        progress(&q, 1.0, "writing");
        r = sw_sg_scene_save(grid, a->out, status);
    }
    sw_cli_progress_end();
    sw_sg_scene_free(grid);
    ms[0] = t1 - q.t0;
    ms[1] = sw_cli_now_ms() - t1;
    return r;
}

int sw_cli_generate(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    gen_args a = {0};
    a.dims = 3;
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc;

    sw_status status = {0};
    sw_scene scene;
    if (sw_cli_load_scene(a.model, &scene, &status) != SW_OK)
        return sw_cli_report("generate", &status);
    sw_rt_scene *model = NULL;
    sw_sg_grid_report rep;
    double ms[2] = {0.0, 0.0};
    sw_result r = sw_rt_scene_acquire(scene, &model, &status);
    if (r == SW_OK) {
        r = write_grid(&a, model, &rep, ms, &status);
        sw_rt_scene_release(model);
    }
    sw_scene_destroy(scene);
    if (r != SW_OK)
        return sw_cli_report("generate", &status);
    printf("%s: %d instances of %s on a %ux%ux%u grid (spacing %g, %g, %g), %llu face "
           "occurrences; generate %.0f ms, write %.0f ms\n",
           a.out, a.count, a.model, rep.nx, rep.ny, rep.nz, rep.spacing[0], rep.spacing[1],
           rep.spacing[2], (unsigned long long)rep.occurrences, ms[0], ms[1]);
    return 0;
}
