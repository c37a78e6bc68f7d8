/* SPDX-License-Identifier: MIT */
/* splinewalk: the command-line runtime. */
#include "cli.h"

#include <stdio.h>
#include <string.h>

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} command;

static const command k_commands[] = {
    {"import", sw_cli_import, "import STEP / IGES / BREP into a .sws scene file"},
    {"info", sw_cli_info, "describe a scene (surfaces, trims, patches, memory)"},
    {"outline", sw_cli_outline, "place filled outlines (SVG path data) into a scene"},
    {"render", sw_cli_render, "render one converged frame headlessly to PNG / EXR"},
    {"path", sw_cli_path, "write a camera path (orbit or fly-through) fitted to a scene"},
    {"profile", sw_cli_profile, "time frames along a camera path: CSV, JSON, SVG, HTML report"},
#if SW_CLI_VIEW
    {"view", sw_cli_view, "walk through a scene in a window (WASD, mouse; needs a display)"},
#endif
    {"generate", sw_cli_generate, "write a test scene: a grid of instances, or a building"},
    {"build-lod", sw_cli_build_lod,
     "build the static LODs of a scene's super-surfaces into its .sws"},
    {"demo", sw_cli_demo, "build and render the built-in default scene"},
#if SW_CLI_CHECK_OSD
    {"check-osd", sw_cli_check_osd, "cross-check uniform bicubic regions against OpenSubdiv"},
#endif
};

/* Commands a build may leave out, and what brings them back. */
static const char *const k_left_out[][2] = {
    {"view", "GLFW (configure with -DSW_WITH_VIEWER=ON)"},
    {"check-osd", "OpenSubdiv and every module (the full build)"},
};

static void usage(FILE *out)
{
    fprintf(out, "usage: splinewalk COMMAND [ARGS]   (splinewalk COMMAND --help for details)\n\n"
                 "commands:\n");
    for (size_t i = 0; i < sizeof k_commands / sizeof k_commands[0]; i++)
        fprintf(out, "  %-10s %s\n", k_commands[i].name, k_commands[i].summary);
    fprintf(out, "\nsplinewalk %s — walk through huge trimmed-NURBS CAD models\n",
            SW_VERSION_STRING);
}

int main(int argc, char **argv)
{
    sw_cli_keep_freed_memory();
    sw_cli_install_modules();
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (sw_cli_is_help(argv[1])) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("splinewalk %s\n", SW_VERSION_STRING);
        return 0;
    }
    for (size_t i = 0; i < sizeof k_commands / sizeof k_commands[0]; i++) {
        if (!strcmp(argv[1], k_commands[i].name))
            return k_commands[i].run(argc - 1, argv + 1);
    }
    for (size_t i = 0; i < sizeof k_left_out / sizeof k_left_out[0]; i++) {
        if (!strcmp(argv[1], k_left_out[i][0])) {
            fprintf(stderr, "splinewalk: '%s' is not in this build: it needs %s\n", argv[1],
                    k_left_out[i][1]);
            return 2;
        }
    }
    fprintf(stderr, "splinewalk: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return 2;
}
