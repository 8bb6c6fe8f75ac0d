/* Insolation over a time range: for every daylight step, cast shadows (an
 * exact sweep at the sun's azimuth, or horizons interpolated between
 * stored directions), then beam, sky-diffuse and ground-reflected
 * irradiance on each cell's surface (insolation_cell.h), summed in Wh/m^2.
 * Steps are skipped exactly where nothing can happen: at night, and the
 * shadow sweep when the sun stands above any horizon the terrain can cast.
 *
 * A run is a few runs of the one driver: each cell's terms
 * (insolation_terms.c), the stored horizons where interpolated, then the
 * steps, each a direction of its own in step order: walked at its sun's
 * azimuth where it needs an exact shadow sweep, else handed to the cells
 * without a walk. The cumulative sky is insolation_cumulative.c. */
#include "config.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "box_shadow.h"
#include "insolation_internal.h"
#include "insolation_lanes.h"
#include "insolation_trees.h"
#include "lines.h"
#include "lit_levels.h"
#include "skysweep_sun.h"
#include "sun_table.h"

_Static_assert(SS_PV_TEMP_FAIMAN == SS_PV_CELL_TEMP_FAIMAN && SS_PV_TEMP_SAPM == SS_PV_CELL_TEMP_SAPM,
               "ss_pv_temp_model and kernels/ss_pv.h agree");
_Static_assert(SS_SKY_MODEL_ISOTROPIC == SS_SKY_ISOTROPIC &&
                   SS_SKY_MODEL_HAYDAVIES == SS_SKY_HAYDAVIES && SS_SKY_MODEL_PEREZ == SS_SKY_PEREZ,
               "ss_sky_model and kernels/ss_sky_diffuse.h agree");

/* What a step is, decided once before the steps run. */
enum {
    STEP_NONE,   /* missing record, or night: adds nothing */
    STEP_LIT,    /* the sun above every horizon the terrain can cast (or below every cell's
                    horizontal, with light), or a record without light shadows change:
                    no shadows */
    STEP_SWEPT,  /* exact shadows: a sweep at its sun's azimuth */
    STEP_MARCHED, /* exact box-model shadows by bounds and march (box_shadow.h) */
    STEP_STORED  /* interpolated shadows from the stored horizons */
};

/* pvlib.irradiance.get_extra_radiation (method spencer, solar constant
 * 1366.1 W/m^2) for the UTC day of the year of unix_s: Erbs's clearness
 * index follows pvlib's, whatever --solar-constant (r.sun's) is. pvlib
 * takes the day's number, not the instant: the sun's true distance and
 * 1367 W/m^2 differed from it by 0.06 %, which Erbs amplified to 0.2 %. */
static double pvlib_extra_radiation(double unix_s)
{
    ss_civil_time t;
    ss_civil_from_unix(unix_s, &t);
    double day = floor((unix_s - ss_unix_from_civil(t.year, 1, 1, 0, 0, 0)) / 86400.0) + 1.0;
    double b = 2.0 * M_PI * (day - 1.0) / 365.0;
    return 1366.1 * (1.00011 + 0.034221 * cos(b) + 0.00128 * sin(b) + 0.000719 * cos(2.0 * b) +
                     0.000077 * sin(2.0 * b));
}

/* Erbs et al. 1982's diffuse fraction of a clearness index. */
static double erbs_diffuse_fraction(double kt)
{
    if (kt <= 0.22)
        return 1.0 - 0.09 * kt;
    if (kt <= 0.8)
        return 0.9511 - 0.1604 * kt + 4.388 * kt * kt - 16.638 * kt * kt * kt +
               12.336 * kt * kt * kt * kt;
    return 0.165;
}

ss_irradiance_source ss_irradiance_complete(double ghi, double *dni, double *dhi,
                                            double zenith_deg, double unix_s)
{
    if (!isfinite(ghi) || !isnan(*dni))
        return SS_IRRADIANCE_AS_GIVEN;
    double cz = cos(zenith_deg * M_PI / 180.0);
    if (isfinite(*dhi)) {
        double beam = (ghi - *dhi) / cz;
        *dni = beam < 0 || (zenith_deg >= 88.0 && beam != 0) ? 0.0 : beam;
        return SS_IRRADIANCE_CLOSURE;
    }
    if (!isnan(*dhi))
        return SS_IRRADIANCE_AS_GIVEN;
    double kt = fmin(fmax(ghi / (pvlib_extra_radiation(unix_s) * fmax(cz, 0.065)), 0.0), 1.0);
    *dhi = erbs_diffuse_fraction(kt) * ghi;
    *dni = (ghi - *dhi) / cz;
    if (zenith_deg > 87.0 || ghi < 0 || *dni < 0) {
        *dni = 0.0;
        *dhi = ghi;
    }
    return SS_IRRADIANCE_ERBS;
}

int ss_insolation_sky_record(ss_ctx *ctx, const ss_sun_step *sun,
                             const ss_insolation_options *io, ss_sky_record *rec, int *light,
                             int count)
{
    double z = (90.0 - sun->elevation_deg) * M_PI / 180.0;
    double ghi = sun->ghi_w_m2, dni = sun->dni_w_m2, dhi = sun->dhi_w_m2;
    rec->dni_extra = (float)sun->extraterrestrial_w_m2;
    rec->albedo = (float)(isfinite(sun->albedo) ? sun->albedo : io->albedo);
    *light = 0;
    ss_irradiance_source source =
        ss_irradiance_complete(ghi, &dni, &dhi, 90.0 - sun->elevation_deg, sun->unix_s);
    switch (source) {
    case SS_IRRADIANCE_ERBS: ctx->counters.records_split += count; break;
    case SS_IRRADIANCE_CLOSURE: ctx->counters.records_dni_from_closure += count; break;
    case SS_IRRADIANCE_AS_GIVEN: break;
    }
    if (!isfinite(ghi) || !isfinite(dni) || !isfinite(dhi)) {
        ctx->counters.records_missing += count;
        return 0;
    }
    /* A file's beam above the sun's own (1 W/m^2 spared for rounding) is
     * corrupt, not weather. The models' DNI is theirs, as pvlib's. */
    if (source == SS_IRRADIANCE_AS_GIVEN && dni > sun->extraterrestrial_w_m2 + 1.0) {
        ctx->counters.records_dni_above_extraterrestrial += count;
        return 0;
    }
    rec->ghi = (float)ghi;
    rec->dni = (float)dni;
    rec->dhi = (float)dhi;
    *light = ghi > 0 || dni > 0 || dhi > 0;
    /* The sun moves at most 15 degrees an hour: below this, it is down for
     * the record's whole interval. */
    if (*light && sun->elevation_deg + sun->spread_deg < -7.5 * sun->duration_h) {
        ctx->counters.records_light_at_night += count;
        *light = 0;
    }
    double cz = cos(z);
    if (cz > 0 && dni * cz > ghi + fmax(10.0, 0.05 * ghi))
        ctx->counters.records_beam_above_global += count;
    return 1;
}

ss_status ss_insolation_check(ss_ctx *ctx, const ss_insolation_options *io, int n_steps)
{
    const ss_surface *surf = &io->surface;
    if ((unsigned)surf->kind > SS_SURFACE_FIXED ||
        (surf->kind == SS_SURFACE_FIXED &&
         !(surf->tilt_deg >= 0 && surf->tilt_deg <= 90 && isfinite(surf->azimuth_deg))))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a fixed surface needs a tilt of 0 to 90 degrees and an azimuth (tilt %g, "
                       "azimuth %g)",
                       surf->tilt_deg, surf->azimuth_deg);
    if ((unsigned)io->sky_model > SS_SKY_MODEL_PEREZ)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown sky model %d", (int)io->sky_model);
    const ss_pv_options *pv = &io->pv;
    if (pv->on && (!(pv->gamma_pdc > -0.05 && pv->gamma_pdc < 0.05) || !(pv->losses >= 0 && pv->losses < 1) ||
                   (unsigned)pv->temp_model > SS_PV_TEMP_SAPM || !(fabs(pv->temp_air_c) < 100) ||
                   !(pv->wind_speed_m_s >= 0 && pv->wind_speed_m_s < 100)))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "PV yield needs a temperature coefficient within +-0.05 /K, losses in "
                       "0..1, a temperature model, and a plausible air temperature and wind "
                       "(gamma %g, losses %g, %g C, %g m/s)",
                       pv->gamma_pdc, pv->losses, pv->temp_air_c, pv->wind_speed_m_s);
    if (pv->on && (!(pv->inverter_efficiency > 0 && pv->inverter_efficiency <= 1) ||
                   !(pv->dc_ac_ratio >= 0.1 && pv->dc_ac_ratio <= 10)))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the AC yield needs an inverter efficiency in (0, 1] and a DC/AC ratio of "
                       "0.1 to 10 (efficiency %g, ratio %g)",
                       pv->inverter_efficiency, pv->dc_ac_ratio);
    if (!(io->albedo >= 0 && io->albedo <= 1) || n_steps < 1 ||
        (unsigned)io->shadow_mode > SS_SHADOW_CUMULATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "insolation needs an albedo in 0..1, at least one step and a shadow mode "
                       "(albedo %g, %d steps)",
                       io->albedo, n_steps);
    return SS_OK;
}

ss_insolation_planes ss_insolation_planes_of(int want)
{
    ss_insolation_planes p = {0, 1, 2, 3, 4, -1, -1, -1, 5};
    if (want & SS_INSOLATION_MONTHLY) {
        p.monthly = p.count;
        p.count += 12;
    }
    if (want & SS_INSOLATION_PV) {
        p.pv = p.count++;
        p.pv_ac = p.count++;
    }
    return p;
}

ss_status ss_insolation_write_band(const ss_insolation_job *job, const ss_band_view *band,
                                   float *planes)
{
    ss_insolation_planes p = ss_insolation_planes_of(job->want);
    size_t n = (size_t)band->n_rows * band->width;
    ss_status st = ss_share_reduce(job->share, planes, n * (size_t)p.count);
    for (int k = 0; k < p.count; ++k)
        for (size_t c = 0; c < n; ++c)
            if (!isfinite(band->own_z[c]))
                planes[(size_t)k * n + c] = SS_NODATA;
    struct {
        int output, plane, bands;
    } outputs[] = {{SS_OUT_GLOBAL, p.global, 1},    {SS_OUT_BEAM, p.beam, 1},
                   {SS_OUT_DIFFUSE, p.diffuse, 1},  {SS_OUT_REFLECTED, p.reflected, 1},
                   {SS_OUT_SUN_HOURS, p.hours, 1},  {SS_OUT_MONTHLY, p.monthly, 12},
                   {SS_OUT_PV, p.pv, 1},            {SS_OUT_PV_AC, p.pv_ac, 1}};
    for (size_t o = 0; o < sizeof outputs / sizeof outputs[0]; ++o)
        for (int k = 0; outputs[o].plane >= 0 && k < outputs[o].bands && st == SS_OK; ++k)
            st = job->sink(job->user, outputs[o].output, k, band->row0, band->n_rows,
                           planes + (size_t)(outputs[o].plane + k) * n);
    return st;
}

/* ---- the steps --------------------------------------------------------------- */

typedef struct {
    ss_insolation_job *job;
    const unsigned char *kind; /* per step */
    ss_cell_terms *terms;    /* the band's own cells */
    const int16_t *stored;   /* interpolated: the band's stored horizons ... */
    size_t stored_stride;    /* ... D planes this far apart */
    int16_t *stored_band;    /* where they were read into (bands) */
    float *step_global;      /* the step's global over the band's rows (NULL: no step outputs) */
    ss_step_sun *sun;        /* the step's sun terms over the band's cells */
    float pressure_lo, pressure_hi; /* the band's range of air pressure factors */
    uint64_t valid_cells;           /* the band's cells with a height */
    double *lattice_tx;      /* a step's sun lattice's places of the columns (or NULL) */
    size_t lattice_tx_count;
    /* Trees: the terms with the crowns' sky at transmissivity terms_T (NAN:
     * not made for this band), the crowns each step's sun crosses, and
     * (Beer-Lambert) the fraction of its beam each cell keeps. */
    ss_cell_terms *terms_trees;
    float terms_T;
    unsigned char *crossed;
    float *through;
    float *marched; /* a STEP_MARCHED step's horizons over the band's own rows */
    const float *heights; /* the grid's, held whole for the march (ss_source_heights) */
    float *heights_owned;
} steps_run;

/* Where an azimuth (options' frame) falls between the stored directions:
 * the two around it and the weight of the second. */
typedef struct {
    int i0, i1;
    float t;
} stored_between;

static stored_between stored_between_of(const ss_sweep_options *opt, double az)
{
    double pos = fmod((az - opt->offset_deg) / (360.0 / opt->directions), opt->directions);
    if (pos < 0)
        pos += opt->directions;
    stored_between b;
    b.i0 = (int)pos % opt->directions;
    b.i1 = (b.i0 + 1) % opt->directions;
    b.t = (float)(pos - floor(pos));
    return b;
}

/* A weather record's sky split into its parts at the centre's sun, which
 * serve every cell. */
static ss_sky_parts sky_parts_at_centre(const ss_insolation_options *io, const ss_sun_step *sun,
                                        const ss_sky_record *rec)
{
    return ss_sky_parts_of((int)io->sky_model, fmaxf(rec->dhi, 0.0f), fmaxf(rec->dni, 0.0f),
                           rec->dni_extra, (float)((90.0 - sun->elevation_deg) * M_PI / 180.0));
}

/* Whether shadows change anything a weather record gives: a cell's being
 * lit changes its beam, its circumsolar diffuse and its hours of direct
 * sun (which need beam) and nothing else (insolation_cell.h), so a record
 * with neither beam nor circumsolar light needs no shadow sweep. */
static int record_casts_shadows(const ss_insolation_options *io, const ss_sun_step *sun,
                                const ss_sky_record *rec)
{
    return rec->dni > 0.0f || sky_parts_at_centre(io, sun, rec).circumsolar > 0.0f;
}

/* Cell c's step, the run's cell j, computed cell by cell, its sun's terms
 * exactly where they fall outside the step's tables or too far from the
 * centre's sun (ss_lane_cells leaves those cells). */
static ss_cell_step cell_step_behind(const ss_lane_step *l, const ss_lane_suns *suns,
                                     const ss_step_sun *tables, const ss_cell_terms *t,
                                     float horizon, int j)
{
    const float rad = (float)(M_PI / 180.0);
    float az = (suns->az_deg ? suns->az_deg[j] : l->az_step_deg) * rad;
    float h0 = (suns->h0_deg ? suns->h0_deg[j] : l->h0_step_deg) * rad;
    float app = suns->app_deg ? suns->app_deg[j] : l->app_step_deg;
    ss_cell_sun at = ss_step_sun_at(tables, t, h0, az);
    return l->real_sky ? ss_cell_step_weather(t, &at, app, horizon, &l->rec, l->sky, l->dt)
                       : ss_cell_step_of(t, &at, app, horizon, l->g0, l->albedo, l->dt);
}

static ss_cell_step cell_step_exact(const ss_lane_step *l, const ss_lane_suns *suns,
                                    const ss_step_sun *tables, const ss_cell_terms *t, size_t c,
                                    int j)
{
    return cell_step_behind(l, suns, tables, t, ss_lane_horizon(l, c), j);
}

/* Trees: a cell of the run whose ray toward the sun crosses a crown gets T
 * x its step lit plus (1 - T) x its step in shadow, which passes T of the
 * beam, of the circumsolar diffuse and of the hours of sun (and, under the
 * clear sky, weighs Muneer's sunlit and shaded diffuse so); a cell the
 * terrain shades loses nothing more. Both steps are the cell's exact sun's.
 * T is the step's, or with Beer-Lambert (through given) the cell's own. */
static void trees_shade_run(const ss_lane_step *l, const ss_lane_suns *suns,
                            const ss_step_sun *tables, const ss_cell_terms *terms,
                            const unsigned char *crossed, const float *through, float T,
                            size_t c0, int m, ss_lane_adds *a)
{
    for (int j = 0; j < m; ++j) {
        size_t c = c0 + (size_t)j;
        /* Beer-Lambert's fraction is below 1 exactly where a path crosses
         * a crown (SS_NODATA at nodata). */
        int shaded = through ? through[c] >= 0.0f && through[c] < 1.0f : crossed[c];
        if (a->what[j] == SS_LANE_SKIP || !shaded)
            continue;
        ss_cell_step lit = cell_step_exact(l, suns, tables, &terms[c], c, j);
        ss_cell_step dark = cell_step_behind(l, suns, tables, &terms[c], 90.0f, j);
        float keep = 1.0f - (through ? through[c] : T);
        ss_cell_step d = {keep * (dark.beam - lit.beam), keep * (dark.diffuse - lit.diffuse),
                          keep * (dark.reflected - lit.reflected),
                          keep * (dark.total - lit.total),
                          keep * (dark.sun_hours - lit.sun_hours)};
        l->beam[c] += d.beam;
        l->diffuse[c] += d.diffuse;
        l->reflected[c] += d.reflected;
        l->global[c] += d.total;
        l->sun_hours[c] += d.sun_hours;
        if (l->month)
            l->month[c] += d.total;
        a->global[j] += d.total;
    }
}

/* A step's per-cell array from a run's first cell (NULL: none). */
static const float *run_of(const float *per_cell, size_t c0)
{
    return per_cell ? per_cell + c0 : NULL;
}

/* Whether a step's lattice spans the band's cells (skysweep.h): a caller's
 * that did not would leave cells without a sun, or extrapolate. */
static int lattice_spans(const ss_sun_lattice *l, const ss_band_view *band)
{
    int nc = l->n_cols, nr = l->n_rows, ok = nc >= 2 && nr >= 2;
    for (int i = 1; ok && i < nc; ++i)
        ok = l->cols[i] >= l->cols[i - 1];
    for (int j = 1; ok && j < nr; ++j)
        ok = l->rows[j] >= l->rows[j - 1];
    return ok && l->cols[0] == 0 && l->cols[nc - 1] == band->width - 1 &&
           l->rows[0] <= band->row0 && l->rows[nr - 1] >= band->row0 + band->n_rows - 1;
}

/* Refuses step k's lattice where it does not span the band (lattice_spans). */
static ss_status lattice_check(steps_run *s, const ss_sun_lattice *lattice,
                               const ss_band_view *band, int k)
{
    return lattice_spans(lattice, band)
               ? SS_OK
               : ss_fail(s->job->ctx, SS_ERR_ARGUMENT,
                         "time step %d's sun lattice does not span columns 0..%d and rows %d..%d "
                         "in increasing order",
                         k, band->width - 1, band->row0, band->row0 + band->n_rows - 1);
}

/* The places of a step's lattice's columns (ss_sun_lattice_tx) into
 * s->lattice_tx, once its span is checked. */
static ss_status lattice_columns(steps_run *s, const ss_sun_lattice *lattice,
                                 const ss_band_view *band, int k)
{
    ss_status st = lattice_check(s, lattice, band, k);
    if (st != SS_OK)
        return st;
    size_t count = ss_sun_lattice_tx_count(lattice);
    if (count > s->lattice_tx_count) {
        double *tx = ss_realloc(s->lattice_tx, count * sizeof(double));
        if (!tx)
            return ss_fail(s->job->ctx, SS_ERR_MEMORY, "out of memory for the sun's lattice");
        s->lattice_tx = tx;
        s->lattice_tx_count = count;
    }
    ss_sun_lattice_tx(lattice, s->lattice_tx);
    return SS_OK;
}

/* The suns of the band's cells [c0, c0 + n) from a step's lattice, into
 * the run's buffers (ss_lane_suns). */
static void lattice_run(const ss_sun_lattice *lattice, const double *tx,
                        const ss_band_view *band, size_t c0, int n, float *h0, float *az,
                        float *app)
{
    for (int j = 0; j < n;) {
        size_t c = c0 + (size_t)j;
        int row = band->row0 + (int)(c / (size_t)band->width), col = (int)(c % (size_t)band->width);
        int m = band->width - col < n - j ? band->width - col : n - j;
        ss_sun_lattice_cells(lattice, tx, row, col, m, az + j, h0 + j, app + j);
        j += m;
    }
}

/* A lattice's range of true elevations and azimuths in radians as the
 * cells take them (degrees to radians in float), widened by 1e-5 rad for
 * the floats' rounding: the cells' suns are interpolated between the
 * nodes, and a wider range only fills more nodes of the same lattice
 * (sun_table.h), so the tables give what the cells' own range gives. A
 * clear sky's range holds the suns above the horizontal alone. */
static void lattice_range(const ss_sun_lattice *l, int above_only, float *h_lo, float *h_hi,
                          float *a_lo, float *a_hi)
{
    const float rad = (float)(M_PI / 180.0), margin = 1e-5f;
    double e_lo = INFINITY, e_hi = -INFINITY, z_lo = INFINITY, z_hi = -INFINITY;
    for (int k = 0; k < l->n_cols * l->n_rows; ++k) {
        e_lo = fmin(e_lo, l->elevation_deg[k]);
        e_hi = fmax(e_hi, l->elevation_deg[k]);
        z_lo = fmin(z_lo, l->grid_azimuth_deg[k]);
        z_hi = fmax(z_hi, l->grid_azimuth_deg[k]);
    }
    *h_lo = (float)e_lo * rad - margin;
    *h_hi = (float)e_hi * rad + margin;
    *a_lo = (float)z_lo * rad - margin;
    *a_hi = (float)z_hi * rad + margin;
    if (above_only && *h_hi <= 0.0f) {
        *h_lo = INFINITY;
        *h_hi = -INFINITY;
    } else if (above_only) {
        *h_lo = fmaxf(*h_lo, FLT_MIN);
    }
}

/* The range of the air pressure factors of a band's own cells, for the
 * steps' tables of the air mass. */
static void band_pressure_range(steps_run *s, const ss_band_view *band)
{
    size_t n = (size_t)band->n_rows * band->width;
    s->pressure_lo = INFINITY;
    s->pressure_hi = -INFINITY;
    s->valid_cells = 0;
    for (size_t c = 0; c < n; ++c)
        if (isfinite(band->own_z[c])) {
            s->valid_cells++;
            s->pressure_lo = fminf(s->pressure_lo, s->terms[c].pressure_factor);
            s->pressure_hi = fmaxf(s->pressure_hi, s->terms[c].pressure_factor);
        }
}

static ss_status steps_visit(void *user, const ss_band_view *band)
{
    steps_run *s = user;
    ss_insolation_job *job = s->job;
    ss_status st = ss_insolation_band_terms(job, band, s->terms);
    size_t n = (size_t)band->n_rows * band->width;
    if (st != SS_OK)
        return st;
    band_pressure_range(s, band);
    s->terms_T = NAN;
    s->stored = NULL;
    if (job->horizons) {
        /* Interpolated shadows read the band's stored horizons, in place
         * where they are in memory. */
        s->stored = ss_cell_store_peek(job->horizons, 0, band->row0);
        s->stored_stride = (size_t)job->src->width * job->src->height;
    }
    if (job->horizons && !s->stored) {
        for (int d = 0; d < job->opt->directions && st == SS_OK; ++d)
            st = ss_cell_store_get(job->horizons, d, band->row0, band->n_rows,
                                   s->stored_band + (size_t)d * n);
        s->stored = s->stored_band;
        s->stored_stride = n;
    }
    if (st == SS_OK && band->device)
        st = ss_engine_cells_begin(band->device, s->terms,
                                   ss_insolation_planes_of(job->want).count, s->stored,
                                   s->stored_stride);
    return st;
}

/* A weather record's PV: whether a step yields (the PV planes kept, a
 * record, the options' PV on), and its system and air. */
typedef struct {
    int on;
    ss_pv_step terms;
} step_pv;

static step_pv step_pv_of(const ss_insolation_options *io, const ss_sun_step *sun,
                          const ss_insolation_planes *p)
{
    step_pv s;
    s.on = p->pv >= 0 && sun->real_sky && io->pv.on;
    ss_pv_step *v = &s.terms;
    v->temp_model = (int)io->pv.temp_model;
    v->temp_air = (float)(isnan(sun->temp_air_c) ? io->pv.temp_air_c : sun->temp_air_c);
    v->wind = (float)(isnan(sun->wind_speed_m_s) ? io->pv.wind_speed_m_s : sun->wind_speed_m_s);
    v->gamma_pdc = (float)io->pv.gamma_pdc;
    v->losses = (float)io->pv.losses;
    /* The inverter's DC input limit per kWp of modules: its AC rating
     * (1 / the DC/AC ratio) over its nominal efficiency. */
    v->eta_inv = (float)io->pv.inverter_efficiency;
    v->inv_pdc0 = s.on ? (float)(1.0 / (io->pv.dc_ac_ratio * io->pv.inverter_efficiency)) : 1.0f;
    return s;
}

/* A step added on the device (kernels/ss_insolation_cells.h), its
 * horizons the walk's rows left there, the stored ones (between) or none;
 * every valid cell counts as a cell step. Its global, nodata included,
 * comes back to step_global where the run writes each step. */
static ss_status device_step(steps_run *s, int k, const ss_band_view *band, int kind,
                             const ss_dir_rows *rows, stored_between between,
                             const ss_sun_step *sun, const ss_sky_record *rec, ss_sky_parts sky,
                             const ss_insolation_planes *p, int month_plane, const step_pv *pv)
{
    const ss_sun_lattice *l = sun->lattice;
    ss_cells_step step = {
        .cells = band->n_rows * band->width,
        .width = band->width,
        .row0 = band->row0,
        .horizon = kind == STEP_SWEPT && rows ? SS_CELLS_WALKED
                   : kind == STEP_STORED          ? SS_CELLS_STORED
                                                  : SS_CELLS_NO_HORIZON,
        .stored0 = between.i0,
        .stored1 = between.i1,
        .stored_t = between.t,
        .step_out = s->step_global != NULL,
        .real_sky = sun->real_sky != 0,
        .lattice = l != NULL,
        .lattice_cols = l ? l->n_cols : 0,
        .lattice_rows = l ? l->n_rows : 0,
        .h0_deg = (float)sun->elevation_deg,
        .az_deg = (float)sun->grid_azimuth_deg,
        .app_deg = (float)sun->apparent_elevation_deg,
        .centre = ss_sun_centre_of((float)sun->elevation_deg, (float)sun->grid_azimuth_deg),
        .linke = (float)sun->linke,
        .g0 = (float)sun->extraterrestrial_w_m2,
        .albedo = (float)s->job->io->albedo,
        .dt = (float)sun->duration_h,
        .rec = *rec,
        .sky = sky,
        .beam = p->beam,
        .diffuse = p->diffuse,
        .reflected = p->reflected,
        .total = p->global,
        .hours = p->hours,
        .month = month_plane,
        .pv = pv->on ? p->pv : -1,
        .pv_ac = pv->on ? p->pv_ac : -1,
        .pv_step = pv->terms};
    ss_status st = l ? lattice_check(s, l, band, k) : SS_OK;
    if (st != SS_OK)
        return st;
    s->job->ctx->counters.cell_steps += s->valid_cells;
    s->job->ctx->counters.cell_steps_on_device += s->valid_cells;
    return ss_engine_cells_step(band->device, kind == STEP_SWEPT ? rows : NULL, &step, l,
                                s->step_global);
}

/* A step's global over the band before the host adds its cells: 0, and
 * the output's nodata at nodata. */
static void step_global_clear(float *step_global, const ss_band_view *band)
{
    size_t n = (size_t)band->n_rows * band->width;
    for (size_t c = 0; step_global && c < n; ++c)
        step_global[c] = isfinite(band->own_z[c]) ? 0.0f : SS_NODATA;
}

/* Trees at step k: its transmissivity T, the band's terms with the
 * crowns' sky at T (made again where T changes), and the crowns its sun
 * crosses from the band's cells, or with Beer-Lambert the fraction of the
 * beam each keeps (both NULL where no beam or circumsolar light could be
 * shaded, or the crowns pass all of it). */
static ss_status step_trees(steps_run *s, int k, const ss_band_view *band, const ss_sun_step *sun,
                            const ss_sky_record *rec, float *T, const ss_cell_terms **terms,
                            const unsigned char **crossed, const float **through)
{
    const ss_insolation_trees *t = s->job->io->trees;
    *T = ss_insolation_trees_transmissivity(t, k);
    int beer_lambert = ss_insolation_trees_beer_lambert(t, k);
    /* Beer-Lambert's sky is each cell's own: keyed -1, no transmissivity. */
    float key = beer_lambert ? -1.0f : *T;
    if (!(s->terms_T == key)) {
        ss_insolation_trees_terms(s->job, band, *T, beer_lambert, s->terms, s->terms_trees);
        s->terms_T = key;
    }
    *terms = s->terms_trees;
    int shaded = sun->apparent_elevation_deg > 0.0 && (beer_lambert || *T < 1.0f) &&
                 (!sun->real_sky || record_casts_shadows(s->job->io, sun, rec));
    if (!shaded)
        return SS_OK;
    size_t at = (size_t)band->row0 * band->width;
    if (beer_lambert) {
        *through = s->through + at;
        return ss_insolation_trees_through(s->job->ctx, t, sun, s->through);
    }
    *crossed = s->crossed + at;
    /* The band's rows; cells the step's marched solid shadows shade need
     * no crowns. */
    return ss_insolation_trees_crossed(s->job->ctx, t, s->job->opt, sun, band->row0,
                                       band->n_rows,
                                       s->kind[k] == STEP_MARCHED ? s->marched : NULL, s->crossed);
}

/* A STEP_MARCHED step's horizons over the band's own rows, from the
 * heights held whole: right for every sun between the step's lowest and
 * highest over the cells. */
static ss_status march_step(steps_run *s, const ss_band_view *band, const ss_sun_step *sun)
{
    ss_insolation_job *job = s->job;
    ss_grid grid = {band->width, band->height, job->src->cell_x_m, job->src->cell_y_m, 0.0,
                    (float *)s->heights};
    ss_box_ray_counts counts;
    if (!ss_box_shadow_horizons(&grid, sun->azimuth_deg - job->opt->grid_north_deg,
                                sun->apparent_elevation_deg - sun->spread_deg,
                                sun->apparent_elevation_deg + sun->spread_deg,
                                ss_curvature_k(job->opt), band->row0, band->n_rows,
                                &job->ctx->cancel_requested, s->marched, &counts))
        return ss_fail(job->ctx, SS_ERR_MEMORY, "out of memory for the box shadows' lines");
    /* A step counts once, at its first band. */
    job->ctx->counters.box_march_steps += band->row0 == 0;
    job->ctx->counters.box_march_cells += counts.cells;
    job->ctx->counters.box_march_marched += counts.marched;
    return ss_check_cancel(job->ctx, "the box shadows");
}

/* Step k over a band's own cells: its shadows (rows of the walk at its
 * sun's azimuth, the stored horizons, or none), irradiance added into the
 * planes, its global to the step's output where asked for. */
static ss_status steps_direction(void *user, int k, const ss_band_view *band,
                                 const ss_dir_rows *rows, float *planes)
{
    steps_run *s = user;
    ss_insolation_job *job = s->job;
    const ss_insolation_options *io = job->io;
    size_t n = (size_t)band->n_rows * band->width;
    int kind = s->kind[k];
    ss_sun_step sun = {0};
    ss_sky_record rec = {0};
    ss_sky_parts sky = {0.0f, 0.0f, 0.0f};
    int light = 0;
    ss_status st = kind == STEP_NONE
                       ? SS_OK
                       : job->sun_rows(job->ctx, k, band->row0, band->n_rows, &sun, job->sun_user);
    float *step_global = s->step_global;
    if (st == SS_OK && kind == STEP_NONE)
        step_global_clear(step_global, band);
    if (st == SS_OK && kind != STEP_NONE) {
        if (sun.real_sky) {
            ss_insolation_sky_record(job->ctx, &sun, io, &rec, &light, 0);
            sky = sky_parts_at_centre(io, &sun, &rec);
        }
        ss_insolation_planes p = ss_insolation_planes_of(job->want);
        step_pv pvs = step_pv_of(io, &sun, &p);
        int month_plane = p.monthly >= 0 && sun.month >= 1 && sun.month <= 12
                              ? p.monthly + sun.month - 1
                              : -1;
        stored_between between =
            kind == STEP_STORED ? stored_between_of(job->opt, sun.azimuth_deg) : (stored_between){0};
        if (band->device && !io->trees && (sun.lattice || !(sun.elevation_per_cell ||
                                              sun.grid_azimuth_per_cell || sun.apparent_per_cell))) {
            st = device_step(s, k, band, kind, rows, between, &sun, &rec, sky, &p, month_plane,
                             &pvs);
            return st == SS_OK && step_global ? job->sink(job->user, SS_OUT_STEP, k, band->row0,
                                                          band->n_rows, step_global)
                                              : st;
        }
        step_global_clear(step_global, band);
        /* The walk's rows, where they were left on the device. */
        ss_dir_rows read = rows ? *rows : (ss_dir_rows){NULL, NULL, NULL, 0};
        if (band->device && kind == STEP_SWEPT)
            st = ss_engine_device_rows(band->device, &read);
        if (st == SS_OK && kind == STEP_MARCHED)
            st = march_step(s, band, &sun);
        float *beam = planes + (size_t)p.beam * n, *diffuse = planes + (size_t)p.diffuse * n;
        float *reflected = planes + (size_t)p.reflected * n, *global = planes + (size_t)p.global * n;
        float *hours = planes + (size_t)p.hours * n;
        float *month = month_plane >= 0 ? planes + (size_t)month_plane * n : NULL;
        int pv_on = pvs.on;
        float *pv = pv_on ? planes + (size_t)p.pv * n : NULL;
        float *pv_ac = pv_on ? planes + (size_t)p.pv_ac * n : NULL;
        float dt = (float)sun.duration_h;
        const ss_sun_lattice *lattice = sun.lattice;
        const ss_cell_terms *terms = s->terms;
        float T = 1.0f;
        const unsigned char *crossed = NULL;
        const float *through = NULL;
        if (st == SS_OK && io->trees)
            st = step_trees(s, k, band, &sun, &rec, &T, &terms, &crossed, &through);
        if (st == SS_OK && lattice) {
            float h_lo, h_hi, a_lo, a_hi;
            lattice_range(lattice, !sun.real_sky, &h_lo, &h_hi, &a_lo, &a_hi);
            ss_step_sun_fill_range(s->sun, h_lo, h_hi, a_lo, a_hi, (float)sun.elevation_deg,
                                   (float)sun.grid_azimuth_deg, (float)sun.linke, !sun.real_sky,
                                   s->pressure_lo, s->pressure_hi);
            st = lattice_columns(s, lattice, band, k);
        } else if (st == SS_OK) {
            ss_step_sun_fill(s->sun, sun.elevation_per_cell, sun.grid_azimuth_per_cell, n,
                             (float)sun.elevation_deg, (float)sun.grid_azimuth_deg,
                             (float)sun.linke, !sun.real_sky, s->pressure_lo, s->pressure_hi);
        }
        ss_lane_step lane = {
            .tables = s->sun,
            .h0_step_deg = (float)sun.elevation_deg,
            .az_step_deg = (float)sun.grid_azimuth_deg,
            .app_step_deg = (float)sun.apparent_elevation_deg,
            .swept = kind == STEP_SWEPT ? read.angle : kind == STEP_MARCHED ? s->marched : NULL,
            .stored0 = kind == STEP_STORED ? s->stored + (size_t)between.i0 * s->stored_stride : NULL,
            .stored1 = kind == STEP_STORED ? s->stored + (size_t)between.i1 * s->stored_stride : NULL,
            .stored_t = between.t,
            .real_sky = sun.real_sky,
            .g0 = (float)sun.extraterrestrial_w_m2,
            .albedo = (float)io->albedo,
            .dt = dt,
            .rec = rec,
            .sky = sky,
            .beam = beam,
            .diffuse = diffuse,
            .reflected = reflected,
            .global = global,
            .sun_hours = hours,
            .month = month};
        uint64_t cells = 0, exact = 0;
#pragma omp parallel for schedule(static) reduction(+ : cells, exact)
        for (size_t c0 = 0; c0 < (st == SS_OK ? n : 0); c0 += SS_LANE_CELLS) {
            int m = n - c0 < SS_LANE_CELLS ? (int)(n - c0) : SS_LANE_CELLS;
            /* The run's suns: from the lattice here, where they stay in
             * cache, or the step's arrays. */
            float run_h0[SS_LANE_CELLS], run_az[SS_LANE_CELLS], run_app[SS_LANE_CELLS];
            ss_lane_suns suns = {run_h0, run_az, run_app};
            if (lattice)
                lattice_run(lattice, s->lattice_tx, band, c0, m, run_h0, run_az, run_app);
            else
                suns = (ss_lane_suns){run_of(sun.elevation_per_cell, c0),
                                      run_of(sun.grid_azimuth_per_cell, c0),
                                      run_of(sun.apparent_per_cell, c0)};
            ss_lane_adds a;
            ss_lane_cells(&lane, &suns, band->own_z, terms, c0, m, &a);
            /* Counted in int over the run, which GCC vectorises (in the
             * 64-bit sums it did not: 4 % of a weather year's time). */
            int run_cells = 0, run_exact = 0;
            for (int j = 0; j < m; ++j) {
                run_cells += a.what[j] != SS_LANE_SKIP;
                run_exact += a.what[j] == SS_LANE_EXACT;
            }
            cells += (uint64_t)run_cells;
            exact += (uint64_t)run_exact;
            for (int j = 0; run_exact && j < m; ++j)
                if (a.what[j] == SS_LANE_EXACT) {
                    size_t c = c0 + (size_t)j;
                    ss_cell_step add = cell_step_exact(&lane, &suns, s->sun, &terms[c], c, j);
                    beam[c] += add.beam;
                    diffuse[c] += add.diffuse;
                    reflected[c] += add.reflected;
                    global[c] += add.total;
                    hours[c] += add.sun_hours;
                    if (month)
                        month[c] += add.total;
                    a.global[j] = add.total;
                }
            if (crossed || through)
                trees_shade_run(&lane, &suns, s->sun, terms, crossed, through, T, c0, m, &a);
            for (int j = 0; (pv_on || step_global) && j < m; ++j) {
                size_t c = c0 + (size_t)j;
                if (a.what[j] == SS_LANE_SKIP)
                    continue;
                if (pv_on && dt > 0.0f) {
                    float dc, ac;
                    ss_cell_pv_yield(&pvs.terms, a.global[j], dt, &dc, &ac);
                    pv[c] += dc;
                    pv_ac[c] += ac;
                }
                if (step_global)
                    step_global[c] = a.global[j];
            }
        }
        job->ctx->counters.cell_steps += cells;
        job->ctx->counters.cell_steps_exact_sun += exact;
    }
    if (st == SS_OK && step_global)
        st = job->sink(job->user, SS_OUT_STEP, k, band->row0, band->n_rows, step_global);
    return st;
}

static ss_status steps_finish(void *user, const ss_band_view *band, float *planes)
{
    steps_run *s = user;
    return ss_insolation_write_band(s->job, band, planes);
}

/* What every step of this process is, decided before the run: its kind,
 * the steps as the driver's directions, and whether any is a weather
 * record. */
typedef struct {
    unsigned char *kind; /* per step */
    ss_engine_dir *dirs;
    int n_dirs, real_sky;
    int n_swept; /* steps with a shadow walk */
    int n_marched; /* steps with box shadows by bounds and march */
} steps_plan;

/* Decides what every step of this process is (kind), counting the night
 * steps, the daylight steps and the shadow sweeps skipped, and lists them
 * as the driver's directions. */
static ss_status classify_steps(ss_insolation_job *job, int n_steps, steps_plan *plan)
{
    unsigned char *kind = plan->kind;
    ss_ctx *ctx = job->ctx;
    const ss_insolation_options *io = job->io;
    double bound_deg;
    ss_status st = ss_horizon_bound_of(ctx, job->src, job->opt, &bound_deg);
    if (st != SS_OK)
        return st;
    plan->n_dirs = plan->n_swept = plan->n_marched = 0;
    int marched = ss_box_shadows_marched(job->opt);
    for (int k = 0; k < n_steps; ++k) {
        if (!ss_share_has(job->share, k))
            continue; /* another process's step */
        ss_sun_step sun;
        st = job->sun_rows(ctx, k, 0, 0, &sun, job->sun_user);
        if (st != SS_OK)
            return st;
        ss_sky_record rec;
        int light = 0;
        int missing = sun.real_sky && !ss_insolation_sky_record(ctx, &sun, io, &rec, &light, 1);
        plan->real_sky |= sun.real_sky != 0;
        int sun_up = sun.elevation_deg + sun.spread_deg > 0.0;
        kind[k] = STEP_NONE;
        if (missing) {
            /* counted by ss_insolation_sky_record */
        } else if (!sun_up && !light) {
            ctx->counters.night_steps_skipped++;
        } else {
            ctx->counters.time_steps++;
            /* Shadows: none can fall where the sun is above every horizon,
             * and none is cast by a sun below every cell's horizontal; nor
             * do they matter to a record without light they could shade. */
            int all_lit = !sun_up || sun.apparent_elevation_deg - sun.spread_deg > bound_deg;
            int unshaded = !all_lit && sun.real_sky && !record_casts_shadows(io, &sun, &rec);
            if (all_lit)
                ctx->counters.shadow_sweeps_skipped += sun_up;
            ctx->counters.shadow_sweeps_unshaded += unshaded;
            all_lit |= unshaded;
            kind[k] = all_lit                                        ? STEP_LIT
                      : io->shadow_mode != SS_SHADOW_EXACT ? STEP_STORED
                      : marched                            ? STEP_MARCHED
                                                           : STEP_SWEPT;
            if ((job->want & SS_INSOLATION_PV) && sun.real_sky && io->pv.on &&
                (isnan(sun.temp_air_c) || isnan(sun.wind_speed_m_s)))
                ctx->counters.records_without_temperature++;
        }
        /* The lowest the sun stands over the cells: those whose horizons all
         * lie below it need no walk (lit_levels.h). */
        int lit_level = ss_lit_level_below(sun.apparent_elevation_deg - sun.spread_deg);
        plan->n_swept += kind[k] == STEP_SWEPT;
        plan->n_marched += kind[k] == STEP_MARCHED;
        plan->dirs[plan->n_dirs++] =
            (ss_engine_dir){sun.azimuth_deg, kind[k] == STEP_SWEPT, k, lit_level};
    }
    return SS_OK;
}

static ss_status plan_steps(ss_insolation_job *job, int n_steps, steps_plan *plan)
{
    plan->kind = ss_calloc((size_t)n_steps, 1);
    plan->dirs = ss_malloc(sizeof *plan->dirs * (size_t)n_steps);
    if (!plan->kind || !plan->dirs)
        return ss_fail(job->ctx, SS_ERR_MEMORY, "out of memory for %d time steps", n_steps);
    return classify_steps(job, n_steps, plan);
}

/* Each cell's bound level per sector of azimuth (lit_levels.h), where exact shadows are walked
 * and ss_lit_levels_used says they repay it: of a grid held whole into
 * *levels, of one read in bands into *bands; else neither, and where
 * memory is short too: the walks then go whole. Their work space is freed
 * before the steps' buffers (about 90 bytes a cell, band_memory.c) are
 * made, so on a grid held whole it adds nothing to the peak; the levels
 * kept, a byte a cell and sector, are in ss_insolation_band_cell_bytes. */
static ss_status shadow_levels(const ss_insolation_job *job, const steps_plan *plan,
                               unsigned char **levels, ss_lit_bands **bands)
{
    const ss_source *src = job->src;
    int box = job->opt->lines == SS_LINES_BOX, families = box ? job->opt->box_lines : 0;
    int sectors = ss_lit_sectors_for(plan->n_swept, job->opt->lines, families);
    *levels = NULL;
    *bands = NULL;
    if (!ss_lit_levels_used(plan->n_swept, job->opt->lines))
        return SS_OK;
    int banded = ss_source_band_rows(src) < src->height;
    /* In bands the levels are made a window at a time before the band's
     * buffers: where a window's making needs more than the band a memory
     * plan sized (narrow bands under a tight --memory), the walks go whole. */
    int rows = ss_source_band_rows(src);
    if (banded && job->ctx->memory.band_rows > 0 &&
        (double)SS_LIT_MAKING_CELL_BYTES * ss_lit_bands_window_rows(rows, src->height) >
            (ss_horizon_band_cell_bytes(0) + ss_insolation_band_cell_bytes(job->want, 0)) * rows)
        return SS_OK;
    if (!src->z || banded)
        return ss_lit_bands_make(job->ctx, src, families, sectors, bands);
    *levels = box ? ss_lit_levels_box(src->z, src->width, src->height, src->cell_x_m,
                                      src->cell_y_m, families, sectors)
                  : ss_lit_levels(src->z, src->width, src->height, src->cell_x_m, src->cell_y_m,
                                  sectors);
    return SS_OK;
}

static ss_status run_steps(ss_insolation_job *job, const steps_plan *plan)
{
    const ss_source *src = job->src;
    int rows = ss_source_band_rows(src);
    size_t n = (size_t)rows * src->width;
    unsigned char *levels;
    ss_lit_bands *bands;
    ss_status st = shadow_levels(job, plan, &levels, &bands);
    /* Stored horizons not held in memory are read band by band. */
    int read_stored = job->horizons && !ss_cell_store_peek(job->horizons, 0, 0);
    steps_run s = {
        .job = job,
        .kind = plan->kind,
        .terms = ss_malloc(n * sizeof(ss_cell_terms)),
        .stored_band = read_stored
                           ? ss_malloc(n * sizeof(int16_t) * (size_t)job->opt->directions)
                           : NULL,
        .step_global = job->want & SS_INSOLATION_STEPS ? ss_malloc(n * sizeof(float)) : NULL,
        .sun = ss_malloc(sizeof(ss_step_sun))};
    int steps_out = (job->want & SS_INSOLATION_STEPS) != 0;
    int trees = job->io->trees != NULL;
    int beer_lambert = trees && job->io->trees->leaf_area_density > 0.0;
    if (trees) {
        s.terms_trees = ss_malloc(n * sizeof(ss_cell_terms));
        s.crossed = ss_malloc((size_t)src->width * src->height);
    }
    if (beer_lambert)
        s.through = ss_malloc((size_t)src->width * src->height * sizeof(float));
    if (plan->n_marched) {
        s.marched = ss_malloc(n * sizeof(float));
        if (st == SS_OK)
            st = ss_source_heights(job->ctx, src, &s.heights_owned, &s.heights);
    }
    if (st == SS_OK &&
        (!s.terms || (steps_out && !s.step_global) || !s.sun || (read_stored && !s.stored_band) ||
         (trees && (!s.terms_trees || !s.crossed)) || (beer_lambert && !s.through) ||
         (plan->n_marched && !s.marched)))
        st = ss_fail(job->ctx, SS_ERR_MEMORY, "out of memory for a band of insolation");
    /* Steps go to the device where the backend can take them, with the
     * stored horizons of interpolated shadows. */
    ss_consumer consumer = {.planes = ss_insolation_planes_of(job->want).count,
                            .visit = steps_visit,
                            .direction = steps_direction,
                            .finish = steps_finish,
                            /* The crowns and the box shadows' march run on
                             * the host: so do the steps that use them. */
                            .device_cells = !trees && !plan->n_marched,
                            .device_stored = job->horizons ? job->opt->directions : 0};
    ss_engine_job run = {.walk = {.term = SS_TERM_HORIZON,
                                  .none_deg = 0.0f,
                                  .lit_levels = levels,
                                  .lit_bands = bands},
                         .dirs = plan->dirs,
                         .n_dirs = plan->n_dirs,
                         .group = SS_INSOLATION_STEPS_PER_RUN,
                         .consumer = &consumer,
                         .user = &s,
                         .what = "insolation"};
    if (st == SS_OK)
        st = ss_engine_run(job->ctx, src, job->opt, &run);
    free(s.terms);
    free(s.stored_band);
    free(s.step_global);
    free(s.sun);
    free(s.lattice_tx);
    free(s.terms_trees);
    free(s.crossed);
    free(s.through);
    free(s.marched);
    free(s.heights_owned);
    free(levels);
    ss_lit_bands_free(bands);
    return st;
}

/* ss_insolation_rows on a DEM and options already checked. */
static ss_status run_insolation(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                                const ss_insolation_options *io, int n_steps,
                                ss_sun_rows_fn sun_rows, void *sun_user, int want,
                                const ss_share *share, ss_rows_sink sink, void *user)
{
    if (io->shadow_mode == SS_SHADOW_CUMULATIVE && (want & SS_INSOLATION_STEPS))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the cumulative sky has no per-step bands: use exact or interpolated "
                       "shadows with them");
    if (io->shadow_mode == SS_SHADOW_CUMULATIVE && (io->pv.on || (want & SS_INSOLATION_PV)))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the cumulative sky gives no PV yield (its cell temperature needs each "
                       "record's irradiance): use exact or interpolated shadows with it");
    ss_insolation_job job = {ctx,  src,  opt,  io,   share, sun_rows, sun_user,
                             want, sink, user, 0,    NULL, NULL, NULL, NULL, NULL};
    int cumulative = io->shadow_mode == SS_SHADOW_CUMULATIVE;
    steps_plan plan = {NULL, NULL, 0, 0, 0, 0};
    ss_status st = io->trees ? ss_insolation_trees_check(ctx, io, src) : SS_OK;
    if (st == SS_OK && !cumulative)
        st = plan_steps(&job, n_steps, &plan);
    /* The clear sky's diffuse light is Muneer's, which takes no horizon band. */
    job.perez_band = io->sky_model == SS_SKY_MODEL_PEREZ && (cumulative || plan.real_sky);
    if (st == SS_OK)
        st = ss_insolation_cell_inputs(&job);
    /* A horizontal surface takes none of the horizon band (sin(tilt) 0). */
    if (st == SS_OK && io->trees && job.perez_band &&
        io->surface.kind != SS_SURFACE_HORIZONTAL)
        st = ss_insolation_trees_band(&job);
    if (st == SS_OK && io->trees)
        st = ss_insolation_trees_sky(&job);
    if (st == SS_OK)
        st = cumulative ? ss_insolation_cumulative(&job, n_steps) : run_steps(&job, &plan);
    free(plan.kind);
    free(plan.dirs);
    free(job.trees_band_hidden);
    free(job.trees_sky_through);
    free(job.trees_band_through);
    ss_cell_store_close(job.cells);
    ss_cell_store_close(job.horizons);
    return st;
}

ss_status ss_insolation_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                             const ss_insolation_options *io, int n_steps, ss_sun_rows_fn sun_rows,
                             void *sun_user, int want, const ss_share *share, ss_rows_sink sink,
                             void *user)
{
    ss_call_begin(ctx);
    ss_status st = ss_insolation_check(ctx, io, n_steps);
    if (st == SS_OK)
        st = ss_rows_begin(ctx, src, opt, share);
    return st == SS_OK ? run_insolation(ctx, src, opt, io, n_steps, sun_rows, sun_user, want,
                                        share, sink, user)
                       : st;
}

/* ---- the whole grid held in memory --------------------------------------------- */

typedef struct {
    ss_ctx *ctx;
    ss_sun_step_fn sun_at;
    void *sun_user;
    size_t width, cells;
    ss_insolation_out *out;
    ss_step_sink step_sink;
    void *step_user;
} whole_insolation;

/* The whole grid's sun, for rows of it. */
static ss_status whole_sun(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                           void *user)
{
    (void)n_rows;
    whole_insolation *w = user;
    ss_status st = w->sun_at(ctx, index, step, w->sun_user);
    size_t at = (size_t)row0 * w->width;
    if (st == SS_OK && step->grid_azimuth_per_cell)
        step->grid_azimuth_per_cell += at;
    if (st == SS_OK && step->elevation_per_cell)
        step->elevation_per_cell += at;
    if (st == SS_OK && step->apparent_per_cell)
        step->apparent_per_cell += at;
    return st;
}

static float *whole_grid_of(const whole_insolation *w, int output, int index)
{
    const ss_insolation_out *o = w->out;
    switch (output) {
    case SS_OUT_GLOBAL: return o->global;
    case SS_OUT_BEAM: return o->beam;
    case SS_OUT_DIFFUSE: return o->diffuse;
    case SS_OUT_REFLECTED: return o->reflected;
    case SS_OUT_SUN_HOURS: return o->sun_hours;
    case SS_OUT_MONTHLY: return o->monthly_global + (size_t)index * w->cells;
    case SS_OUT_PV: return o->pv_yield;
    case SS_OUT_PV_AC: return o->pv_ac_yield;
    default: return NULL;
    }
}

/* The rows of the whole grid: each output into its grid, each step's
 * global to the step sink. */
static ss_status whole_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    whole_insolation *w = user;
    if (output == SS_OUT_STEP)
        return w->step_sink(index, values, w->step_user)
                   ? SS_OK
                   : ss_fail(w->ctx, SS_ERR_CANCELLED, "stopped while storing time step %d",
                             index);
    float *grid = whole_grid_of(w, output, index);
    if (grid)
        memcpy(grid + (size_t)row0 * w->width, values, sizeof(float) * (size_t)n_rows * w->width);
    return SS_OK;
}

ss_status ss_insolation(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        const ss_insolation_options *io, int n_steps, ss_sun_step_fn sun_at,
                        void *sun_user, ss_step_sink sink, void *sink_user,
                        ss_insolation_out *out)
{
    ss_call_begin(ctx);
    ss_status st = ss_insolation_check(ctx, io, n_steps);
    if (st == SS_OK)
        st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK)
        st = ss_grid_check(ctx, grid, NULL);
    if (st != SS_OK)
        return st;
    int want = (out->monthly_global ? SS_INSOLATION_MONTHLY : 0) |
               (out->pv_yield || out->pv_ac_yield ? SS_INSOLATION_PV : 0) |
               (sink ? SS_INSOLATION_STEPS : 0);
    whole_insolation w = {ctx,
                          sun_at,
                          sun_user,
                          (size_t)grid->width,
                          (size_t)grid->width * (size_t)grid->height,
                          out,
                          sink,
                          sink_user};
    ss_source src = ss_source_of_grid(grid);
    return run_insolation(ctx, &src, opt, io, n_steps, whole_sun, &w, want, NULL, whole_rows, &w);
}
