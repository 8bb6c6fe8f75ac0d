/* Each cell's terms for insolation (insolation_cell.h): what does not
 * change with time, made once before the time steps by runs of the one
 * driver, and the horizons stored at the sweep's directions for
 * interpolated shadows and the cumulative sky (from the same walk as the
 * terms where both are needed). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "insolation_internal.h"

/* Perez's horizon band as each cell sees it (SS_PEREZ_BAND_DEG): in each
 * of the sweep's directions the terrain horizon hides its lowest part, and
 * the shares left open are averaged over the directions in front of the
 * cell's surface, each weighted by the cosine of its incidence on the cell.
 * A surface other than the cell's own also gets its tilted sky view here,
 * from the same horizons (the SVF product sweeps with the cell's own
 * gradient). */

/* A fixed surface descends toward the azimuth it faces. */
void ss_insolation_surface_gradient(const ss_surface *s, const ss_sweep_options *opt,
                                    float *dz_de, float *dz_dn)
{
    *dz_de = *dz_dn = 0.0f;
    if (s->kind != SS_SURFACE_FIXED)
        return;
    double rad = M_PI / 180.0, a = (s->azimuth_deg - opt->grid_north_deg) * rad;
    double slope = tan(fmin(s->tilt_deg, 89.9) * rad);
    *dz_de = (float)(-slope * sin(a));
    *dz_dn = (float)(-slope * cos(a));
}

/* The surface's gradient at every own cell of a band: the cell's own
 * (Horn's, from the held rows) or the fixed surface's. */
static void band_gradients(const ss_insolation_job *job, const ss_band_view *band, float *de,
                           float *dn)
{
    ss_grid held = ss_band_grid(band, job->src);
    int own = job->io->surface.kind == SS_SURFACE_CELL, first = band->row0 - band->lo;
    float fixed_de, fixed_dn, cx = (float)held.cell_x_m, cy = (float)held.cell_y_m;
    ss_insolation_surface_gradient(&job->io->surface, job->opt, &fixed_de, &fixed_dn);
#pragma omp parallel for schedule(static)
    for (int r = 0; r < band->n_rows; ++r)
        for (int c = 0; c < band->width; ++c) {
            size_t k = (size_t)r * band->width + c;
            de[k] = fixed_de;
            dn[k] = fixed_dn;
            if (own && isfinite(band->own_z[k]))
                ss_gradient_horn(held.z, held.width, held.height, c, first + r, cx, cy, &de[k],
                                 &dn[k]);
        }
}

ss_status ss_insolation_band_terms(const ss_insolation_job *job, const ss_band_view *band,
                                   ss_cell_terms *terms)
{
    size_t n = (size_t)band->n_rows * band->width;
    float *sky = ss_malloc(n * sizeof(float)), *seen = ss_malloc(n * sizeof(float));
    float *de = ss_malloc(n * sizeof(float)), *dn = ss_malloc(n * sizeof(float));
    ss_status st = sky && seen && de && dn
                       ? ss_cell_store_get(job->cells, 0, band->row0, band->n_rows, sky)
                       : ss_fail(job->ctx, SS_ERR_MEMORY, "out of memory for a band's terms");
    if (st == SS_OK)
        st = ss_cell_store_get(job->cells, 1, band->row0, band->n_rows, seen);
    if (st == SS_OK) {
        band_gradients(job, band, de, dn);
        double origin = ss_source_origin(job->src);
#pragma omp parallel for schedule(static)
        for (size_t c = 0; c < n; ++c)
            if (isfinite(band->own_z[c])) {
                terms[c] = ss_cell_terms_of(de[c], dn[c], sky[c], band->own_z[c] + origin);
                terms[c].band_seen = seen[c];
            } else {
                /* Nodata: a level cell at the datum, which the steps compute
                 * side by side with the others and then drop (insolation_lanes.h). */
                terms[c] = ss_cell_terms_of(0.0f, 0.0f, 1.0f, 0.0);
            }
    }
    free(sky);
    free(seen);
    free(de);
    free(dn);
    return st;
}

/* ---- horizons stored at the directions -------------------------------------- */

/* Opens job->horizons for the D directions' horizons, where they fit. */
static ss_status open_horizon_store(ss_insolation_job *job)
{
    const ss_sweep_options *opt = job->opt;
    const ss_source *src = job->src;
    double bytes = (double)src->width * src->height * opt->directions * sizeof(int16_t);
    if (src->z && ss_source_band_rows(src) == src->height && bytes >= 4e9)
        return ss_fail(job->ctx, SS_ERR_MEMORY,
                       "storing %d horizon directions takes %.1f GB: use the exact shadow "
                       "mode or fewer directions",
                       opt->directions, bytes / 1e9);
    return ss_cell_store_open(job->ctx, src, opt->directions, sizeof(int16_t), &job->horizons);
}

/* Direction `index`'s horizons (degrees) over a band's own rows into the
 * store, through rows_buffer (int16 per cell). */
static ss_status store_horizon_rows(ss_insolation_job *job, int index, const ss_band_view *band,
                                    const float *angle_deg, int16_t *rows_buffer)
{
    size_t n = (size_t)band->n_rows * band->width;
    for (size_t c = 0; c < n; ++c)
        rows_buffer[c] = isfinite(band->own_z[c])
                             ? (int16_t)lrintf(angle_deg[c] * SS_HORIZON_SCALE)
                             : 0;
    return ss_cell_store_put(job->horizons, index, band->row0, band->n_rows, rows_buffer);
}

typedef struct {
    ss_insolation_job *job;
    int16_t *rows; /* a band's own rows */
} stored_run;

static ss_status store_direction(void *user, int index, const ss_band_view *band,
                                 const ss_dir_rows *rows, float *planes)
{
    (void)planes;
    stored_run *s = user;
    return store_horizon_rows(s->job, index, band, rows->angle, s->rows);
}

/* The horizons at the D directions into job->horizons, a walk of their own. */
static ss_status store_horizons(ss_insolation_job *job)
{
    const ss_sweep_options *opt = job->opt;
    const ss_source *src = job->src;
    int rows = ss_source_band_rows(src);
    stored_run s = {job, ss_malloc(sizeof(int16_t) * (size_t)rows * src->width)};
    ss_engine_dir *dirs = ss_malloc(sizeof *dirs * (size_t)opt->directions);
    ss_status st = s.rows && dirs ? open_horizon_store(job)
                                  : ss_fail(job->ctx, SS_ERR_MEMORY,
                                            "out of memory storing %d directions",
                                            opt->directions);
    for (int i = 0; st == SS_OK && i < opt->directions; ++i)
        dirs[i] = (ss_engine_dir){ss_direction_azimuth(opt, i), 1, i, -1};
    ss_consumer consumer = {.planes = 0, .direction = store_direction};
    ss_engine_job run = {.walk = {.term = SS_TERM_HORIZON, .none_deg = 0.0f},
                         .dirs = dirs,
                         .n_dirs = opt->directions,
                         .consumer = &consumer,
                         .user = &s,
                         .what = "horizon"};
    if (st == SS_OK)
        st = ss_horizon_walk(job->ctx, src, opt, &run);
    free(s.rows);
    free(dirs);
    return st;
}

/* ---- the horizon terms: Perez's band, another surface's sky view ---------- */

typedef struct {
    ss_insolation_job *job;
    const double *azimuths;
    int with_sky;    /* a surface other than the cell's own: its sky view too */
    float *de, *dn;  /* the band's surface gradients */
    int16_t *stored; /* storing the horizons too: a band's own rows (else NULL) */
} horizon_terms;

enum { OPEN, WEIGHT, SKY }; /* the planes of the horizon terms */

static ss_status terms_visit(void *user, const ss_band_view *band)
{
    horizon_terms *h = user;
    band_gradients(h->job, band, h->de, h->dn);
    return SS_OK;
}

static ss_status terms_direction(void *user, int index, const ss_band_view *band,
                                 const ss_dir_rows *rows, float *planes)
{
    horizon_terms *h = user;
    size_t n = (size_t)band->n_rows * band->width;
    float *open = planes + OPEN * n, *weight = planes + WEIGHT * n, *sky = planes + SKY * n;
    /* The options' frame: the cells' gradients are in the grid's. */
    float az = (float)((h->azimuths[index] - h->job->opt->grid_north_deg) * M_PI / 180.0);
    float se = sinf(az), sn = cosf(az);
    const float *angle_deg = rows->angle;
    for (size_t c = 0; c < n; ++c) {
        if (!isfinite(band->own_z[c]))
            continue;
        /* ss_svf_tilted_term takes the horizon as a rise over a distance and
         * clips it at the horizontal, as this does: a horizon below it
         * hides no sky and none of the band. */
        float rise = tanf(fmaxf(angle_deg[c], 0.0f) * (float)(M_PI / 180.0));
        if (h->with_sky)
            sky[c] += ss_svf_tilted_term(1.0f, rise, se, sn, h->de[c], h->dn[c]);
        float facing = ss_cos_incidence_gradient(se, sn, 0.0f, h->de[c], h->dn[c]);
        if (facing <= 0.0f)
            continue;
        weight[c] += facing;
        open[c] += facing * fminf(fmaxf(1.0f - angle_deg[c] / SS_PEREZ_BAND_DEG, 0.0f), 1.0f);
    }
    return h->stored ? store_horizon_rows(h->job, index, band, angle_deg, h->stored) : SS_OK;
}

static ss_status terms_finish(void *user, const ss_band_view *band, float *planes)
{
    horizon_terms *h = user;
    size_t n = (size_t)band->n_rows * band->width;
    const float *open = planes + OPEN * n, *weight = planes + WEIGHT * n;
    float *seen = h->de, *sky = planes + SKY * n; /* the gradients are done with */
    for (size_t c = 0; c < n; ++c) {
        seen[c] = weight[c] > 0.0f ? open[c] / weight[c] : 1.0f;
        if (h->with_sky)
            sky[c] = ss_product_finish(SS_SVF_TILTED, sky[c], h->job->opt->directions);
    }
    ss_status st = ss_cell_store_put(h->job->cells, 1, band->row0, band->n_rows, seen);
    if (st == SS_OK && h->with_sky)
        st = ss_cell_store_put(h->job->cells, 0, band->row0, band->n_rows, sky);
    return st;
}

/* Every cell's band seen (and, with_sky, its surface's sky view) from the
 * horizons at the options' directions, and with store those horizons into
 * job->horizons: one horizon walk. */
static ss_status run_horizon_terms(ss_insolation_job *job, int with_sky, int store)
{
    const ss_sweep_options *opt = job->opt;
    const ss_source *src = job->src;
    int n_dirs = opt->directions;
    int rows = ss_source_band_rows(src);
    size_t n = (size_t)rows * src->width;
    ss_engine_dir *dirs = ss_malloc(sizeof *dirs * (size_t)n_dirs);
    double *azimuths = ss_malloc(sizeof *azimuths * (size_t)n_dirs);
    horizon_terms h = {job, azimuths, with_sky, ss_malloc(n * sizeof(float)),
                       ss_malloc(n * sizeof(float)),
                       store ? ss_malloc(n * sizeof(int16_t)) : NULL};
    ss_status st = SS_OK;
    if (!dirs || !azimuths || !h.de || !h.dn || (store && !h.stored))
        st = ss_fail(job->ctx, SS_ERR_MEMORY, "cannot allocate the horizon terms' sums");
    if (st == SS_OK && store)
        st = open_horizon_store(job);
    for (int i = 0; st == SS_OK && i < n_dirs; ++i) {
        azimuths[i] = ss_direction_azimuth(opt, i);
        dirs[i] = (ss_engine_dir){azimuths[i], 1, i, -1};
    }
    ss_consumer consumer = {.planes = 3,
                            .visit = terms_visit,
                            .direction = terms_direction,
                            .finish = terms_finish};
    ss_engine_job run = {.walk = {.term = SS_TERM_HORIZON, .none_deg = 0.0f},
                         .dirs = dirs,
                         .n_dirs = n_dirs,
                         .consumer = &consumer,
                         .user = &h,
                         .what = "horizon"};
    if (st == SS_OK)
        st = ss_horizon_walk(job->ctx, src, opt, &run);
    free(dirs);
    free(azimuths);
    free(h.de);
    free(h.dn);
    free(h.stored);
    return st;
}

/* Where no horizon terms are made: every cell sees the whole band. */
static ss_status band_seen_everywhere(ss_insolation_job *job)
{
    const ss_source *src = job->src;
    float *ones = ss_malloc(sizeof(float) * (size_t)src->width);
    if (!ones)
        return ss_fail(job->ctx, SS_ERR_MEMORY, "out of memory for a row");
    for (int c = 0; c < src->width; ++c)
        ones[c] = 1.0f;
    ss_status st = SS_OK;
    for (int r = 0; r < src->height && st == SS_OK; ++r)
        st = ss_cell_store_put(job->cells, 1, r, 1, ones);
    free(ones);
    return st;
}

/* The sky view's terms (and the stored horizons, shadows not exact). */
static ss_status sky_inputs(ss_insolation_job *job, int store)
{
    int own = job->io->surface.kind == SS_SURFACE_CELL;
    ss_status st = ss_cell_store_open(job->ctx, job->src, 2, sizeof(float), &job->cells);
    /* The cell's own surface: the radiative SVF product's tilted sky view. */
    ss_store_sink sky = {job->cells, 0};
    if (st == SS_OK && own)
        st = ss_sky_walk(job->ctx, job->src, job->opt, SS_SKY_SVF_RADIATIVE, 0.0, NULL,
                         ss_store_sink_rows, &sky);
    if (st != SS_OK)
        return st;
    if (!own || job->perez_band)
        return run_horizon_terms(job, !own, store);
    st = band_seen_everywhere(job);
    return st == SS_OK && store ? store_horizons(job) : st;
}

ss_status ss_insolation_cell_inputs(ss_insolation_job *job)
{
    int store = job->io->shadow_mode != SS_SHADOW_EXACT;
    /* Exact shadows take nothing from these sweeps: the sky view's own
     * box lines per cell, where the plan gave it some (sky_box_lines). */
    const ss_sweep_options *given = job->opt;
    ss_sweep_options sky = *given;
    if (!store && sky.sky_box_lines > 0)
        sky.box_lines = sky.sky_box_lines;
    job->opt = &sky;
    ss_status st = sky_inputs(job, store);
    job->opt = given;
    return st;
}

