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
#include "skysweep_products.h"

typedef struct {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary; /* NULL: a product's, from the registry */
} command_entry;

/* The commands that have a file of their own; a product's summary and whether it shares its
 * run between MPI processes (mpi_share.h) are the registry's
 * (skysweep_products.h). */
static const command_entry commands[] = {
    {"horizon", cmd_horizon, NULL},
    {"svf", cmd_sky, NULL},
    {"openness", cmd_sky, NULL},
    {"hillshade", cmd_hillshade, NULL},
    {"insolation", cmd_insolation, NULL},
    {"roofs", cmd_roofs, "solar cadastre: roof planes and PV yield per roof and building (GeoPackage)"},
    {"shadow", cmd_shadow, NULL},
    {"canopy", cmd_canopy, "a buildings-and-ground DSM and a tree CDSM from a lidar DSM, a DTM and footprints"},
    {"render", cmd_render, "3D picture of the DEM, draped with a product; .vts for ParaView"},
    {"quicklook", cmd_quicklook, "PNG of one band of a product through a colour map"},
    {"sun", cmd_sun, "sun position (NREL SPA) for a place and a time or a time range"},
    {"weather", cmd_weather, "the records of a weather file (EPW, TMY3, PVGIS, PSM, CSV) as read"},
    {"plan", NULL, "what a scene needs: effects on/off with reason and error bound, cost"},
    {"run", NULL, "run the job a scene file describes"},
    {"info", cmd_info, "version, dependencies, devices, kernel build status"},
};

#define WRITTEN (sizeof commands / sizeof commands[0])
/* Those, then each registry product with a run call and no command written
 * for it, which cmd_product runs from its entry alone (listed_gather). */
static command_entry listed[WRITTEN + 16];
static size_t n_listed;

static int written_for(const char *name)
{
    for (size_t i = 0; i < WRITTEN; ++i)
        if (strcmp(commands[i].name, name) == 0)
            return 1;
    return 0;
}

static void listed_gather(void)
{
    for (n_listed = 0; n_listed < WRITTEN; ++n_listed)
        listed[n_listed] = commands[n_listed];
    for (int k = 0; k < ss_product_count() && n_listed < sizeof listed / sizeof listed[0]; ++k) {
        const ss_product_info *p = ss_product_at(k);
        if (p->run && !written_for(p->name))
            listed[n_listed++] = (command_entry){p->name, cmd_product, NULL};
    }
}

static const char *command_summary(size_t i)
{
    return listed[i].summary ? listed[i].summary : ss_product_named(listed[i].name)->summary;
}

/* "svf, openness, insolation": the products that share their runs. */
static void sharing_products(char *buf, size_t size)
{
    size_t n = 0;
    buf[0] = '\0';
    for (int k = 0; k < ss_product_count() && n < size; ++k)
        if (ss_product_at(k)->shares)
            n += (size_t)snprintf(buf + n, size - n, "%s%s", n ? ", " : "",
                                  ss_product_at(k)->name);
}

/* Runs command i, unless several MPI processes would each do all of it
 * (roofs shares its insolation run's steps; its own stage is rank 0's). */
static int run_command(size_t i, int argc, char **argv)
{
    const ss_product_info *product = ss_product_named(listed[i].name);
    int shares = (product && product->shares) || strcmp(listed[i].name, "roofs") == 0;
    if (share_size() > 1 && !shares) {
        char sharing[128];
        sharing_products(sharing, sizeof sharing);
        if (share_rank() == 0)
            fprintf(stderr,
                    "skysweep %s: runs in one process; under mpirun only %s share their work "
                    "(%d processes were started)\n",
                    listed[i].name, sharing, share_size());
        return SS_ERR_ARGUMENT;
    }
    return listed[i].run(argc, argv);
}

/* skysweep plan|run SCENE [options]: the scene's product command with
 * --scene SCENE (and --plan). */
static int scene_command(const char *verb, int argc, char **argv)
{
    char usage[64], description[400];
    snprintf(usage, sizeof usage, "skysweep %s SCENE [options]", verb);
    snprintf(description, sizeof description,
             "%s the job a scene file describes: an INI file whose keys are the options of\nits "
             "product's command (doc/scenes.md). Options given after SCENE override the "
             "scene's;\nskysweep PRODUCT --help lists them.",
             strcmp(verb, "plan") == 0 ? "Plans (and writes nothing for)" : "Runs");
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("Usage: %s\n\n%s\n", usage, description);
        return 0;
    }
    if (argc == 2 && strcmp(argv[1], "--help-man") == 0) { /* its options are its product's */
        const opt_spec *none[] = {NULL};
        opt_print_man(none, verb, usage, description, ss_version());
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
    for (size_t i = 0; i < n_listed; ++i)
        if (listed[i].run && strcmp(product, listed[i].name) == 0 &&
            strcmp(product, "sun") && strcmp(product, "info"))
            return run_command(i, n, args);
    fprintf(stderr, "skysweep %s: %s: unknown product '%s'\n", verb, argv[1], product);
    return SS_ERR_ARGUMENT;
}

static void usage(FILE *to)
{
    fprintf(to, "Usage: skysweep COMMAND [options] INPUT... OUTPUT\n\nCommands:\n");
    for (size_t i = 0; i < n_listed; ++i)
        fprintf(to, "  %-9s %s\n", listed[i].name, command_summary(i));
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
    for (size_t i = 0; i < n_listed; ++i) {
        printf(".TP\n.B %s\n", listed[i].name);
        for (const char *c = command_summary(i); *c; ++c)
            fputs(*c == '-' ? "\\-" : (char[2]){*c, 0}, stdout);
        printf("\n");
    }
    printf(".SH SEE ALSO\n");
    for (size_t i = 0; i < n_listed; ++i)
        printf("%s.BR skysweep\\-%s (1)", i ? ",\n" : "", listed[i].name);
    printf("\n");
}

static int dispatch(int argc, char **argv)
{
    listed_gather();
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
        for (size_t i = 0; i < n_listed; ++i)
            printf("%s%s", i ? " " : "", listed[i].name);
        printf("\n");
        return 0;
    }
    if (strcmp(name, "--version") == 0 || strcmp(name, "version") == 0) {
        printf("skysweep %s\n", ss_version());
        return 0;
    }
    if (strcmp(name, "plan") == 0 || strcmp(name, "run") == 0)
        return scene_command(name, argc - 1, argv + 1);
    for (size_t i = 0; i < n_listed; ++i)
        if (strcmp(name, listed[i].name) == 0)
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
