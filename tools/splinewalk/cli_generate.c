/* SPDX-License-Identifier: MIT */
/* splinewalk generate grid|building: test scenes (culling tests, huge architectural scenes). */
#include "cli.h"

#include "sw_hooks.h"
#include "sw_rt.h"
#include "sw_safe_write.h"
#include "sw_sg_export.h"
#include "sw_sg_generate.h"
#include "sw_sg_import.h"
#include "sw_status_util.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define DEFAULT_DATA "/usr/share/opencascade/data"

static const char k_usage[] =
    "usage: splinewalk generate grid --model M --count N -o OUT.sws [--spacing S] [--dims 2|3]\n"
    "       splinewalk generate building|vehicle --surfaces N [--seed S] -o OUT.sws\n"
    "                                    [--brep OUT.brep] [--data DIR]\n"
    "\n"
    "grid:\n"
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
    "\n"
    "building:\n"
    "Writes a procedural building of exactly N trimmed surfaces (face occurrences, instances\n"
    "expanded), in centimetres: storeys of 4 m x 4 m rooms with floor and ceiling slabs (the "
    "stair\n"
    "room's cut by the stairwell), walls of two planar faces trimmed by window holes (rectangular\n"
    "or arched) and door notches (rectangular or arched, with their reveals), columns (exact\n"
    "rational cylinders), a stair per storey (one prototype, instanced), roofs with domes (exact\n"
    "rational spheres) and barrel vaults, furnished with instances of OCCT's sample models\n"
    "(MODERN_*.brep, Motor-c.brep, CrankArm.brep, Pump_Nut.brep), each imported once. Furniture "
    "is\n"
    "placed while the occurrences drawn through instances stay within 3 x the unique faces, so\n"
    "about a quarter of the faces are unique (25-29 % measured for N = 10^4..10^6; the stairs are\n"
    "instanced outside that budget); bollards in front of the facade make up the exact count. The "
    "same N and seed give the same file, byte for byte. Both outputs are written to\n"
    "temporary names, then renamed: a failed run leaves nothing behind.\n"
    "\n"
    "vehicle:\n"
    "The same for a parking lot of cars, in millimetres: each car unique, its body of lofted\n"
    "bicubic B-spline panels (rear quarter, doors, front fender per side, cut apart by door gaps,\n"
    "trimmed by exact wheel arches; a cabin side trimmed by its windows; roof with or without a\n"
    "sunroof, windscreen, rear window, bonnet, boot lid, bumpers), four instances of one wheel\n"
    "(exact rational tyre and hub, a disc trimmed by circles), and under some bonnets instances "
    "of\n"
    "Motor-c.brep, CrankArm.brep and Pump_Nut.brep (within the same 3 x budget). Parking bollards\n"
    "make up the exact count.\n"
    "\n"
    "options:\n"
    "  --surfaces N        face occurrences, 100..10000000 (10^7: about 2.5 million unique faces)\n"
    "  --seed S            the random seed, an unsigned 64-bit integer (default 1)\n"
    "  -o, --output FILE   the .sws file to write (required)\n"
    "  --brep FILE         also write the scene as an OCCT BREP compound (instances share their\n"
    "                      TShape), which `splinewalk import` and OCCT-based programs read\n"
    "  --data DIR          the OCCT sample-data folder holding occ/MODERN_Chair_1.brep,\n"
    "                      occ/Motor-c.brep and the other models; a .sws of the same name\n"
    "                      (occ/Motor-c.sws, the imported file) is read instead where present,\n"
    "                      and is all a build without the import module reads (default: a\n"
    "                      bundle's share/splinewalk/data beside its bin/, else\n"
    "                      " DEFAULT_DATA ", Debian's occt-misc)\n"
    "  -h, --help          this text\n";

typedef struct gen_args {
    const char *kind, *model, *out, *brep, *data;
    int count, dims, surfaces;
    double spacing;
    unsigned long long seed;
} gen_args;

/* Numbers for one option; returns nonzero for a bad value. */
static int parse_value(const char *arg, const char *val, gen_args *a)
{
    if (!strcmp(arg, "--count"))
        return sw_cli_parse_count(val, 1, SW_SG_GRID_MAX_COUNT, &a->count);
    if (!strcmp(arg, "--dims"))
        return sw_cli_parse_count(val, 2, 3, &a->dims);
    if (!strcmp(arg, "--surfaces"))
        return sw_cli_parse_count(val, SW_SG_BUILDING_MIN_SURFACES, SW_SG_BUILDING_MAX_SURFACES,
                                  &a->surfaces);
    if (!strcmp(arg, "--seed"))
        return sw_cli_parse_seed(val, &a->seed);
    return sw_cli_parse_positive(val, &a->spacing);
}

static const char *value_hint(const char *arg)
{
    if (!strcmp(arg, "--count"))
        return " (an integer in 1..10000000)";
    if (!strcmp(arg, "--surfaces"))
        return " (an integer in 100..10000000)";
    if (!strcmp(arg, "--seed"))
        return " (an unsigned 64-bit integer)";
    return "";
}

static int is_number_option(const char *arg)
{
    return !strcmp(arg, "--count") || !strcmp(arg, "--dims") || !strcmp(arg, "--spacing") ||
           !strcmp(arg, "--surfaces") || !strcmp(arg, "--seed");
}

/* What the generator named in a->kind needs. */
static int check_args(const gen_args *a)
{
    const int grid = !strcmp(a->kind, "grid");
    const int building = !strcmp(a->kind, "building") || !strcmp(a->kind, "vehicle");
    if (!grid && !building) {
        fprintf(stderr, "splinewalk generate: unknown generator '%s' (grid, building, vehicle)\n%s",
                a->kind, k_usage);
        return 2;
    }
    if (grid && (!a->model || !a->count || !a->out)) {
        fprintf(stderr, "splinewalk generate: need grid, --model M, --count N and -o OUT.sws\n%s",
                k_usage);
        return 2;
    }
    if (building && (!a->surfaces || !a->out)) {
        fprintf(stderr, "splinewalk generate: need %s, --surfaces N and -o OUT.sws\n%s", a->kind,
                k_usage);
        return 2;
    }
    if ((grid && (a->surfaces || a->brep || a->data || a->seed != 1)) ||
        (building && (a->model || a->count || a->spacing > 0.0))) {
        fprintf(stderr, "splinewalk generate: an option of the other generator given to %s\n%s",
                a->kind, k_usage);
        return 2;
    }
#if !SW_CLI_IMPORT
    if (a->brep) {
        fprintf(stderr,
                "splinewalk generate: --brep writes through OpenCASCADE, and this build has "
                "no import module\n");
        return 2;
    }
#endif
    return 0;
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
        } else if (!strcmp(arg, "--brep") && val) {
            a->brep = val;
        } else if (!strcmp(arg, "--data") && val) {
            a->data = val;
        } else if (is_number_option(arg) && val) {
            if (parse_value(arg, val, a)) {
                fprintf(stderr, "splinewalk generate: bad value '%s' for %s%s\n%s", val, arg,
                        value_hint(arg), k_usage);
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
    if (!a->kind) {
        fprintf(stderr, "splinewalk generate: need a generator (grid, building, vehicle)\n%s",
                k_usage);
        return 2;
    }
    return check_args(a);
}

/* Progress only once the run has taken a second, or before a write that will (the .sws writer
 * reports none; ~280 MB/s measured here): small grids stay quiet. */
typedef struct quiet_progress {
    double t0;
    int on;
} quiet_progress;

enum { SLOW_WRITE_BYTES = 256 << 20, SLOW_BREP_BYTES = 16 << 20 };

static void progress(void *user_data, double fraction, const char *stage)
{
    quiet_progress *q = user_data;
    q->on = q->on || sw__clock_ms() - q->t0 > 1000.0;
    if (q->on)
        sw_cli_progress(NULL, fraction, stage);
}

/* Generates and writes the grid of an acquired model. */
static sw_result write_grid(const gen_args *a, const sw_rt_scene *model, sw_sg_grid_report *rep,
                            double ms[2], sw_status *status)
{
    quiet_progress q = {sw__clock_ms(), 0};
    sw_sg_grid_desc d = {(uint32_t)a->count, a->dims, a->spacing, progress, &q};
    sw_sg_scene *grid = NULL;
    sw_result r = sw_sg_generate_grid(model->sg, &d, &grid, rep, status);
    const double t1 = sw__clock_ms();
    if (r == SW_OK) {
        q.on = q.on || sw_sg_scene_memory(grid) >= SLOW_WRITE_BYTES;
        progress(&q, 1.0, "writing");
        r = sw_sg_scene_save(grid, a->out, status);
    }
    sw_cli_progress_end();
    sw_sg_scene_free(grid);
    ms[0] = t1 - q.t0;
    ms[1] = sw__clock_ms() - t1;
    return r;
}

/* ---- building ------------------------------------------------------------------------------ */

/* A sample model: a .sws of the same name beside where the OCCT file would be (occ/Motor-c.sws
 * for occ/Motor-c.brep; scripts/bundle ships the parts so, for a build without the import
 * module), else the OCCT file itself through the installed importer. A .sws written by
 * `splinewalk import` holds the imported scene itself, so either way the generated scene is the
 * same, byte for byte. */
static sw_result load_model(const char *data, const char *file, sw_sg_scene **model,
                            sw_status *status)
{
    char path[4096], sws[4096];
    struct stat sb;
    const int n = snprintf(path, sizeof path, "%s/%s", data, file);
    if (n < 0 || (size_t)n >= sizeof path)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: the folder's name is too long", data);
    const char *dot = strrchr(path, '.');
    const int m = snprintf(sws, sizeof sws, "%.*s.sws",
                           (int)(dot ? dot - path : (ptrdiff_t)strlen(path)), path);
    if (m > 0 && (size_t)m < sizeof sws && stat(sws, &sb) == 0 && S_ISREG(sb.st_mode))
        return sw_sg_scene_open(sws, model, status);
    if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode)) {
        sw_sg_import_desc d = {path, NULL, sw_cli_warning, NULL, NULL, 0};
        return sw_sg_cad_import_file(&d, model, NULL, status);
    }
    return sw__fail(status, SW_ERR_NOT_FOUND,
                    "%s: no such file (nor %s): the models come from the OCCT sample data "
                    "(Debian's occt-misc); give its folder with --data DIR",
                    path, sws);
}

/* Loads the models, each once. */
static sw_result load_models(const char *data, const char *const *files, int n,
                             sw_sg_scene **models, sw_status *status)
{
    for (int m = 0; m < n; ++m) {
        sw_result r = load_model(data, files[m], &models[m], status);
        if (r != SW_OK)
            return r;
    }
    return SW_OK;
}

/* The sample-data folder when --data is not given: the one a bundle ships (share/splinewalk/data:
 * the parts as .sws, see scripts/bundle), else Debian's. */
static const char *default_data(char *buf, size_t size)
{
    const char *bundled = sw_cli_bundle_path("data", buf, size);
    return bundled ? bundled : DEFAULT_DATA;
}

/* The BREP is built in memory first (an OCCT refusal leaves both outputs untouched) and written
 * once the .sws is, both through the project's one writer (sw_safe_write.h). */
static sw_result write_building(const gen_args *a, sw_sg_scene *scene, double *ms_write,
                                sw_sg_export_report *er, sw_status *status)
{
    const double t0 = sw__clock_ms();
    char *brep = NULL;
    size_t brep_len = 0;
#if SW_CLI_IMPORT
    sw_result r = a->brep ? sw_sg_export_brep_text(scene, &brep, &brep_len, er, status) : SW_OK;
#else
    (void)er; /* check_args refused --brep */
    sw_result r = SW_OK;
#endif
    if (r == SW_OK)
        r = sw_sg_scene_save(scene, a->out, status);
    if (r == SW_OK && a->brep)
        r = sw__write_file(a->brep, brep, brep_len, 0, status);
    sw__free(brep);
    *ms_write = sw__clock_ms() - t0;
    return r;
}

static void print_building(const gen_args *a, const sw_sg_building_report *rep)
{
    printf("%s: building of %llu surfaces, %llu unique faces (%.1f %%), %u storeys of %ux%u rooms, "
           "%u rooms (%u furnished), %llu instances, %u domes, %u vaults, %u columns, %u windows, "
           "%u doors, %u arches, %u stairs, %u bollards",
           a->out, (unsigned long long)rep->occurrences, (unsigned long long)rep->unique_faces,
           100.0 * (double)rep->unique_faces / (double)rep->occurrences, rep->floors, rep->nx,
           rep->ny, rep->rooms, rep->furnished, (unsigned long long)rep->instances, rep->domes,
           rep->vaults, rep->columns, rep->windows, rep->doors, rep->arches, rep->stairs,
           rep->bollards);
}

static void print_vehicle(const gen_args *a, const sw_sg_vehicle_report *rep)
{
    printf("%s: %u cars of %llu surfaces, %llu unique faces (%.1f %%), %llu instances, %u with "
           "an engine, %u panels, %u wheel arches, %u windows, %u door gaps, %u bollards",
           a->out, rep->vehicles, (unsigned long long)rep->occurrences,
           (unsigned long long)rep->unique_faces,
           100.0 * (double)rep->unique_faces / (double)rep->occurrences,
           (unsigned long long)rep->instances, rep->with_engine, rep->panels, rep->arches,
           rep->windows, rep->gaps, rep->bollards);
}

/* building or vehicle: models, generation, the outputs. */
static int generate_scene(const gen_args *a)
{
    const int vehicle = !strcmp(a->kind, "vehicle");
    const int n = vehicle ? SW_SG_VEHICLE_N_MODELS : SW_SG_BUILDING_N_MODELS;
    sw_status status = {0};
    sw_sg_scene *models[SW_SG_BUILDING_N_MODELS] = {0};
    const double t0 = sw__clock_ms();
    char bundled[4096];
    sw_result r = load_models(a->data ? a->data : default_data(bundled, sizeof bundled),
                              vehicle ? sw_sg_vehicle_model_files : sw_sg_building_model_files, n,
                              models, &status);
    const double t1 = sw__clock_ms();
    quiet_progress q = {t1, 0};
    sw_sg_building_report brep;
    sw_sg_vehicle_report vrep;
    sw_sg_export_report er = {0, 0};
    sw_sg_scene *scene = NULL;
    double ms_write = 0.0;
    if (r == SW_OK && vehicle) {
        sw_sg_vehicle_desc d = {(uint64_t)a->surfaces, a->seed, (const sw_sg_scene *const *)models,
                                progress, &q};
        r = sw_sg_generate_vehicle(&d, &scene, &vrep, &status);
    } else if (r == SW_OK) {
        sw_sg_building_desc d = {(uint64_t)a->surfaces, a->seed, (const sw_sg_scene *const *)models,
                                 progress, &q};
        r = sw_sg_generate_building(&d, &scene, &brep, &status);
    }
    const double t2 = sw__clock_ms();
    if (r == SW_OK) {
        /* the BREP writer runs at ~11 MB of scene a second here */
        q.on = q.on || sw_sg_scene_memory(scene) >= (a->brep ? SLOW_BREP_BYTES : SLOW_WRITE_BYTES);
        progress(&q, 1.0, "writing");
        r = write_building(a, scene, &ms_write, &er, &status);
    }
    sw_cli_progress_end();
    const size_t bytes = scene ? sw_sg_scene_memory(scene) : 0;
    sw_sg_scene_free(scene);
    for (int m = 0; m < n; ++m)
        sw_sg_scene_free(models[m]);
    if (r != SW_OK)
        return sw_cli_report("generate", &status);
    if (vehicle)
        print_vehicle(a, &vrep);
    else
        print_building(a, &brep);
    printf("; %.0f MB in memory; load models %.0f ms, generate %.0f ms, write %.0f ms\n",
           (double)bytes / 1e6, t1 - t0, t2 - t1, ms_write);
    if (a->brep)
        printf("%s: %u faces, %llu face occurrences\n", a->brep, er.faces,
               (unsigned long long)er.occurrences);
    return 0;
}

int sw_cli_generate(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    gen_args a = {0};
    a.dims = 3;
    a.seed = 1;
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc;
    if (sw_cli_check_output("generate", a.out, 0) ||
        (a.brep && sw_cli_check_output("generate", a.brep, 0)))
        return 1;
    if (strcmp(a.kind, "grid") != 0)
        return generate_scene(&a);

    sw_status status = {0};
    sw_scene scene;
    if (sw_cli_load_scene(a.model, 0, &scene, &status) != SW_OK)
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
