/* skysweep COMMAND [options] INPUT... OUTPUT */
#include "config.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "commands.h"
#include "mpi_share.h"
#include "run.h"
#include "scene.h"
#include "skysweep.h"

static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
    int shares; /* runs shared between MPI processes (mpi_share.h) */
} commands[] = {
    {"horizon", cmd_horizon, "horizon elevation angle per azimuth (one band each)", 0},
    {"svf", cmd_svf, "sky-view factor (geometric, radiative or horizontal)", 1},
    {"openness", cmd_openness, "positive or negative topographic openness (degrees)", 1},
    {"hillshade", cmd_hillshade, "gdaldem-compatible hillshade, with cast shadows and sky view", 0},
    {"insolation", cmd_insolation, "clear-sky beam, diffuse, reflected irradiation, hours of sun", 1},
    {"roofs", cmd_roofs, "solar cadastre: roof planes and PV yield per roof and building (GeoPackage)", 0},
    {"shadow", cmd_shadow, "cast shadows and self-shadow for one sun (exact sweep)", 0},
    {"render", cmd_render, "3D picture of the DEM, draped with a product; .vts for ParaView", 0},
    {"quicklook", cmd_quicklook, "PNG of one band of a product through a colour map", 0},
    {"sun", cmd_sun, "sun position (NREL SPA) for a place and a time or a time range", 0},
    {"weather", cmd_weather, "the records of a weather file (EPW, TMY3, PVGIS, PSM, CSV) as read", 0},
    {"plan", NULL, "what a scene needs: effects on/off with reason and error bound, cost", 0},
    {"run", NULL, "run the job a scene file describes", 0},
    {"info", cmd_info, "version, dependencies, devices, kernel build status", 0},
};

/* Runs command i, unless several MPI processes would each do all of it. */
static int run_command(size_t i, int argc, char **argv)
{
    if (share_size() > 1 && !commands[i].shares) {
        if (share_rank() == 0)
            fprintf(stderr,
                    "skysweep %s: runs in one process; under mpirun only svf and openness "
                    "share their work (%d processes were started)\n",
                    commands[i].name, share_size());
        return SS_ERR_ARGUMENT;
    }
    return commands[i].run(argc, argv);
}

/* skysweep plan|run SCENE [options]: the scene's product command with
 * --scene SCENE (and --plan). */
static int scene_command(const char *verb, int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("Usage: skysweep %s SCENE [options]\n\n%s the job a scene file describes: an INI "
               "file whose keys are the options of\nits product's command (doc/scenes.md). "
               "Options given after SCENE override the scene's;\nskysweep PRODUCT --help lists "
               "them.\n",
               verb, strcmp(verb, "plan") == 0 ? "Plans (and writes nothing for)" : "Runs");
        return 0;
    }
    if (argc < 2 || argv[1][0] == '-') {
        fprintf(stderr, "skysweep %s: needs a scene file (skysweep %s SCENE [options])\n", verb,
                verb);
        return SS_ERR_ARGUMENT;
    }
    char product[32], err[400];
    if (scene_product(argv[1], product, sizeof product, err, sizeof err) != 0) {
        fprintf(stderr, "skysweep %s: %s\n", verb, err);
        return SS_ERR_ARGUMENT;
    }
    char *args[COMMAND_MAX_INPUTS + 8];
    int n = 0;
    args[n++] = product;
    args[n++] = "--scene";
    args[n++] = argv[1];
    if (strcmp(verb, "plan") == 0)
        args[n++] = "--plan";
    for (int i = 2; i < argc && n < COMMAND_MAX_INPUTS + 7; ++i)
        args[n++] = argv[i];
    args[n] = NULL;
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        if (commands[i].run && strcmp(product, commands[i].name) == 0 &&
            strcmp(product, "sun") && strcmp(product, "info"))
            return run_command(i, n, args);
    fprintf(stderr, "skysweep %s: %s: unknown product '%s'\n", verb, argv[1], product);
    return SS_ERR_ARGUMENT;
}

static void usage(FILE *to)
{
    fprintf(to, "Usage: skysweep COMMAND [options] INPUT... OUTPUT\n\nCommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        fprintf(to, "  %-9s %s\n", commands[i].name, commands[i].summary);
    fprintf(to, "\nskysweep COMMAND --help lists a command's options. Azimuths are degrees "
                "clockwise from north.\n");
}

/* skysweep(1): the commands, from the same table as --help; each has its
 * own page, skysweep-COMMAND(1), from its option tables. */
static void man_page(void)
{
    printf(".TH SKYSWEEP 1 \"\" \"skysweep %s\" \"skysweep manual\"\n", ss_version());
    printf(".SH NAME\nskysweep \\- terrain horizons, sky-view factor, shadows, hillshade and "
           "insolation from DEMs\n");
    printf(".SH SYNOPSIS\n.B skysweep\n.I COMMAND\n[options]\n.I INPUT... OUTPUT\n");
    printf(".SH DESCRIPTION\nskysweep computes exact terrain horizons with a convex-hull "
           "sweep along parallel lines, and the products that follow from them. Azimuths are "
           "degrees clockwise from north.\n.SH COMMANDS\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i) {
        printf(".TP\n.B %s\n", commands[i].name);
        for (const char *c = commands[i].summary; *c; ++c)
            fputs(*c == '-' ? "\\-" : (char[2]){*c, 0}, stdout);
        printf("\n");
    }
    printf(".SH SEE ALSO\n");
    for (size_t i = 0, first = 1; i < sizeof commands / sizeof commands[0]; ++i)
        if (commands[i].run) {
            printf("%s.BR skysweep\\-%s (1)", first ? "" : ",\n", commands[i].name);
            first = 0;
        }
    printf("\n");
}

static int dispatch(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return SS_ERR_ARGUMENT;
    }
    const char *name = argv[1];
    if (strcmp(name, "--help") == 0 || strcmp(name, "-h") == 0 || strcmp(name, "help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(name, "--help-man") == 0) {
        man_page();
        return 0;
    }
    if (strcmp(name, "--help-commands") == 0) { /* for doc/completion.sh */
        for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
            printf("%s%s", i ? " " : "", commands[i].name);
        printf("\n");
        return 0;
    }
    if (strcmp(name, "--version") == 0 || strcmp(name, "version") == 0) {
        printf("skysweep %s\n", ss_version());
        return 0;
    }
    if (strcmp(name, "plan") == 0 || strcmp(name, "run") == 0)
        return scene_command(name, argc - 1, argv + 1);
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        if (strcmp(name, commands[i].name) == 0)
            return run_command(i, argc - 1, argv + 1);
    fprintf(stderr, "skysweep: unknown command '%s' (see skysweep --help)\n", name);
    return SS_ERR_ARGUMENT;
}

int main(int argc, char **argv)
{
    int rc = share_start(&argc, &argv);
    if (rc)
        return rc;
    rc = dispatch(argc, argv);
    scene_release();
    share_stop();
    if (run_interrupted()) {
        /* A signal may have left the OpenCL kernels building in a thread
         * of their own (src/core/ocl_build.c): the libraries' exit handlers
         * and destructors must not run under PoCL's compiler. The outputs
         * are already cleaned up. */
        fflush(NULL);
        _exit(rc);
    }
    return rc;
}
