/* skysweep COMMAND [options] INPUT... OUTPUT */
#include "config.h"

#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "skysweep.h"

static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} commands[] = {
    {"horizon", cmd_horizon, "horizon elevation angle per azimuth (one band each)"},
    {"svf", cmd_svf, "sky-view factor (geometric, radiative or horizontal)"},
    {"hillshade", cmd_hillshade, "gdaldem-compatible hillshade, with cast shadows and sky view"},
    {"insolation", cmd_insolation, "clear-sky beam, diffuse, reflected irradiation, hours of sun"},
    {"shadow", cmd_shadow, "cast shadows and self-shadow for one sun (exact sweep)"},
    {"sun", cmd_sun, "sun position (NREL SPA) for a place and a time or a time range"},
    {"info", cmd_info, "version, dependencies, devices, kernel build status"},
};

static void usage(FILE *to)
{
    fprintf(to, "Usage: skysweep COMMAND [options] INPUT... OUTPUT\n\nCommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        fprintf(to, "  %-9s %s\n", commands[i].name, commands[i].summary);
    fprintf(to, "\nskysweep COMMAND --help lists a command's options. Azimuths are degrees "
                "clockwise from north.\n");
}

int main(int argc, char **argv)
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
    if (strcmp(name, "--version") == 0 || strcmp(name, "version") == 0) {
        printf("skysweep %s\n", ss_version());
        return 0;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        if (strcmp(name, commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "skysweep: unknown command '%s' (see skysweep --help)\n", name);
    return SS_ERR_ARGUMENT;
}
