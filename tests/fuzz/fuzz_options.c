/* Fuzz target: option values and argument vectors as the CLI parses them.
 * The input is an argument vector: arguments separated by NUL bytes (at
 * most 24 of at most 200 bytes). Two consumers:
 *   1. opt_parse (src/cli/options.c) with the shared tables of run.c
 *      (common_options(): directions, offset, north, device, -q, -of, -co,
 *      cell-size, curvature, refraction, earth-radius, lines; sun_options():
 *      time, sun azimuth and elevation, delta-t, pressure, ...) and a table
 *      with one option of every type. Checked: a refusal is -1 with a
 *      one-line message; an accepted vector gives values inside the
 *      tables' ranges, and sweep options that ss_sweep_options_check
 *      accepts (the table's ranges and the library's agree).
 *   2. the whole `skysweep sun` command (cmd_sun: --at, --time ranges,
 *      --delta-t, --pressure, --horizon-from, ...), stdout thrown away.
 *      Vectors whose time range holds more than 2000 instants are skipped
 *      (they are valid and only slow: up to a million SPA rows), and so are
 *      vectors naming /dev, /proc or /sys (a DEM read from /dev/stdin waits).
 * Sweeping commands are not run here: their arguments name files, and a
 * fuzzer must not write files where the bytes say (tests/test_faults.sh
 * covers them). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "skysweep_sun.h"
#include "options.h"
#include "run.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

typedef struct {
    common_settings common; /* first, as in every sweeping command */
    int count;
    double ratio;
    const char *name;
    int colour;
    int verbose;
    opt_list tags;
} fuzz_settings;

#define SET(field) offsetof(fuzz_settings, field)
static const opt_spec fuzz_options[] = {
    {"count", OPT_INT, SET(count), "N", "3", -5, 100, NULL, "an int"},
    {"ratio", OPT_DOUBLE, SET(ratio), "R", NULL, -1e-3, 1e300, NULL, "a double"},
    {"name", OPT_STRING, SET(name), "S", NULL, 0, 0, NULL, "a string"},
    {"colour", OPT_CHOICE, SET(colour), NULL, "red", 0, 0, "red|green|blue|b", "a choice"},
    {"verbose", OPT_FLAG, SET(verbose), NULL, NULL, 0, 0, NULL, "a flag"},
    {"tag", OPT_LIST, SET(tags), "T", NULL, 0, 0, NULL, "a list"},
    OPT_END};

#define MAX_ARGS 24
#define MAX_ARG_LEN 200

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    /* The sun table goes nowhere; refusals still print one line on stderr. */
    if (!freopen("/dev/null", "w", stdout))
        abort();
    return 0;
}

/* A range with more instants than a quick run should print. */
static int slow_time(const char *arg)
{
    static ss_ctx *ctx;
    if (!ctx)
        ctx = ss_ctx_new();
    const char *eq = strchr(arg, '=');
    const char *candidates[2] = {arg, eq ? eq + 1 : NULL};
    for (int i = 0; i < 2; ++i) {
        ss_time_range r;
        if (candidates[i] && ss_parse_time_range(ctx, candidates[i], &r) == SS_OK &&
            r.count > 2000)
            return 1;
    }
    return 0;
}

static void check_parsed(const fuzz_settings *s)
{
    FUZZ_CHECK(s->count >= -5 && s->count <= 100, "count %d", s->count);
    FUZZ_CHECK(isnan(s->ratio) || s->ratio == 0 || (s->ratio >= -1e-3 && isfinite(s->ratio)),
               "ratio %g", s->ratio);
    FUZZ_CHECK(s->colour >= 0 && s->colour <= 3, "colour %d", s->colour);
    FUZZ_CHECK(s->tags.count >= 0 && s->tags.count <= OPT_LIST_MAX &&
                   s->tags.items[s->tags.count] == NULL,
               "tags %d", s->tags.count);
    const common_settings *c = &s->common;
    FUZZ_CHECK(c->creation_options.count <= OPT_LIST_MAX &&
                   c->creation_options.items[c->creation_options.count] == NULL,
               "-co count %d", c->creation_options.count);
    FUZZ_CHECK(c->cell_size_m == 0 || (c->cell_size_m >= 1e-6 && c->cell_size_m <= 1e7),
               "cell size %g", c->cell_size_m);
    FUZZ_CHECK(isnan(c->sun.sun_elevation_deg) ||
                   (c->sun.sun_elevation_deg >= -90 && c->sun.sun_elevation_deg <= 90),
               "sun elevation %g", c->sun.sun_elevation_deg);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = c->sweep.directions ? c->sweep.directions : 32; /* 0: the planner chooses */
    opt.offset_deg = c->sweep.offset_deg;
    opt.lines = c->sweep.lines == 0 ? SS_LINES_INTERPOLATED : SS_LINES_DIGITAL;
    opt.refraction_k = c->sweep.refraction_k;
    if (c->sweep.earth_radius_m > 0)
        opt.earth_radius_m = c->sweep.earth_radius_m;
    ss_ctx *ctx = ss_ctx_new();
    ss_status st = ss_sweep_options_check(ctx, &opt);
    FUZZ_CHECK(st == SS_OK, "options accepted by the table, refused by the library: %s",
               ss_ctx_message(ctx));
    ss_ctx_free(ctx);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *args[MAX_ARGS + 2];
    int argc = 0;
    args[argc++] = strdup("fuzz");
    size_t i = 0;
    while (i <= size && argc <= MAX_ARGS) {
        size_t j = i;
        while (j < size && data[j] != '\0')
            ++j;
        size_t len = j - i < MAX_ARG_LEN ? j - i : MAX_ARG_LEN;
        char *a = malloc(len + 1);
        memcpy(a, data + i, len);
        a[len] = '\0';
        args[argc++] = a;
        i = j + 1;
    }
    args[argc] = NULL;

    /* 1. The option tables. */
    fuzz_settings set;
    memset(&set, 0, sizeof set);
    common_settings_init(&set.common);
    set.ratio = NAN;
    const opt_spec *tables[] = {fuzz_options, common_options(), sun_options(), NULL};
    const char *pos[4];
    int n_pos = -1;
    char err[512];
    err[0] = '\0';
    int r = opt_parse(tables, &set, argc, args, pos, &n_pos, 4, err, sizeof err);
    FUZZ_CHECK(r >= -1 && r <= 1, "opt_parse returned %d", r);
    FUZZ_CHECK(n_pos >= 0 && n_pos <= 4, "%d positionals", n_pos);
    if (r < 0)
        FUZZ_CHECK(err[0] && !strchr(err, '\n'), "refusal without a one-line message: '%s'", err);
    else if (r == 0)
        check_parsed(&set);

    /* 2. The sun command, on a copy (getopt may reorder the vector). */
    int slow = 0;
    for (int k = 1; k < argc && !slow; ++k)
        slow = slow_time(args[k]) || strstr(args[k], "/dev") || strstr(args[k], "/proc") ||
               strstr(args[k], "/sys"); /* --horizon-from /dev/stdin would wait */
    if (!slow) {
        char *copy[MAX_ARGS + 2];
        for (int k = 0; k <= argc; ++k)
            copy[k] = args[k];
        int rc = cmd_sun(argc, copy);
        /* 3: --horizon-from names a file that is no DEM. */
        FUZZ_CHECK(rc == 0 || rc == SS_ERR_ARGUMENT || rc == SS_ERR_INPUT,
                   "skysweep sun exit code %d", rc);
    }

    for (int k = 0; k < argc; ++k)
        free(args[k]);
    return 0;
}
