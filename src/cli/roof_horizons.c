/* Horizon files per roof plane (roof_horizons.h). */
#include "config.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "horizon_formats.h"
#include "roof_horizons.h"
#include "site.h"
#include "skysweep_sites.h"

void roof_plane_centre(const int *cells, const int *label, size_t n_cells, int width, int p,
                       double *col, double *row)
{
    double sc = 0.0, sr = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < n_cells; ++i)
        if (label[i] == p) {
            sc += cells[i] % width;
            sr += cells[i] / width;
            n++;
        }
    double mc = sc / (double)n, mr = sr / (double)n, best = -1.0;
    for (size_t i = 0; i < n_cells; ++i) {
        double dc = cells[i] % width - mc, dr = cells[i] / width - mr;
        if (label[i] == p && (best < 0.0 || dc * dc + dr * dr < best)) {
            best = dc * dc + dr * dr;
            *col = cells[i] % width;
            *row = cells[i] / width;
        }
    }
}

int roof_horizon_check(const char *folder)
{
    struct stat sb;
    if (!folder || (stat(folder, &sb) == 0 && S_ISDIR(sb.st_mode)))
        return 0;
    return run_usage_error("roofs", "--horizon-files writes one file per roof plane: it must "
                                    "name an existing folder");
}

static void file_name(const roof_horizon_site *s, const char *ext, char *buf, size_t size)
{
    int used = snprintf(buf, size, "%s_%d%s", s->building_id, s->plane, ext);
    for (int i = 0; i < used && (size_t)i < size; ++i) {
        unsigned char c = (unsigned char)buf[i];
        if (!(isalnum(c) || c == '-' || c == '_' || c == '.') || (i == 0 && c == '.'))
            buf[i] = '_';
    }
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Every site's file name (names[i], to be freed as one block); refuses two
 * sites with one name. */
static ss_status name_files(ss_ctx *ctx, const roof_horizon_site *sites, size_t n, const char *ext,
                            char ***names)
{
    enum { NAME_MAX_BYTES = 256 };
    char **list = malloc(sizeof *list * (n + 1) * 2 + (n + 1) * NAME_MAX_BYTES);
    if (!list)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory naming horizon files");
    char **sorted = list + n + 1, *text = (char *)(sorted + n + 1);
    for (size_t i = 0; i < n; ++i) {
        list[i] = sorted[i] = text + i * NAME_MAX_BYTES;
        file_name(&sites[i], ext, list[i], NAME_MAX_BYTES);
    }
    qsort(sorted, n, sizeof *sorted, by_name);
    for (size_t i = 1; i < n; ++i)
        if (strcmp(sorted[i], sorted[i - 1]) == 0) {
            ss_status st = ss_ctx_error(ctx, SS_ERR_INPUT,
                                        "two roof planes would share the horizon file '%s' "
                                        "(building ids that differ only in characters a file "
                                        "name cannot hold)",
                                        sorted[i]);
            free(list);
            return st;
        }
    *names = list;
    return SS_OK;
}

typedef struct {
    ss_ctx *ctx;
    const horizon_file_format *format;
    const char *folder, *sources;
    const roof_horizon_site *sites;
    char **names;
    ss_site_frame *sf;
    int directions;
    ss_status status;
} roof_writer;

static int write_one(int index, const ss_point_horizon_result *p, void *user)
{
    roof_writer *w = user;
    const roof_horizon_site *s = &w->sites[index];
    char id[300], path[4096];
    snprintf(id, sizeof id, "%s plane %d", s->building_id, s->plane);
    horizon_file_site site = {id, 0.0, 0.0, w->sources};
    snprintf(path, sizeof path, "%s/%s", w->folder, w->names[index]);
    w->status = ss_site_lonlat(w->sf, 1, &s->col, &s->row, &site.lon_deg, &site.lat_deg);
    if (w->status == SS_OK)
        w->status = horizon_file_write(w->ctx, w->format, path, &site, p, w->directions);
    return w->status == SS_OK;
}

ss_status roof_horizon_files(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                             const char *folder, int format, const roof_horizon_site *sites,
                             size_t n)
{
    static const char *const names[] = {"pvgis", "pvsyst", "pvsol", "helioscope", "sam"};
    roof_writer w = {ctx,    horizon_file_format_named(names[format]),
                     folder, dem->description,
                     sites,  NULL,
                     NULL,   360,
                     SS_OK};
    ss_point_grid *pg = NULL;
    ss_point_site *ps = malloc(sizeof *ps * (n + 1));
    ss_status st = ps ? name_files(ctx, sites, n, w.format->extension, &w.names)
                      : ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for %zu planes", n);
    if (st == SS_OK)
        st = ss_site_frame_open(ctx, dem, "dem", &w.sf);
    if (st == SS_OK)
        st = ss_point_grid_new(ctx, &dem->grid, &pg);
    for (size_t i = 0; st == SS_OK && i < n; ++i) {
        ps[i] = (ss_point_site){sites[i].col, sites[i].row, 0.0, 0.0};
        st = ss_geo_grid_north(frame->geo, sites[i].col, sites[i].row, &ps[i].grid_north_deg);
    }
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = w.directions;
    if (st == SS_OK && n > 0)
        st = ss_point_horizons(ctx, pg, &opt, ps, (int)n, write_one, &w);
    if (w.status != SS_OK)
        st = w.status;
    ss_point_grid_free(pg);
    ss_site_frame_close(w.sf);
    free(w.names);
    free(ps);
    return st;
}
