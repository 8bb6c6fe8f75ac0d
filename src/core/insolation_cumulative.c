/* The cumulative sky for weather records (doc/insolation.md, "Cumulative
 * sky"): instead of a shadow sweep per record, the records' suns are binned
 * by month, by the nearest of the sweep's D directions and by apparent
 * elevation (elevation_step_deg). A cell then sums over the occupied bins,
 * each lit or not at its mean elevation against the horizon stored in its
 * direction. The beam and the circumsolar part are linear in the sun's
 * vector, so a bin keeps their weighted sums of sun vectors; the isotropic
 * part, Perez's horizon band and the reflection are sums of per-record
 * scalars times per-cell terms. The sweeps are the D directions once, and
 * a cell's work is one dot product per occupied bin instead of per record.
 * What it gives up against the exact run: a bin's suns share one
 * direction's horizon and their mean elevation; cos(incidence) is clipped
 * at zero per bin, not per record; Perez's clip of a negative sky at zero
 * is per month; one sun (the DEM's centre's) serves every cell. Its error
 * against the exact run is measured in doc/accuracy.md. Trees
 * (doc/cumulative_sky.md, "Trees"): a bin sums its leaf-off records apart,
 * and the crowns are swept once per (direction, elevation) of the bins. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "insolation_internal.h"
#include "insolation_trees.h"

/* What a bin of suns holds: the beam's and the circumsolar part's sums of
 * weight x sun vector (grid frame: east, north, up; Wh/m^2 on the normal),
 * the hours of sunshine (DNI >= 120 W/m^2) with their sum of sun vectors
 * (whether the surface faces them), and the hours and hour-weighted
 * apparent elevation of its suns. */
typedef struct {
    float beam[3], circumsolar[3], sunshine[3];
    float sunshine_hours, hours, elevation_hours;
    int month, direction;
    /* Trees: the same sums over the bin's leaf-off records, and the bin's
     * (direction, elevation) pair, whose crowns' crossing it takes. */
    float beam_off[3], circumsolar_off[3], sunshine_off[3], sunshine_hours_off;
    int pair;
} sun_bin;

/* Trees: the suns of all the bins of one direction and elevation, whose
 * hour-weighted mean direction is where the crowns are swept. */
typedef struct {
    double hours, elevation_hours, east_hours, north_hours;
} sun_pair;

/* Per month: sums over records of what multiplies per-cell terms
 * (ss_sky_parts; Wh/m^2). */
typedef struct {
    double isotropic; /* times the cell's sky view */
    double band;      /* times sin(tilt) times the band the cell sees */
    double reflected; /* times (1 - sky view) */
    /* Trees: the isotropic, horizon band and reflected sums of the
     * leaf-off records, whose sky view and band are the leaf-off ones. */
    double isotropic_off, band_off, reflected_off;
} month_sums;

typedef struct {
    sun_bin *bins;
    int *index; /* (month x directions + direction) x elevations + bin -> bins entry + 1 */
    int n_bins, capacity, directions, elevations;
    double step_deg;
    month_sums month[12];
    /* Trees (NULL without): direction x elevations + bin -> pairs entry + 1. */
    int *pair_index;
    sun_pair *pairs;
    int n_pairs;
} sun_map;

/* The bin for a sun, created on first use; NULL if out of memory. */
static sun_bin *bin_for(sun_map *m, int month, int direction, double apparent_deg)
{
    int e = (int)floor(fmax(apparent_deg, 0.0) / m->step_deg);
    if (e >= m->elevations)
        e = m->elevations - 1;
    size_t k = ((size_t)month * m->directions + (size_t)direction) * m->elevations + (size_t)e;
    if (!m->index[k]) {
        if (m->n_bins == m->capacity) {
            int c = m->capacity ? 2 * m->capacity : 1024;
            sun_bin *grown = ss_realloc(m->bins, sizeof *grown * (size_t)c);
            if (!grown)
                return NULL;
            m->bins = grown;
            m->capacity = c;
        }
        sun_bin *b = &m->bins[m->n_bins++];
        memset(b, 0, sizeof *b);
        b->month = month;
        b->direction = direction;
        b->pair = -1;
        m->index[k] = m->n_bins;
        if (m->pair_index) {
            size_t q = (size_t)direction * m->elevations + (size_t)e;
            if (!m->pair_index[q])
                m->pair_index[q] = ++m->n_pairs;
            b->pair = m->pair_index[q] - 1;
        }
    }
    return &m->bins[m->index[k] - 1];
}

static void add_vector(float v[3], float w, const float s[3])
{
    for (int i = 0; i < 3; ++i)
        v[i] += w * s[i];
}

/* One weather step into the map: its sun into a bin (when the sun is up
 * at the centre), its diffuse and reflected light into its month. */
static ss_status add_step(ss_ctx *ctx, sun_map *m, const ss_sweep_options *opt,
                          const ss_insolation_options *io, const ss_sun_step *sun, int k)
{
    int off = io->trees && io->trees->leaf_off && io->trees->leaf_off[k];
    ss_sky_record rec;
    int light = 0;
    if (!sun->real_sky)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the cumulative sky takes weather records, not clear-sky steps");
    if (!ss_insolation_sky_record(ctx, sun, io, &rec, &light, 1))
        return SS_OK; /* missing: counted */
    int month = sun->month >= 1 && sun->month <= 12 ? sun->month - 1 : 0;
    month_sums *ms = &m->month[month];
    double dt = sun->duration_h;
    double dni = fmax(rec.dni, 0.0), dhi = fmax(rec.dhi, 0.0), ghi = fmax(rec.ghi, 0.0);
    int up = sun->elevation_deg > 0.0;
    if (!up && !light) {
        ctx->counters.night_steps_skipped++;
        return SS_OK;
    }
    ctx->counters.time_steps++;
    ms->reflected += rec.albedo * ghi * dt;
    if (off)
        ms->reflected_off += rec.albedo * ghi * dt;
    if (!up) { /* sunrise and sunset hours: isotropic, as the exact run */
        ms->isotropic += dhi * dt;
        if (off)
            ms->isotropic_off += dhi * dt;
        return SS_OK;
    }
    float h0 = (float)(sun->elevation_deg * M_PI / 180.0);
    ss_sky_parts sky = ss_sky_parts_of((int)io->sky_model, (float)dhi, (float)dni, rec.dni_extra,
                                       0.5f * SS_PI_F - h0);
    ms->isotropic += sky.isotropic * dt;
    if (off)
        ms->isotropic_off += sky.isotropic * dt;
    ms->band += sky.horizon * dt;
    if (off)
        ms->band_off += sky.horizon * dt;
    double az = sun->grid_azimuth_deg * M_PI / 180.0;
    float s[3] = {(float)(cos(h0) * sin(az)), (float)(cos(h0) * cos(az)), sinf(h0)};
    double pos = fmod((sun->azimuth_deg - opt->offset_deg) / (360.0 / m->directions), m->directions);
    int direction = ((int)lround(pos < 0 ? pos + m->directions : pos)) % m->directions;
    sun_bin *b = bin_for(m, month, direction, sun->apparent_elevation_deg);
    if (!b)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the cumulative sky's sun bins");
    add_vector(b->beam, (float)(dni * dt), s);
    add_vector(b->circumsolar, (float)(sky.circumsolar * dt), s);
    if (dni >= 120.0) {
        b->sunshine_hours += (float)dt;
        add_vector(b->sunshine, (float)dt, s);
    }
    b->hours += (float)dt;
    b->elevation_hours += (float)(sun->apparent_elevation_deg * dt);
    if (off) {
        add_vector(b->beam_off, (float)(dni * dt), s);
        add_vector(b->circumsolar_off, (float)(sky.circumsolar * dt), s);
        if (dni >= 120.0) {
            b->sunshine_hours_off += (float)dt;
            add_vector(b->sunshine_off, (float)dt, s);
        }
    }
    if (b->pair >= 0) {
        sun_pair *q = &m->pairs[b->pair];
        q->hours += dt;
        q->elevation_hours += sun->apparent_elevation_deg * dt;
        q->east_hours += sin(az) * dt;
        q->north_hours += cos(az) * dt;
    }
    return SS_OK;
}

/* Trees at one cell: the crowns' crossings (a bit per pair and grid cell,
 * pairs one after another; NULL where no crown passes less than all the
 * light), the cell's index in the grid, both seasons' transmissivities and
 * the cell's leaf-off sky view and horizon band seen (its terms' are the
 * leaf-on ones). */
typedef struct {
    const unsigned char *crossed;
    size_t grid_cells, at;
    float T_on, T_off, sky_view_off, band_seen_off;
} cell_trees;

static float dot3(const float n[3], const float v[3])
{
    return n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
}

/* Whether the crowns stand in the way of a bin's suns at the cell. */
static int bin_crossed(const cell_trees *tr, const sun_bin *b)
{
    if (!tr || !tr->crossed)
        return 0;
    size_t bit = (size_t)b->pair * tr->grid_cells + tr->at;
    return (tr->crossed[bit >> 3] >> (bit & 7)) & 1;
}

/* A bin's beam, circumsolar light and hours of sun at a cell the crowns
 * shade: the leaf-on records' times T_on, the leaf-off ones' times T_off
 * (as the exact run's trees_shade_run, step by step). */
static void bin_through_crowns(const cell_trees *tr, const sun_bin *b, const float nv[3],
                               double *beam, double *circ, double *hours)
{
    float on_beam[3], on_circ[3], on_sun[3];
    for (int i = 0; i < 3; ++i) {
        on_beam[i] = b->beam[i] - b->beam_off[i];
        on_circ[i] = b->circumsolar[i] - b->circumsolar_off[i];
        on_sun[i] = b->sunshine[i] - b->sunshine_off[i];
    }
    *beam += tr->T_on * fmaxf(dot3(nv, on_beam), 0.0f) +
             tr->T_off * fmaxf(dot3(nv, b->beam_off), 0.0f);
    *circ += tr->T_on * fmaxf(dot3(nv, on_circ), 0.0f) +
             tr->T_off * fmaxf(dot3(nv, b->circumsolar_off), 0.0f);
    *hours += (dot3(nv, on_sun) > 0.0f ? tr->T_on * (b->sunshine_hours - b->sunshine_hours_off)
                                       : 0.0f) +
              (dot3(nv, b->sunshine_off) > 0.0f ? tr->T_off * b->sunshine_hours_off : 0.0f);
}

/* A cell's sums over the map into the planes (p): the year's five and
 * each month's global. */
static void cell_sums(const sun_map *m, const ss_cell_terms *t, const cell_trees *tr,
                      const int16_t *stored, size_t stride, size_t c,
                      const ss_insolation_planes *p, size_t n, float *planes)
{
    float norm = sqrtf(1.0f + t->dz_de * t->dz_de + t->dz_dn * t->dz_dn);
    float nv[3] = {-t->dz_de / norm, -t->dz_dn / norm, 1.0f / norm};
    double beam[12] = {0}, circ[12] = {0}, hours = 0;
    for (int k = 0; k < m->n_bins; ++k) {
        const sun_bin *b = &m->bins[k];
        float horizon = ss_stored_horizon(stored[(size_t)b->direction * stride + c]);
        if (!(b->elevation_hours / b->hours > horizon))
            continue;
        if (bin_crossed(tr, b)) {
            bin_through_crowns(tr, b, nv, &beam[b->month], &circ[b->month], &hours);
            continue;
        }
        float beam_dot = nv[0] * b->beam[0] + nv[1] * b->beam[1] + nv[2] * b->beam[2];
        float circ_dot =
            nv[0] * b->circumsolar[0] + nv[1] * b->circumsolar[1] + nv[2] * b->circumsolar[2];
        float sun_dot = nv[0] * b->sunshine[0] + nv[1] * b->sunshine[1] + nv[2] * b->sunshine[2];
        beam[b->month] += fmaxf(beam_dot, 0.0f);
        circ[b->month] += fmaxf(circ_dot, 0.0f);
        hours += sun_dot > 0.0f ? b->sunshine_hours : 0.0f;
    }
    /* Without trees, or with crowns that hide no sky, the leaf-off terms
     * add an exact zero. */
    double sky_off = tr ? (double)tr->sky_view_off - t->sky_view : 0.0;
    double band_off = tr ? (double)tr->band_seen_off - t->band_seen : 0.0;
    double year_beam = 0, year_diffuse = 0, year_reflected = 0;
    for (int month = 0; month < 12; ++month) {
        const month_sums *ms = &m->month[month];
        double diffuse = fmax(ms->isotropic * t->sky_view + ms->isotropic_off * sky_off +
                                  circ[month] + ms->band * t->sin_tilt * t->band_seen +
                                  ms->band_off * t->sin_tilt * band_off,
                              0.0);
        double reflected = ms->reflected * (1.0 - t->sky_view) - ms->reflected_off * sky_off;
        year_beam += beam[month];
        year_diffuse += diffuse;
        year_reflected += reflected;
        if (p->monthly >= 0)
            planes[(size_t)(p->monthly + month) * n + c] =
                (float)(beam[month] + diffuse + reflected);
    }
    planes[(size_t)p->beam * n + c] = (float)year_beam;
    planes[(size_t)p->diffuse * n + c] = (float)year_diffuse;
    planes[(size_t)p->reflected * n + c] = (float)year_reflected;
    planes[(size_t)p->global * n + c] = (float)(year_beam + year_diffuse + year_reflected);
    planes[(size_t)p->hours * n + c] = (float)hours;
}

typedef struct {
    ss_insolation_job *job;
    sun_map *map;
    ss_cell_terms *terms; /* the band's own cells */
    int16_t *stored;      /* its stored horizons, read where they are not in memory */
    /* Trees: the band's terms under leaf-on crowns and its leaf-off ones,
     * and the crowns' crossings (cell_trees). */
    ss_cell_terms *terms_on, *terms_off;
    unsigned char *crossed;
} cumulative_run;

/* Every own cell of a band against the map. */
static ss_status cumulative_band(void *user, const ss_band_view *band, float *planes)
{
    cumulative_run *r = user;
    ss_insolation_job *job = r->job;
    ss_status st = ss_insolation_band_terms(job, band, r->terms);
    size_t n = (size_t)band->n_rows * band->width;
    const int16_t *stored = ss_cell_store_peek(job->horizons, 0, band->row0);
    size_t stride = (size_t)job->src->width * job->src->height;
    if (!stored) {
        for (int d = 0; d < job->opt->directions && st == SS_OK; ++d)
            st = ss_cell_store_get(job->horizons, d, band->row0, band->n_rows,
                                   r->stored + (size_t)d * n);
        stored = r->stored;
        stride = n;
    }
    if (st != SS_OK)
        return st;
    ss_insolation_planes p = ss_insolation_planes_of(job->want);
    const ss_insolation_trees *trees = job->io->trees;
    const ss_cell_terms *terms = r->terms;
    size_t grid_cells = (size_t)job->src->width * job->src->height;
    float T_on = 1.0f, T_off = 1.0f;
    if (trees) {
        T_on = (float)trees->canopy->transmissivity;
        T_off = (float)trees->transmissivity_leaf_off;
        ss_insolation_trees_terms(job, band, T_on, 0, r->terms, r->terms_on);
        ss_insolation_trees_terms(job, band, T_off, 0, r->terms, r->terms_off);
        terms = r->terms_on;
    }
#pragma omp parallel for schedule(dynamic, 256)
    for (size_t c = 0; c < n; ++c)
        if (isfinite(band->own_z[c])) {
            cell_trees tr = {r->crossed, grid_cells, (size_t)band->row0 * band->width + c, T_on, T_off,
                             trees ? r->terms_off[c].sky_view : 0.0f,
                             trees ? r->terms_off[c].band_seen : 0.0f};
            cell_sums(r->map, &terms[c], trees ? &tr : NULL, stored, stride, c, &p, n, planes);
        }
    return ss_insolation_write_band(job, band, planes);
}

/* Trees: the crowns' crossing for each (direction, elevation) pair of
 * bins, swept over the whole grid at the pair's hour-weighted mean sun
 * (ss_canopy_crossed, as the exact run at each step's), a bit per cell;
 * NULL in *crossed where crowns let all the light through in both seasons. */
static ss_status pairs_crossed(ss_insolation_job *job, const sun_map *m, unsigned char **crossed)
{
    const ss_insolation_trees *t = job->io->trees;
    *crossed = NULL;
    if (!t || !m->n_pairs || (t->canopy->transmissivity >= 1.0 && t->transmissivity_leaf_off >= 1.0))
        return SS_OK;
    size_t cells = (size_t)job->src->width * job->src->height;
    size_t bytes = ((size_t)m->n_pairs * cells + 7) / 8;
    unsigned char *bits = ss_calloc(bytes, 1), *one = ss_malloc(cells);
    ss_status st = bits && one ? SS_OK
                               : ss_fail(job->ctx, SS_ERR_MEMORY,
                                         "out of memory for the crowns of %d sun bins (%zu MB)",
                                         m->n_pairs, bytes >> 20);
    for (int q = 0; q < m->n_pairs && st == SS_OK; ++q) {
        const sun_pair *p = &m->pairs[q];
        double az = atan2(p->east_hours, p->north_hours) * 180.0 / M_PI;
        st = ss_insolation_trees_crossed_at(job->ctx, t, job->opt, az < 0 ? az + 360.0 : az,
                                            p->elevation_hours / p->hours, one);
        for (size_t c = 0; st == SS_OK && c < cells; ++c)
            if (one[c]) {
                size_t bit = (size_t)q * cells + c;
                bits[bit >> 3] |= (unsigned char)(1u << (bit & 7));
            }
        if (st == SS_OK)
            st = ss_check_cancel(job->ctx, "the cumulative sky's crowns");
    }
    free(one);
    if (st == SS_OK)
        *crossed = bits;
    else
        free(bits);
    return st;
}

ss_status ss_insolation_cumulative(ss_insolation_job *job, int n_steps)
{
    ss_ctx *ctx = job->ctx;
    const ss_insolation_options *io = job->io;
    const ss_sweep_options *opt = job->opt;
    double step = io->elevation_step_deg > 0 ? io->elevation_step_deg : 1.0;
    if (!(step >= 0.01 && step <= 90.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a sun bin's elevation step must be 0.01 to 90 degrees, not %g", step);
    sun_map m = {0};
    m.directions = opt->directions;
    m.elevations = (int)ceil(90.0 / step) + 1;
    m.step_deg = step;
    m.index = ss_calloc((size_t)12 * m.directions * m.elevations, sizeof *m.index);
    size_t pair_slots = (size_t)m.directions * m.elevations;
    if (io->trees) {
        m.pair_index = ss_calloc(pair_slots, sizeof *m.pair_index);
        m.pairs = ss_calloc(pair_slots, sizeof *m.pairs);
    }
    ss_status st = m.index && (!io->trees || (m.pair_index && m.pairs))
                       ? SS_OK
                       : ss_fail(ctx, SS_ERR_MEMORY,
                                 "out of memory for %d directions of sun bins", m.directions);
    for (int k = 0; k < n_steps && st == SS_OK; ++k) {
        if (!ss_share_has(job->share, k))
            continue;
        ss_sun_step sun;
        st = job->sun_rows(ctx, k, 0, 0, &sun, job->sun_user);
        if (st == SS_OK)
            st = add_step(ctx, &m, opt, io, &sun, k);
        if (st == SS_OK)
            st = ss_check_cancel(ctx, "the cumulative sky");
    }
    const ss_source *src = job->src;
    int rows = ss_source_band_rows(src);
    size_t n = (size_t)rows * src->width;
    cumulative_run r = {job, &m, ss_malloc(n * sizeof(ss_cell_terms)),
                        ss_cell_store_peek(job->horizons, 0, 0)
                            ? NULL
                            : ss_malloc(n * sizeof(int16_t) * (size_t)opt->directions),
                        NULL, NULL, NULL};
    if (io->trees) {
        r.terms_on = ss_malloc(n * sizeof(ss_cell_terms));
        r.terms_off = ss_malloc(n * sizeof(ss_cell_terms));
    }
    if (st == SS_OK && (!r.terms || (!r.stored && !ss_cell_store_peek(job->horizons, 0, 0)) ||
                        (io->trees && (!r.terms_on || !r.terms_off))))
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of insolation");
    if (st == SS_OK)
        st = pairs_crossed(job, &m, &r.crossed);
    ss_consumer consumer = {.planes = ss_insolation_planes_of(job->want).count,
                            .finish = cumulative_band};
    ss_engine_job run = {.walk = {.term = SS_TERM_NONE},
                         .consumer = &consumer,
                         .user = &r,
                         .what = "insolation"};
    if (st == SS_OK)
        st = ss_engine_run(ctx, src, opt, &run);
    if (st == SS_OK) {
        ctx->counters.sun_bins = (uint64_t)m.n_bins;
        st = ss_progress(ctx, 1.0, "insolation");
    }
    free(r.terms);
    free(r.stored);
    free(r.terms_on);
    free(r.terms_off);
    free(r.crossed);
    free(m.bins);
    free(m.index);
    free(m.pair_index);
    free(m.pairs);
    return st;
}
