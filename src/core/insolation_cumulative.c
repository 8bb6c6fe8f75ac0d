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
 * against the exact run is measured in doc/accuracy.md. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "insolation_internal.h"

/* What a bin of suns holds: the beam's and the circumsolar part's sums of
 * weight x sun vector (grid frame: east, north, up; Wh/m^2 on the normal),
 * the hours of sunshine (DNI >= 120 W/m^2) with their sum of sun vectors
 * (whether the surface faces them), and the hours and hour-weighted
 * apparent elevation of its suns. */
typedef struct {
    float beam[3], circumsolar[3], sunshine[3];
    float sunshine_hours, hours, elevation_hours;
    int month, direction;
} sun_bin;

/* Per month: sums over records of what multiplies per-cell terms
 * (ss_sky_parts; Wh/m^2). */
typedef struct {
    double isotropic; /* times the cell's sky view */
    double band;      /* times sin(tilt) times the band the cell sees */
    double reflected; /* times (1 - sky view) */
} month_sums;

typedef struct {
    sun_bin *bins;
    int *index; /* (month x directions + direction) x elevations + bin -> bins entry + 1 */
    int n_bins, capacity, directions, elevations;
    double step_deg;
    month_sums month[12];
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
        m->index[k] = m->n_bins;
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
                          const ss_insolation_options *io, const ss_sun_step *sun)
{
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
    if (!up) { /* sunrise and sunset hours: isotropic, as the exact run */
        ms->isotropic += dhi * dt;
        return SS_OK;
    }
    float h0 = (float)(sun->elevation_deg * M_PI / 180.0);
    ss_sky_parts sky = ss_sky_parts_of((int)io->sky_model, (float)dhi, (float)dni, rec.dni_extra,
                                       0.5f * SS_PI_F - h0);
    ms->isotropic += sky.isotropic * dt;
    ms->band += sky.horizon * dt;
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
    return SS_OK;
}

/* A cell's sums over the map into the planes (p): the year's five and
 * each month's global. */
static void cell_sums(const sun_map *m, const ss_cell_terms *t, const int16_t *stored,
                      size_t stride, size_t c, const ss_insolation_planes *p, size_t n,
                      float *planes)
{
    float norm = sqrtf(1.0f + t->dz_de * t->dz_de + t->dz_dn * t->dz_dn);
    float nv[3] = {-t->dz_de / norm, -t->dz_dn / norm, 1.0f / norm};
    double beam[12] = {0}, circ[12] = {0}, hours = 0;
    for (int k = 0; k < m->n_bins; ++k) {
        const sun_bin *b = &m->bins[k];
        float horizon = ss_stored_horizon(stored[(size_t)b->direction * stride + c]);
        if (!(b->elevation_hours / b->hours > horizon))
            continue;
        float beam_dot = nv[0] * b->beam[0] + nv[1] * b->beam[1] + nv[2] * b->beam[2];
        float circ_dot =
            nv[0] * b->circumsolar[0] + nv[1] * b->circumsolar[1] + nv[2] * b->circumsolar[2];
        float sun_dot = nv[0] * b->sunshine[0] + nv[1] * b->sunshine[1] + nv[2] * b->sunshine[2];
        beam[b->month] += fmaxf(beam_dot, 0.0f);
        circ[b->month] += fmaxf(circ_dot, 0.0f);
        hours += sun_dot > 0.0f ? b->sunshine_hours : 0.0f;
    }
    double year_beam = 0, year_diffuse = 0, year_reflected = 0;
    for (int month = 0; month < 12; ++month) {
        const month_sums *ms = &m->month[month];
        double diffuse = fmax(ms->isotropic * t->sky_view + circ[month] +
                                  ms->band * t->sin_tilt * t->band_seen,
                              0.0);
        double reflected = ms->reflected * (1.0 - t->sky_view);
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
#pragma omp parallel for schedule(dynamic, 256)
    for (size_t c = 0; c < n; ++c)
        if (isfinite(band->own_z[c]))
            cell_sums(r->map, &r->terms[c], stored, stride, c, &p, n, planes);
    return ss_insolation_write_band(job, band, planes);
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
    ss_status st = m.index ? SS_OK
                           : ss_fail(ctx, SS_ERR_MEMORY,
                                     "out of memory for %d directions of sun bins", m.directions);
    for (int k = 0; k < n_steps && st == SS_OK; ++k) {
        if (!ss_share_has(job->share, k))
            continue;
        ss_sun_step sun;
        st = job->sun_rows(ctx, k, 0, 0, &sun, job->sun_user);
        if (st == SS_OK)
            st = add_step(ctx, &m, opt, io, &sun);
        if (st == SS_OK)
            st = ss_check_cancel(ctx, "the cumulative sky");
    }
    const ss_source *src = job->src;
    int rows = ss_source_band_rows(src);
    size_t n = (size_t)rows * src->width;
    cumulative_run r = {job, &m, ss_malloc(n * sizeof(ss_cell_terms)),
                        ss_cell_store_peek(job->horizons, 0, 0)
                            ? NULL
                            : ss_malloc(n * sizeof(int16_t) * (size_t)opt->directions)};
    if (st == SS_OK && (!r.terms || (!r.stored && !ss_cell_store_peek(job->horizons, 0, 0))))
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of insolation");
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
    free(m.bins);
    free(m.index);
    return st;
}
