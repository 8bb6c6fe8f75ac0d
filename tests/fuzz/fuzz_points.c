/* Fuzz target: the sites file of `skysweep horizon --points FILE`
 * (src/cli/horizon_points.c). The input is the file; it is written to a
 * private temporary folder and read as the command reads it, for CSV and
 * JSON output and for pvgis folders (ids that name files). Checked: a
 * refusal is SS_ERR_INPUT or SS_ERR_MEMORY with a one-line message naming
 * the file; a read file has 1 to 1000000 sites with distinct ids that keep
 * to the characters an output may hold, finite coordinates and heights of
 * 0 to 1e6 m. */
#include "config.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "horizon_points.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int id_char_ok(unsigned char c, int as_file_name)
{
    if (as_file_name)
        return isalnum(c) || c == '-' || c == '_' || c == '.';
    return c >= 0x20 && c != 0x7f && !strchr("\"#\\,", c);
}

static void check_sites(const site_rec *sites, int n, int as_file_name)
{
    FUZZ_CHECK(sites && n >= 1 && n <= 1000000, "%d sites", n);
    for (int i = 0; i < n; ++i) {
        const site_rec *s = &sites[i];
        size_t len = strlen(s->id);
        FUZZ_CHECK(len >= 1 && len <= ID_MAX, "site %d: id of %zu characters", i, len);
        FUZZ_CHECK(!as_file_name || s->id[0] != '.', "site %d: id '%s' names a hidden file", i,
                   s->id);
        for (size_t k = 0; k < len; ++k)
            FUZZ_CHECK(id_char_ok((unsigned char)s->id[k], as_file_name),
                       "site %d: id '%s' holds 0x%02x", i, s->id, (unsigned char)s->id[k]);
        FUZZ_CHECK(isfinite(s->x) && isfinite(s->y), "site %d: %g, %g", i, s->x, s->y);
        FUZZ_CHECK(s->height_m >= 0 && s->height_m <= 1e6, "site %d: height %g", i, s->height_m);
        for (int j = 0; j < i; ++j)
            FUZZ_CHECK(strcmp(s->id, sites[j].id) != 0, "id '%s' twice", s->id);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 20000) /* the sites compared pairwise stay few */
        return 0;
    const char *path = fuzz_input_file("sites.csv", data, size);
    for (int as_file_name = 0; as_file_name < 2; ++as_file_name) {
        ss_ctx *ctx = ss_ctx_new();
        if (!ctx)
            abort();
        site_rec *sites = NULL;
        int n = 0;
        ss_status st = horizon_sites_read(ctx, path, 2.5, as_file_name, &sites, &n);
        if (st != SS_OK) {
            const char *m = ss_ctx_message(ctx);
            FUZZ_CHECK(st == SS_ERR_INPUT || st == SS_ERR_MEMORY, "status %d: %s", st, m);
            FUZZ_CHECK(m[0] && !strchr(m, '\n') && !strchr(m, '\r') && strstr(m, path),
                       "message '%s'", m);
        } else {
            check_sites(sites, n, as_file_name);
            free(sites);
        }
        ss_ctx_free(ctx);
    }
    return 0;
}
