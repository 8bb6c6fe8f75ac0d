/* Clear-sky insolation over a time range: for every daylight step, cast
 * shadows (an exact sweep at the sun's azimuth, or horizons interpolated
 * between stored directions), then beam, sky-diffuse and ground-reflected
 * irradiance on each cell's own slope (kernels/ss_insolation.h), summed in
 * Wh/m^2. Steps are skipped exactly where nothing can happen: at night,
 * and the shadow sweep when the sun stands above any horizon the terrain
 * can cast. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "insolation_cell.h"
#include "lines.h"
#include "products_internal.h"

/* Stored horizons (products_internal.h) are int16 hundredths of a degree:
 * 0.005 degrees of rounding, far below the interpolation's own error. */

_Static_assert(SS_PV_TEMP_FAIMAN == SS_PV_CELL_TEMP_FAIMAN && SS_PV_TEMP_SAPM == SS_PV_CELL_TEMP_SAPM,
               "ss_pv_temp_model and kernels/ss_pv.h agree");
_Static_assert(SS_SKY_MODEL_ISOTROPIC == SS_SKY_ISOTROPIC &&
                   SS_SKY_MODEL_HAYDAVIES == SS_SKY_HAYDAVIES && SS_SKY_MODEL_PEREZ == SS_SKY_PEREZ,
               "ss_sky_model and kernels/ss_sky_diffuse.h agree");

/* Perez's horizon band as each cell sees it: the band spans the 6.5
 * degrees above the horizontal (Perez et al. 1987); in each of the sweep's
 * directions the terrain horizon hides its lowest part, and the shares left
 * open are averaged over the directions in front of the cell's surface,
 * each weighted by the cosine of its incidence on the cell. A surface other
 * than the cell's own also gets its tilted sky view here, from the same
 * horizons (the SVF product sweeps with the cell's own gradient). */
#define PEREZ_BAND_DEG 6.5f

typedef struct {
    const ss_grid *g;
    double grid_north_deg; /* the options' */
    ss_cell_terms *terms;
    float *open, *weight, *sky; /* sky: NULL, or the sky-view sums */
} horizon_sums;

static int add_horizon_direction(int index, double azimuth_deg, const float *angle_deg,
                                 const float *dist_m, const float *cast_height_m, void *user)
{
    (void)index, (void)dist_m, (void)cast_height_m;
    horizon_sums *b = user;
    size_t n = (size_t)b->g->width * b->g->height;
    /* The options' frame: the cells' gradients are in the grid's. */
    float az = (float)((azimuth_deg - b->grid_north_deg) * M_PI / 180.0);
    float se = sinf(az), sn = cosf(az);
    for (size_t c = 0; c < n; ++c) {
        if (!isfinite(b->g->z[c]))
            continue;
        const ss_cell_terms *t = &b->terms[c];
        /* ss_svf_tilted_term takes the horizon as a rise over a distance and
         * clips it at the horizontal; -90 (no terrain ahead) must not reach
         * tan, whose float pi/2 overshoots to a huge positive rise. */
        float rise = tanf(fmaxf(angle_deg[c], 0.0f) * (float)(M_PI / 180.0));
        if (b->sky)
            b->sky[c] += ss_svf_tilted_term(1.0f, rise, se, sn, t->dz_de, t->dz_dn);
        float facing = ss_cos_incidence_gradient(se, sn, 0.0f, t->dz_de, t->dz_dn);
        if (facing <= 0.0f)
            continue;
        b->weight[c] += facing;
        b->open[c] += facing * fminf(fmaxf(1.0f - angle_deg[c] / PEREZ_BAND_DEG, 0.0f), 1.0f);
    }
    return 1;
}

/* Sets every cell's band_seen, and (with_sky) its sky view, from the
 * horizons at the options' directions: one more sweep per direction. */
static ss_status horizon_terms(ss_ctx *ctx, const ss_grid *g, const ss_sweep_options *opt,
                               int with_sky, ss_cell_terms *terms)
{
    size_t n = (size_t)g->width * g->height;
    horizon_sums b = {g, opt->grid_north_deg, terms, ss_calloc(n, sizeof(float)),
                      ss_calloc(n, sizeof(float)), with_sky ? ss_calloc(n, sizeof(float)) : NULL};
    ss_status st = b.open && b.weight && (b.sky || !with_sky)
                       ? ss_horizon(ctx, g, opt, 0, add_horizon_direction, &b)
                       : ss_fail(ctx, SS_ERR_MEMORY,
                                 "cannot allocate the horizon terms' sums for %d x %d cells",
                                 g->width, g->height);
    for (size_t c = 0; st == SS_OK && c < n; ++c) {
        if (!isfinite(g->z[c]))
            continue;
        terms[c].band_seen = b.weight[c] > 0.0f ? b.open[c] / b.weight[c] : 1.0f;
        if (with_sky)
            terms[c].sky_view = ss_product_finish(SS_SVF_TILTED, b.sky[c], opt->directions);
    }
    free(b.open);
    free(b.weight);
    free(b.sky);
    return st;
}

/* The gradient (east, north) of a fixed surface in the grid's frame: it
 * descends toward the azimuth it faces. */
static void surface_gradient(const ss_surface *s, const ss_sweep_options *opt, float *dz_de,
                             float *dz_dn)
{
    *dz_de = *dz_dn = 0.0f;
    if (s->kind != SS_SURFACE_FIXED)
        return;
    double rad = M_PI / 180.0, a = (s->azimuth_deg - opt->grid_north_deg) * rad;
    double slope = tan(fmin(s->tilt_deg, 89.9) * rad);
    *dz_de = (float)(-slope * sin(a));
    *dz_dn = (float)(-slope * cos(a));
}

/* Per-cell quantities that do not change with time (insolation_cell.h):
 * for the cell's own surface, the radiative SVF product's tilted sky view;
 * for another surface, its sky view from the cell's horizons. */
ss_status ss_insolation_terms(ss_ctx *ctx, const ss_grid *g, const ss_sweep_options *opt,
                              const ss_insolation_options *io, ss_cell_terms **terms)
{
    size_t n = (size_t)g->width * g->height;
    int own = io->surface.kind == SS_SURFACE_CELL;
    ss_cell_terms *t = *terms = ss_malloc(n * sizeof *t);
    float *sky_view = own ? ss_malloc(n * sizeof(float)) : NULL;
    ss_status st = SS_OK;
    if (!t || (own && !sky_view))
        st = ss_fail(ctx, SS_ERR_MEMORY, "cannot allocate insolation buffers for %d x %d cells",
                     g->width, g->height);
    if (st == SS_OK && own)
        st = ss_svf(ctx, g, opt, SS_SVF_DEF_TILTED, sky_view);
    if (st != SS_OK) {
        free(sky_view);
        return st;
    }
    float cx = (float)g->cell_x_m, cy = (float)g->cell_y_m, fixed_de, fixed_dn;
    surface_gradient(&io->surface, opt, &fixed_de, &fixed_dn);
#pragma omp parallel for schedule(static)
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            size_t k = (size_t)r * g->width + c;
            if (!isfinite(g->z[k]))
                continue;
            float dz_de = fixed_de, dz_dn = fixed_dn;
            if (own)
                ss_gradient_horn(g->z, g->width, g->height, c, r, cx, cy, &dz_de, &dz_dn);
            t[k] = ss_cell_terms_of(dz_de, dz_dn, own ? sky_view[k] : 0.0f,
                                    g->z[k] + g->z_origin_m);
        }
    free(sky_view);
    return !own || io->sky_model == SS_SKY_MODEL_PEREZ ? horizon_terms(ctx, g, opt, !own, t)
                                                        : SS_OK;
}

/* Horizons at the D stored directions, int16 hundredths of a degree. */
ss_status ss_insolation_store_horizons(ss_ctx *ctx, ss_session *s, const ss_grid *g,
                                       const ss_sweep_options *opt, int16_t **stored)
{
    size_t n = (size_t)g->width * g->height;
    double bytes = (double)n * opt->directions * sizeof(int16_t);
    *stored = bytes < 4e9 ? ss_malloc((size_t)bytes) : NULL;
    if (!*stored)
        return ss_fail(ctx, SS_ERR_MEMORY,
                       "storing %d horizon directions takes %.1f GB: use the exact shadow "
                       "mode or fewer directions",
                       opt->directions, bytes / 1e9);
    for (int i = 0; i < opt->directions; ++i) {
        float *h;
        ss_status st = ss_sun_horizon(s, g, opt, ss_direction_azimuth(opt, i), &h);
        if (st != SS_OK)
            return st;
        int16_t *dst = *stored + (size_t)i * n;
        for (size_t c = 0; c < n; ++c)
            dst[c] = isfinite(g->z[c]) ? (int16_t)lrintf(h[c] * SS_HORIZON_SCALE) : 0;
    }
    return SS_OK;
}

/* Horizon of cell c at azimuth az (options' frame), linear between the two
 * stored directions around it. */
static float stored_horizon(const int16_t *stored, size_t n, const ss_sweep_options *opt,
                            size_t c, double az)
{
    double pos = fmod((az - opt->offset_deg) / (360.0 / opt->directions), opt->directions);
    if (pos < 0)
        pos += opt->directions;
    int i0 = (int)pos % opt->directions, i1 = (i0 + 1) % opt->directions;
    float t = (float)(pos - floor(pos));
    return ((1.0f - t) * stored[(size_t)i0 * n + c] + t * stored[(size_t)i1 * n + c]) /
           SS_HORIZON_SCALE;
}

/* The step's weather record (W/m^2), or 0 where it is missing (counted).
 * GHI alone is split by Erbs; a record whose beam on the horizontal exceeds
 * its global is counted and used as given, one with light while the sun
 * is below the horizontal over its whole interval (it moves at most 15
 * degrees an hour) is counted and adds nothing. All at the grid's centre
 * sun. *light: the record holds any light. */
int ss_insolation_sky_record(ss_ctx *ctx, const ss_sun_step *sun,
                             const ss_insolation_options *io, ss_sky_record *rec, int *light)
{
    double z = (90.0 - sun->elevation_deg) * M_PI / 180.0;
    double ghi = sun->ghi_w_m2, dni = sun->dni_w_m2, dhi = sun->dhi_w_m2;
    rec->dni_extra = (float)sun->extraterrestrial_w_m2;
    rec->albedo = (float)(isfinite(sun->albedo) ? sun->albedo : io->albedo);
    *light = 0;
    if (isnan(dni) && isnan(dhi) && isfinite(ghi)) {
        float b, d;
        ss_erbs_split((float)ghi, (float)z, rec->dni_extra, &b, &d);
        dni = b;
        dhi = d;
        ctx->counters.records_split++;
    }
    if (!isfinite(ghi) || !isfinite(dni) || !isfinite(dhi)) {
        ctx->counters.records_missing++;
        return 0;
    }
    rec->ghi = (float)ghi;
    rec->dni = (float)dni;
    rec->dhi = (float)dhi;
    *light = ghi > 0 || dni > 0 || dhi > 0;
    if (*light && sun->elevation_deg + sun->spread_deg < -7.5 * sun->duration_h) {
        ctx->counters.records_light_at_night++;
        *light = 0;
    }
    double cz = cos(z);
    if (cz > 0 && dni * cz > ghi + fmax(10.0, 0.05 * ghi))
        ctx->counters.records_beam_above_global++;
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
    if (io->stride < 0 || io->first < 0 || (io->stride > 1 && io->first >= io->stride) ||
        (io->stride <= 1 && io->first != 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a share of the steps needs 0 <= first < stride (first %d, stride %d)",
                       io->first, io->stride);
    return SS_OK;
}

int ss_insolation_step_is_mine(const ss_insolation_options *io, int k)
{
    return io->stride <= 1 || k % io->stride == io->first;
}

ss_status ss_insolation(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        const ss_insolation_options *io, int n_steps, ss_sun_step_fn sun_at,
                        void *sun_user, ss_step_sink sink, void *sink_user,
                        ss_insolation_out *out)
{
    ss_status st = ss_insolation_check(ctx, io, n_steps);
    if (st != SS_OK)
        return st;
    if (io->shadow_mode == SS_SHADOW_CUMULATIVE && sink)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the cumulative sky has no per-step bands: use exact or interpolated "
                       "shadows with them");
    if (io->shadow_mode == SS_SHADOW_CUMULATIVE)
        return ss_insolation_cumulative(ctx, grid, opt, io, n_steps, sun_at, sun_user, out);
    size_t n = (size_t)grid->width * grid->height;
    ss_cell_terms *terms = NULL;
    ss_session *s = NULL;
    int16_t *stored = NULL;
    float *step_global = sink ? ss_malloc(n * sizeof(float)) : NULL;
    st = ss_product_begin(ctx, grid, opt, 1, &s);
    if (st == SS_OK)
        st = ss_insolation_terms(ctx, grid, opt, io, &terms);
    if (st == SS_OK && sink && !step_global)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for per-step bands");
    if (st == SS_OK && io->shadow_mode == SS_SHADOW_INTERPOLATED)
        st = ss_insolation_store_horizons(ctx, s, grid, opt, &stored);
    for (size_t c = 0; st == SS_OK && c < n; ++c) {
        float v = isfinite(grid->z[c]) ? 0.0f : SS_NODATA;
        out->global[c] = out->beam[c] = out->diffuse[c] = out->reflected[c] = v;
        out->sun_hours[c] = v;
        for (int m = 0; out->monthly_global && m < 12; ++m)
            out->monthly_global[(size_t)m * n + c] = v;
        if (out->pv_yield)
            out->pv_yield[c] = v;
        if (out->pv_ac_yield)
            out->pv_ac_yield[c] = v;
    }
    double bound_deg = ss_horizon_bound_deg(grid, opt->lines);
    for (int k = 0; k < n_steps && st == SS_OK; ++k) {
        if (!ss_insolation_step_is_mine(io, k))
            continue; /* another process's step */
        ss_sun_step sun;
        st = sun_at(ctx, k, &sun, sun_user);
        if (st != SS_OK)
            break;
        if (step_global)
            for (size_t c = 0; c < n; ++c)
                step_global[c] = isfinite(grid->z[c]) ? 0.0f : SS_NODATA;
        ss_sky_record rec = {0};
        ss_sky_parts sky = {0.0f, 0.0f, 0.0f};
        int light = 0;
        int missing = sun.real_sky && !ss_insolation_sky_record(ctx, &sun, io, &rec, &light);
        int sun_up = sun.elevation_deg + sun.spread_deg > 0.0;
        if (missing) {
            /* counted by ss_insolation_sky_record */
        } else if (!sun_up && !light) {
            ctx->counters.night_steps_skipped++;
        } else {
            ctx->counters.time_steps++;
            /* Shadows: none can fall where the sun is above every horizon,
             * and none is cast by a sun below every cell's horizontal. */
            float *h = NULL;
            int all_lit = !sun_up || sun.apparent_elevation_deg - sun.spread_deg > bound_deg;
            if (all_lit) {
                ctx->counters.shadow_sweeps_skipped += sun_up;
            } else if (io->shadow_mode == SS_SHADOW_EXACT) {
                double t0 = ss_seconds_now();
                st = ss_sun_horizon(s, grid, opt, sun.azimuth_deg, &h);
                ctx->counters.sweep_seconds += ss_seconds_now() - t0;
            }
            if (st != SS_OK)
                break;
            const float rad = (float)(M_PI / 180.0);
            float g0 = (float)sun.extraterrestrial_w_m2, linke = (float)sun.linke;
            /* The sky's parts at the centre's sun serve every cell. */
            if (sun.real_sky)
                sky = ss_sky_parts_of((int)io->sky_model, fmaxf(rec.dhi, 0.0f),
                                      fmaxf(rec.dni, 0.0f), rec.dni_extra,
                                      (float)((90.0 - sun.elevation_deg) * M_PI / 180.0));
            int pv_on = (out->pv_yield || out->pv_ac_yield) && sun.real_sky && io->pv.on;
            if (pv_on && (isnan(sun.temp_air_c) || isnan(sun.wind_speed_m_s)))
                ctx->counters.records_without_temperature++;
            float temp_air = (float)(isnan(sun.temp_air_c) ? io->pv.temp_air_c : sun.temp_air_c);
            float wind = (float)(isnan(sun.wind_speed_m_s) ? io->pv.wind_speed_m_s
                                                            : sun.wind_speed_m_s);
            float gamma = (float)io->pv.gamma_pdc, losses = (float)io->pv.losses;
            /* The inverter's DC input limit per kWp of modules: its AC rating
             * (1 / the DC/AC ratio) over its nominal efficiency. */
            float eta_inv = (float)io->pv.inverter_efficiency;
            float inv_pdc0 = pv_on ? (float)(1.0 / (io->pv.dc_ac_ratio * io->pv.inverter_efficiency))
                                   : 1.0f;
            float dt = (float)sun.duration_h, albedo = (float)io->albedo;
#pragma omp parallel for schedule(static)
            for (size_t c = 0; c < n; ++c) {
                if (!isfinite(grid->z[c]))
                    continue;
                float az = (sun.grid_azimuth_per_cell ? sun.grid_azimuth_per_cell[c]
                                                      : (float)sun.grid_azimuth_deg) * rad;
                float h0 = (sun.elevation_per_cell ? sun.elevation_per_cell[c]
                                                   : (float)sun.elevation_deg) * rad;
                float app = sun.apparent_per_cell ? sun.apparent_per_cell[c]
                                                  : (float)sun.apparent_elevation_deg;
                if (h0 <= 0.0f && !sun.real_sky)
                    continue;
                float horizon = all_lit ? -90.0f
                                : h     ? h[c]
                                        : stored_horizon(stored, n, opt, c, sun.azimuth_deg);
                ss_cell_step add =
                    sun.real_sky
                        ? ss_cell_step_weather(&terms[c], az, h0, app, horizon, &rec, sky, dt)
                        : ss_cell_step_of(&terms[c], az, h0, app, horizon, g0, linke, albedo, dt);
                if (out->monthly_global && sun.month >= 1 && sun.month <= 12)
                    out->monthly_global[(size_t)(sun.month - 1) * n + c] += add.global;
                if (pv_on && dt > 0.0f) {
                    float pdc = ss_cell_pv_power(add.global / dt, temp_air, wind,
                                                 (int)io->pv.temp_model, gamma, losses);
                    if (out->pv_yield)
                        out->pv_yield[c] += pdc * dt;
                    if (out->pv_ac_yield)
                        out->pv_ac_yield[c] += ss_pvwatts_ac(pdc, inv_pdc0, eta_inv) * dt;
                }
                out->beam[c] += add.beam;
                out->diffuse[c] += add.diffuse;
                out->reflected[c] += add.reflected;
                out->global[c] += add.global;
                out->sun_hours[c] += add.sun_hours;
                if (step_global)
                    step_global[c] = add.global;
            }
        }
        if (st == SS_OK && sink && !sink(k, step_global, sink_user))
            st = ss_fail(ctx, SS_ERR_CANCELLED, "stopped while storing time step %d", k);
        if (st == SS_OK)
            st = ss_progress(ctx, (double)(k + 1) / n_steps, "insolation");
    }
    free(stored);
    free(step_global);
    free(terms);
    ss_session_close(s);
    return st;
}
