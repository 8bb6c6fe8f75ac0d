/* Table-driven option parsing on top of getopt_long_only. */
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "options.h"
#include "skysweep_params.h"

int opt_from_params(const char *table, size_t base, opt_spec *out, int max)
{
    static const opt_type types[] = {[SS_PARAM_INT] = OPT_INT,
                                     [SS_PARAM_DOUBLE] = OPT_DOUBLE,
                                     [SS_PARAM_TEXT] = OPT_STRING,
                                     [SS_PARAM_CHOICE] = OPT_CHOICE,
                                     [SS_PARAM_FLAG] = OPT_FLAG};
    const ss_param_table *t = ss_param_table_named(table);
    int n = 0;
    for (const ss_param *p = t ? t->params : NULL; p && p->name && n + 1 < max; ++p, ++n)
        out[n] = (opt_spec){p->name,         types[p->type], base + p->offset, p->metavar,
                            p->default_text, p->min,         p->max,           p->choices,
                            p->help};
    out[n] = (opt_spec)OPT_END;
    return n;
}

static int n_specs(const opt_spec *const *tables)
{
    int n = 0;
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s)
            n++;
    return n;
}

static const opt_spec *spec_at(const opt_spec *const *tables, int index)
{
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s)
            if (index-- == 0)
                return s;
    return NULL;
}

/* Index of `word` among the '|'-separated choices, or -1. */
static int choice_index(const char *choices, const char *word)
{
    int i = 0;
    size_t n = strlen(word);
    for (const char *p = choices; *p; ++i) {
        const char *bar = strchr(p, '|');
        size_t len = bar ? (size_t)(bar - p) : strlen(p);
        if (len == n && strncmp(p, word, n) == 0)
            return i;
        if (!bar)
            break;
        p = bar + 1;
    }
    return -1;
}

/* Parses text for option s and stores it in settings; settings NULL only
 * checks the text. */
static int set_value(const opt_spec *s, void *settings, const char *text, char *err,
                     size_t err_size)
{
    char *field = settings ? (char *)settings + s->offset : NULL;
    char *end = NULL;
    errno = 0;
    switch (s->type) {
    case OPT_INT: {
        long v = strtol(text, &end, 10);
        if (!*text || *end || errno || v < s->min || v > s->max) {
            snprintf(err, err_size, "--%s expects an integer from %.0f to %.0f, not '%s'",
                     s->name, s->min, s->max, text);
            return -1;
        }
        if (field)
            *(int *)field = (int)v;
        return 0;
    }
    case OPT_DOUBLE: {
        double v = strtod(text, &end);
        if (!*text || *end || errno || !isfinite(v) || v < s->min || v > s->max) {
            snprintf(err, err_size, "--%s expects a number from %g to %g, not '%s'", s->name,
                     s->min, s->max, text);
            return -1;
        }
        if (field)
            *(double *)field = v;
        return 0;
    }
    case OPT_STRING:
    case OPT_INPUT:
    case OPT_OUTPUT:
        if (field)
            *(const char **)field = text;
        return 0;
    case OPT_CHOICE: {
        int i = choice_index(s->choices, text);
        if (i < 0) {
            snprintf(err, err_size, "--%s expects one of %s, not '%s'", s->name, s->choices,
                     text);
            return -1;
        }
        if (field)
            *(int *)field = i;
        return 0;
    }
    case OPT_FLAG:
        if (field)
            *(int *)field = 1;
        return 0;
    case OPT_LIST: {
        opt_list *l = (opt_list *)field;
        if (!l)
            return 0;
        if (l->count >= OPT_LIST_MAX) {
            snprintf(err, err_size, "--%s given more than %d times", s->name, OPT_LIST_MAX);
            return -1;
        }
        l->items[l->count++] = text;
        l->items[l->count] = NULL;
        return 0;
    }
    }
    return -1;
}

const opt_spec *opt_find(const opt_spec *const *tables, const char *name)
{
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s)
            if (strcmp(s->name, name) == 0)
                return s;
    return NULL;
}

int opt_at_default(const opt_spec *s, const void *settings)
{
    const char *field = (const char *)settings + s->offset;
    const char *def = s->default_text;
    switch (s->type) {
    case OPT_INT:
        return def && *(const int *)field == (int)strtol(def, NULL, 10);
    case OPT_DOUBLE:
        return def && *(const double *)field == strtod(def, NULL);
    case OPT_CHOICE:
        return *(const int *)field == (def ? choice_index(s->choices, def) : 0);
    case OPT_FLAG:
        return *(const int *)field == 0;
    case OPT_STRING:
    case OPT_INPUT:
    case OPT_OUTPUT: {
        const char *v = *(const char *const *)field;
        return v == def || (v && def && strcmp(v, def) == 0);
    }
    case OPT_LIST:
        return ((const opt_list *)field)->count == 0;
    }
    return 0;
}

int opt_check(const opt_spec *spec, const char *text, char *err, size_t err_size)
{
    return set_value(spec, NULL, text, err, err_size);
}

int opt_parse(const opt_spec *const *tables, void *settings, int argc, char **argv,
              const char **positional, int *n_positional, int max_positional, char *err,
              size_t err_size)
{
    int n = n_specs(tables);
    struct option *longopts = calloc((size_t)n + 2, sizeof *longopts);
    if (!longopts) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    for (int i = 0; i < n; ++i) {
        const opt_spec *s = spec_at(tables, i);
        longopts[i].name = s->name;
        longopts[i].has_arg = s->type == OPT_FLAG ? no_argument : required_argument;
        longopts[i].val = 1000 + i;
        if (s->default_text && set_value(s, settings, s->default_text, err, err_size) != 0) {
            free(longopts);
            return -1;
        }
    }
    longopts[n].name = "help";
    longopts[n].val = 'h';

    int result = 0;
    *n_positional = 0;
    opterr = 0;
    /* 0, not 1: glibc and musl then forget a previous parse entirely (one
     * that stopped inside "-hx" would otherwise resume at its "x"). */
    optind = 0;
    /* '-' in front: positionals come back in order as value 1. */
    for (;;) {
        int prev = optind > 0 ? optind : 1; /* optind 0 stands for 1 (see above) */
        int c = getopt_long_only(argc, argv, "-:h", longopts, NULL);
        if (c == -1)
            break;
        if (c == 'h') {
            result = 1;
            break;
        }
        if (c == 1) {
            if (*n_positional >= max_positional) {
                snprintf(err, err_size, "unexpected extra argument '%s'", optarg);
                result = -1;
                break;
            }
            positional[(*n_positional)++] = optarg;
            continue;
        }
        if (c == '?' || c == ':') {
            const char *word = prev < argc ? argv[prev] : "?";
            snprintf(err, err_size,
                     c == ':' ? "option '%s' needs a value" : "unknown option '%s'", word);
            result = -1;
            break;
        }
        const opt_spec *s = spec_at(tables, c - 1000);
        if (set_value(s, settings, optarg, err, err_size) != 0) {
            result = -1;
            break;
        }
    }
    free(longopts);
    /* The message quotes the user's words: keep it one line whatever they hold. */
    for (char *p = err; result < 0 && *p; ++p)
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            *p = ' ';
    return result;
}

/* Help shows GDAL's own options the way GDAL's tools spell them (-of,
 * -co, -projwin, -q) and the others with two dashes; both spellings of
 * every option are accepted (getopt_long_only). */
const char *opt_dash(const char *name)
{
    static const char *gdal_style[] = {"of", "co", "projwin", "q"};
    for (size_t i = 0; i < sizeof gdal_style / sizeof gdal_style[0]; ++i)
        if (strcmp(name, gdal_style[i]) == 0)
            return "-";
    return "--";
}

int opt_advanced(const char *name)
{
    static const char *advanced[] = {
        /* where the work runs, how the outputs are written, how --plan prints */
        "device", "co", "memory", "projwin", "plan-format",
        /* reading the DEM where its own description is wrong or missing */
        "cell-size", "z-units", "overlap",
        /* the sweep's accuracy knobs and the earth's figure */
        "offset", "north", "curvature", "refraction", "earth-radius", "horizon-tolerance",
        "svf-tolerance", "sun-tolerance", "lines", "box-lines", "box-shadows",
        /* the sun's position: per cell, Delta T, the air's refraction */
        "sun-per-cell", "delta-t", "pressure", "temperature",
        /* insolation's accuracy knobs and constants, the inverter's fine print */
        "elevation-step", "solar-constant", "insolation-tolerance", "inverter-efficiency",
        "dc-ac-ratio",
        /* the leaves' optics */
        "extinction"};
    for (size_t i = 0; i < sizeof advanced / sizeof advanced[0]; ++i)
        if (strcmp(name, advanced[i]) == 0)
            return 1;
    return 0;
}

int opt_any_advanced(const opt_spec *const *tables)
{
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s)
            if (opt_advanced(s->name))
                return 1;
    return 0;
}

static void print_help_line(const opt_spec *s)
{
    char left[64];
    if (s->type == OPT_FLAG)
        snprintf(left, sizeof left, "%s%s", opt_dash(s->name), s->name);
    else
        snprintf(left, sizeof left, "%s%s %s", opt_dash(s->name), s->name,
                 s->type == OPT_CHOICE ? s->choices : s->metavar);
    printf("  %-34s %s", left, s->help);
    if (s->default_text && s->type != OPT_FLAG)
        printf(" (default %s)", s->default_text);
    printf("\n");
}

void opt_print_help(const opt_spec *const *tables, const char *usage, const char *summary)
{
    printf("Usage: %s\n\n%s\n\nOptions:\n", usage, summary);
    for (int advanced = 0; advanced < 2; ++advanced) {
        if (advanced && opt_any_advanced(tables))
            printf("\n%s:\n", OPT_ADVANCED_HEADING);
        for (int t = 0; tables[t]; ++t)
            for (const opt_spec *s = tables[t]; s->name; ++s)
                if (opt_advanced(s->name) == advanced)
                    print_help_line(s);
        if (!advanced)
            printf("  %-34s %s\n", "--help", "show this help");
    }
}

int opt_parse_site(const char *text, double *lon_deg, double *lat_deg)
{
    char *end;
    *lon_deg = strtod(text, &end);
    if (end == text || *end != ',')
        return 0;
    const char *lat = end + 1;
    *lat_deg = strtod(lat, &end);
    return end != lat && *end == '\0';
}

int opt_parse_zone(const char *text, double *hours, char *err, size_t err_size)
{
    if (strcmp(text, "Z") == 0) {
        *hours = 0.0;
        return 1;
    }
    int h, m = 0, len = 0;
    char sign = text[0];
    if ((sign != '+' && sign != '-') ||
        !(sscanf(text + 1, "%2d:%2d%n", &h, &m, &len) == 2 ||
          sscanf(text + 1, "%2d%2d%n", &h, &m, &len) == 2 ||
          (m = 0, sscanf(text + 1, "%2d%n", &h, &len) == 1)) ||
        text[1 + len] != '\0' || !isdigit((unsigned char)text[1]) || m < 0 || m > 59 ||
        h * 60 + m > 14 * 60) {
        snprintf(err, err_size,
                 "--weather-zone expects a UTC offset such as +01:00 or -05:00 (at most 14 h), "
                 "not '%s'",
                 text);
        return 0;
    }
    *hours = (sign == '-' ? -1 : 1) * (h + m / 60.0);
    return 1;
}
