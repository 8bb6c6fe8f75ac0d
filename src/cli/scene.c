/* Scene files: one INI file (libinih) describing a job. Its keys are the
 * command's own option names (the same declared tables, so every option
 * has a key and every key an option), in any section, plus `product`,
 * `dem` (one or more, space-separated) and `output`. Paths are relative
 * to the scene file. The scene becomes the front of the command line, so
 * options given on the command line override it. Every key and value is
 * checked while reading, so errors name the file and line. */
#include "config.h"

#include <ini.h>
#include <libgen.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "skysweep_sun.h"
#include "scene.h"
#include "text_input.h"

#define SCENE_MAX_ARGS 256
/* A scene is a few dozen lines: a larger file is not one (and /dev/zero
 * would be read for ever). */
#define SCENE_MAX_BYTES (1 << 20)

typedef struct {
    const opt_spec *const *tables;
    const char *dir;       /* the scene file's folder */
    char *args[SCENE_MAX_ARGS];
    int n_args;
    char *dems[64];
    int n_dems;
    char *output;
    char product[32];
    char error[400];       /* the first error; the line comes from ini_parse */
} scene_state;

/* Whether file can be a scene: a regular file of at most SCENE_MAX_BYTES;
 * else why not, into err. */
static int scene_file_ok(const char *file, char *err, size_t err_size)
{
    return ss_text_input_ok(file, "scene file", SCENE_MAX_BYTES, err, err_size);
}

static char *path_beside(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s%s%s", name[0] == '/' ? "" : dir, name[0] == '/' ? "" : "/", name);
    return p;
}

static int fail(scene_state *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail(scene_state *s, const char *fmt, ...)
{
    if (!s->error[0]) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(s->error, sizeof s->error, fmt, ap);
        va_end(ap);
    }
    return 0;
}

static int push(scene_state *s, char *arg)
{
    if (!arg || s->n_args >= SCENE_MAX_ARGS)
        return 0;
    s->args[s->n_args++] = arg;
    return 1;
}

/* Checks values whose meaning goes beyond their type: times and durations
 * (by the option's kind of value: horizon's `step` is degrees). */
static int check_semantics(scene_state *s, const opt_spec *spec, const char *value)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_status st = SS_OK;
    const char *kind = spec->metavar ? spec->metavar : "";
    if (strcmp(spec->name, "time") == 0 && strcmp(kind, "ISO8601") == 0) {
        ss_time_range r;
        st = ss_parse_time_range(ctx, value, &r);
    } else if (strcmp(kind, "DURATION") == 0) {
        ss_duration d;
        st = ss_parse_duration(ctx, value, &d);
    }
    if (st != SS_OK)
        fail(s, "%s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st == SS_OK;
}

static int on_key(void *user, const char *section, const char *name, const char *value)
{
    (void)section;
    scene_state *s = user;
    if (strcmp(name, "product") == 0) {
        if (s->product[0])
            return fail(s, "'product' is given twice");
        snprintf(s->product, sizeof s->product, "%s", value);
        return 1;
    }
    if (strcmp(name, "dem") == 0) {
        char *copy = strdup(value), *save = NULL;
        for (char *tok = copy ? strtok_r(copy, " \t", &save) : NULL; tok;
             tok = strtok_r(NULL, " \t", &save)) {
            char *path = path_beside(s->dir, tok);
            if (!path || s->n_dems >= 64) {
                free(path);
                free(copy);
                return fail(s, "too many DEMs");
            }
            if (access(path, R_OK) != 0 && strncmp(tok, "/vsi", 4) != 0) {
                fail(s, "DEM '%s' not found (paths are relative to the scene file: %s)", tok,
                     path);
                free(path);
                free(copy);
                return 0;
            }
            s->dems[s->n_dems++] = path;
        }
        free(copy);
        return s->n_dems > 0 ? 1 : fail(s, "'dem' names no file");
    }
    if (strcmp(name, "output") == 0) {
        if (s->output)
            return fail(s, "'output' is given twice");
        s->output = path_beside(s->dir, value);
        return s->output != NULL;
    }
    const opt_spec *spec = opt_find(s->tables, name);
    if (!spec)
        return fail(s, "unknown key '%s' for this product", name);
    char err[300];
    if (spec->type == OPT_FLAG) {
        if (strcmp(value, "true") && strcmp(value, "yes") && strcmp(value, "1") &&
            strcmp(value, "false") && strcmp(value, "no") && strcmp(value, "0"))
            return fail(s, "'%s' is a switch: give true or false, not '%s'", name, value);
        if (!strcmp(value, "false") || !strcmp(value, "no") || !strcmp(value, "0"))
            return 1;
    } else if (opt_check(spec, value, err, sizeof err) != 0) {
        return fail(s, "%s", err);
    } else if (!check_semantics(s, spec, value)) {
        return 0;
    }
    size_t n = strlen(name) + 3;
    char *flag = malloc(n);
    if (flag)
        snprintf(flag, n, "--%s", name);
    if (!push(s, flag))
        return fail(s, "too many keys");
    if (spec->type == OPT_FLAG)
        return 1;
    /* A file an option names lies, like the DEM, beside the scene. */
    int is_file = spec->type == OPT_INPUT || spec->type == OPT_OUTPUT;
    return push(s, is_file ? path_beside(s->dir, value) : strdup(value));
}

static void scene_free(scene_state *s)
{
    for (int i = 0; i < s->n_args; ++i)
        free(s->args[i]);
    for (int i = 0; i < s->n_dems; ++i)
        free(s->dems[i]);
    free(s->output);
}

/* Index of the --scene option in argv, or -1. */
int scene_arg(int argc, char **argv)
{
    for (int i = 1; i + 1 < argc; ++i)
        if (!strcmp(argv[i], "--scene") || !strcmp(argv[i], "-scene"))
            return i;
    return -1;
}

/* The last expansion: its vector and the strings it owns (the scene's),
 * kept until scene_release, since the command's settings point into them. */
static struct {
    char **vector;
    char **owned;
    int n_owned;
} held;

void scene_release(void)
{
    for (int i = 0; i < held.n_owned; ++i)
        free(held.owned[i]);
    free(held.owned);
    free(held.vector);
    memset(&held, 0, sizeof held);
}

int scene_expand(const opt_spec *const *tables, int argc, char **argv, int *out_argc,
                 char ***out_argv, char *err, size_t err_size)
{
    scene_release();
    *out_argc = argc;
    *out_argv = NULL;
    int at = scene_arg(argc, argv);
    if (at < 0)
        return 0;
    const char *file = argv[at + 1];
    if (!scene_file_ok(file, err, err_size))
        return -1;
    char *dir_copy = strdup(file);
    scene_state s;
    memset(&s, 0, sizeof s);
    s.tables = tables;
    s.dir = dir_copy ? dirname(dir_copy) : ".";
    int line = ini_parse(file, on_key, &s);
    int rc = 0;
    if (line < 0)
        snprintf(err, err_size, "cannot read scene file '%s'", file), rc = -1;
    else if (line > 0)
        snprintf(err, err_size, "%s:%d: %s", file, line,
                 s.error[0] ? s.error : "not a valid INI line"),
            rc = -1;
    /* The new command line: the scene's options, then the given ones
     * (which win), then the scene's DEMs and output unless positionals
     * were given. */
    int positional = 0;
    for (int i = 1; i < argc; ++i) {
        if (i == at || i == at + 1)
            continue;
        if (argv[i][0] != '-' || !argv[i][1]) {
            positional = 1;
            continue;
        }
        /* An option that takes a value consumes the next word. */
        const char *name = argv[i] + (argv[i][1] == '-' ? 2 : 1);
        const opt_spec *spec = strchr(name, '=') ? NULL : opt_find(tables, name);
        if (spec && spec->type != OPT_FLAG)
            i++;
    }
    char **v = rc == 0 ? calloc((size_t)(argc + s.n_args + s.n_dems + 2), sizeof *v) : NULL;
    char **owned = rc == 0 ? calloc((size_t)(s.n_args + s.n_dems + 1), sizeof *owned) : NULL;
    if (rc == 0 && (!v || !owned)) {
        free(v);
        free(owned);
        v = owned = NULL;
        snprintf(err, err_size, "out of memory"), rc = -1;
    }
    if (rc == 0) {
        int n = 0, k = 0;
        v[n++] = argv[0];
        for (int i = 0; i < s.n_args; ++i)
            v[n++] = owned[k++] = s.args[i], s.args[i] = NULL;
        for (int i = 1; i < argc; ++i)
            if (i != at && i != at + 1)
                v[n++] = argv[i];
        if (!positional) {
            for (int i = 0; i < s.n_dems; ++i)
                v[n++] = owned[k++] = s.dems[i], s.dems[i] = NULL;
            if (s.output)
                v[n++] = owned[k++] = s.output, s.output = NULL;
        }
        held.vector = v;
        held.owned = owned;
        held.n_owned = k;
        *out_argc = n;
        *out_argv = v;
    }
    scene_free(&s);
    free(dir_copy);
    /* The message quotes the file's keys and values: keep it one line. */
    for (char *p = err; rc != 0 && *p; ++p)
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            *p = ' ';
    return rc;
}

int scene_product(const char *file, char *product, size_t size, char *err, size_t err_size)
{
    if (!scene_file_ok(file, err, err_size))
        return -1;
    FILE *f = fopen(file, "r");
    if (!f) {
        snprintf(err, err_size, "cannot read scene file '%s'", file);
        return -1;
    }
    char line[512];
    product[0] = '\0';
    int lineno = 0, found = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char key[64], value[64];
        if (sscanf(line, " %63[a-z_-] = %63s", key, value) == 2 && !strcmp(key, "product")) {
            snprintf(product, size, "%s", value);
            found = lineno;
        }
    }
    fclose(f);
    if (!found)
        snprintf(err, err_size, "%s: no 'product' key (svf, horizon, shadow, hillshade or "
                                "insolation)",
                 file);
    return found ? 0 : -1;
}
