/* Declared option tables: each command lists its options once (name, type,
 * default, range, help) and the parser, --help, --help-json, the man pages
 * and doc/cli.md all come from the table (the libvips habit). Parsing uses
 * getopt_long_only, so both GDAL-style -co and --directions spellings work. */
#ifndef SS_CLI_OPTIONS_H
#define SS_CLI_OPTIONS_H

#include <stddef.h>

typedef enum {
    OPT_INT,    /* int, within [min, max] */
    OPT_DOUBLE, /* double, finite, within [min, max] */
    OPT_STRING, /* const char * */
    OPT_CHOICE, /* int: index into the '|'-separated choices */
    OPT_FLAG,   /* int: set to 1 when given */
    OPT_LIST,   /* opt_list: repeatable, e.g. -co KEY=VALUE */
    /* const char *, a file the run reads (OPT_INPUT) or writes (OPT_OUTPUT):
     * every file option is one of these, so that run_parse registers it
     * (src/adapt/run_files.h) and no output can replace another file the
     * run names. A scene's value for either lies beside the scene. */
    OPT_INPUT,
    OPT_OUTPUT
} opt_type;

#define OPT_LIST_MAX 32
typedef struct {
    const char *items[OPT_LIST_MAX + 1]; /* NULL-terminated */
    int count;
} opt_list;

typedef struct {
    const char *name; /* long name; given as -name or --name */
    opt_type type;
    size_t offset;    /* where the value goes in the command's settings */
    const char *metavar;
    const char *default_text; /* NULL: no default (optional or required by the command) */
    double min, max;
    const char *choices;
    const char *help;
} opt_spec;

#define OPT_END {NULL, OPT_FLAG, 0, NULL, NULL, 0, 0, NULL, NULL}

/* Options from the library's parameter table `table` (skysweep_params.h),
 * whose parameter struct lies at `base` in the command's settings: written
 * into out (at most max entries, an OPT_END included); returns how many
 * options, the OPT_END not counted. */
int opt_from_params(const char *table, size_t base, opt_spec *out, int max);

/* Sets defaults, then parses argv (after the command word). Positional
 * arguments are returned in order. On error writes one line into err and
 * returns -1; returns 1 if --help was asked for, else 0. */
int opt_parse(const opt_spec *const *tables, void *settings, int argc, char **argv,
              const char **positional, int *n_positional, int max_positional, char *err,
              size_t err_size);

/* The option named exactly `name` (no dashes), or NULL. */
const opt_spec *opt_find(const opt_spec *const *tables, const char *name);
/* Whether option s holds its default in settings (a flag: not given). The
 * checks of options another option makes meaningless go by value, not by
 * presence: front ends (QGIS) pass every default. */
int opt_at_default(const opt_spec *s, const void *settings);
/* Checks a value's text for an option without storing it: 0, or -1 with
 * one line in err. */
int opt_check(const opt_spec *spec, const char *text, char *err, size_t err_size);

/* The CLI's groups of options: whether the option named `name` is
 * advanced (where the work runs and how outputs are written, the model's
 * accuracy knobs and constants, whose defaults serve nearly every DEM), and
 * whether any of the tables' options is. --help, doc/cli.md and the man
 * pages list them after the others under OPT_ADVANCED_HEADING; --help-json
 * gives each option's "group" ("basic" or "advanced"), which the QGIS
 * provider shows as its advanced parameters. */
int opt_advanced(const char *name);
int opt_any_advanced(const opt_spec *const *tables);
#define OPT_ADVANCED_HEADING "Advanced options (their defaults serve nearly every DEM)"

/* Prints the options of the tables as a --help text. */
/* "-" for the options GDAL's tools spell with one dash (-of, -co, -projwin,
 * -q), "--" for the others: how help and doc/cli.md show them. */
const char *opt_dash(const char *name);
void opt_print_help(const opt_spec *const *tables, const char *usage, const char *summary);
/* ... and as a Markdown section for doc/cli.md (options_doc.c). */
/* The command's reference as a man page (roff) and as the words bash
 * completes (one option per line: the option, then its choices, or <file>
 * or <value> for what it takes). */
void opt_print_man(const opt_spec *const *tables, const char *command, const char *usage,
                   const char *summary, const char *version);
void opt_print_completion(const opt_spec *const *tables);
/* The command's reference as JSON: command, version, usage, summary and
 * options (name, dash, type, metavar, default, min and max, choices, group, help),
 * for front ends that derive their parameters from the CLI's tables. */
void opt_print_json(const opt_spec *const *tables, const char *command, const char *usage,
                    const char *summary, const char *version);
/* argv = {COMMAND, --help-markdown | --help-man | --help-completion |
 * --help-json}: prints
 * that reference and returns 1; else 0. */
int opt_print_reference(const opt_spec *const *tables, int argc, char **argv, const char *command,
                        const char *usage, const char *summary, const char *version);
void opt_print_markdown(const opt_spec *const *tables, const char *command, const char *usage,
                        const char *summary);

/* "LON,LAT" in degrees (--at); range checks are the library's. */
int opt_parse_site(const char *text, double *lon_deg, double *lat_deg);

/* A UTC offset, "+01:00", "-05:00", "+0530", "+01" or "Z", as hours east of
 * UTC (--weather-zone); 0, with the one line that says so in err, if it is
 * none, or beyond +-14:00. */
int opt_parse_zone(const char *text, double *hours, char *err, size_t err_size);

#endif
