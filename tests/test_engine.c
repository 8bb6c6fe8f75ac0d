/* The one driver gives every product the same answer whatever the DEM's
 * size in memory, the device and the batch: each row-wise product on the
 * whole grid and in bands of 1, 7 and 200 rows, on the C twin and on
 * OpenCL (PoCL; skipped, saying so, where no OpenCL device opens), there
 * with insolation's per-cell work on the host and on the device, with
 * batches of one direction and of all, against the C twin's whole grid.
 * This includes what refused bands before the driver was one: radius
 * forms, interpolated shadows and the cumulative sky, weather and PV,
 * fixed surfaces, and hillshade's sweeping layers. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "testlib.h"

#define W 37
#define H 41
#define CELLS ((size_t)W * H)
#define MAX_OUTPUTS 9
#define MAX_INDEX 16
#define N_STEPS 6

/* Every (output, index) grid a run gave, made on first use; a row written
 * twice is counted. */
typedef struct {
    float *grid[MAX_OUTPUTS][MAX_INDEX];
    int twice;
} results;

static ss_status keep_rows(void *user, int output, int index, int row0, int n_rows,
                           const float *values)
{
    results *r = user;
    if (output < 0 || output >= MAX_OUTPUTS || index < 0 || index >= MAX_INDEX || row0 < 0 ||
        row0 + n_rows > H)
        return SS_ERR_INTERNAL;
    float **g = &r->grid[output][index];
    if (!*g) {
        *g = malloc(sizeof(float) * CELLS);
        for (size_t c = 0; *g && c < CELLS; ++c)
            (*g)[c] = -12345.0f; /* a value nothing writes */
    }
    if (!*g)
        return SS_ERR_MEMORY;
    for (int k = 0; k < n_rows * W; ++k)
        r->twice += (*g)[(size_t)row0 * W + k] != -12345.0f;
    memcpy(*g + (size_t)row0 * W, values, sizeof(float) * (size_t)n_rows * W);
    return SS_OK;
}

static void results_free(results *r)
{
    for (int o = 0; o < MAX_OUTPUTS; ++o)
        for (int i = 0; i < MAX_INDEX; ++i)
            free(r->grid[o][i]);
    memset(r, 0, sizeof *r);
}

/* The worst difference of b from a, relative to max(|a|, 1); grids that
 * one has and the other lacks, cells one leaves unwritten and nodata that
 * differs count as infinitely different. */
static double worst_difference(const results *a, const results *b)
{
    double worst = 0;
    for (int o = 0; o < MAX_OUTPUTS; ++o)
        for (int i = 0; i < MAX_INDEX; ++i) {
            const float *x = a->grid[o][i], *y = b->grid[o][i];
            if (!x && !y)
                continue;
            if (!x || !y)
                return INFINITY;
            for (size_t c = 0; c < CELLS; ++c) {
                if (x[c] == -12345.0f || y[c] == -12345.0f ||
                    (x[c] == SS_NODATA) != (y[c] == SS_NODATA))
                    return INFINITY;
                double e = fabs((double)x[c] - y[c]) / fmax(1.0, fabs((double)x[c]));
                worst = isfinite(e) ? fmax(worst, e) : INFINITY;
            }
        }
    return worst;
}

static ss_grid terrain;

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    (void)user;
    memcpy(z, terrain.z + (size_t)row0 * W, sizeof(float) * (size_t)n_rows * W);
    return SS_OK;
}

/* Suns from the east over the top to the west and one at night, for clear
 * sky and for weather records (real_sky: GHI, DNI and DHI, and air for PV). */
static const double step_az[N_STEPS] = {85.0, 120.0, 170.0, 215.0, 265.0, 10.0};
static const double step_el[N_STEPS] = {4.0, 28.0, 55.0, 41.0, 9.0, -20.0};

static ss_status sun_of(ss_ctx *ctx, int k, int row0, int n_rows, ss_sun_step *step, void *user)
{
    (void)ctx, (void)row0, (void)n_rows;
    int real_sky = user != NULL;
    memset(step, 0, sizeof *step);
    step->duration_h = 1.0;
    step->linke = 3.2;
    step->extraterrestrial_w_m2 = 1361.0;
    step->azimuth_deg = step_az[k] + 0.7; /* the options' frame: grid north is 0.7 */
    step->grid_azimuth_deg = step_az[k];
    step->elevation_deg = step_el[k];
    step->apparent_elevation_deg = step_el[k] + 0.12;
    step->month = 3 + k;
    if (real_sky) {
        double up = fmax(sin(step_el[k] * M_PI / 180.0), 0.0);
        step->real_sky = 1;
        step->dni_w_m2 = 700.0 * up;
        step->dhi_w_m2 = 90.0 * up + 5.0 * (k % 2);
        step->ghi_w_m2 = step->dni_w_m2 * up + step->dhi_w_m2;
        step->albedo = NAN;
        step->temp_air_c = 12.0 + k;
        step->wind_speed_m_s = 2.0;
    }
    return SS_OK;
}

typedef enum {
    P_SVF_GEOMETRIC, P_SVF_RADIATIVE, P_SVF_RADIUS, P_OPENNESS_NEGATIVE, P_OPENNESS_RADIUS,
    P_HORIZON, P_SHADOW, P_HILLSHADE, P_HILLSHADE_SWEPT, P_VAT, P_INSOLATION_EXACT,
    P_INSOLATION_INTERPOLATED, P_INSOLATION_WEATHER_PV, P_INSOLATION_SURFACE,
    P_INSOLATION_CLEAR_MONTHLY, P_INSOLATION_CUMULATIVE, N_PRODUCTS
} product;

static const char *const product_names[N_PRODUCTS] = {
    "geometric SVF", "radiative SVF", "SVF within 100 m (scan)", "negative openness",
    "openness within 700 m (hulls)", "horizons, distances and casting heights", "shadow",
    "hillshade", "hillshade with cast shadows and sky view", "VAT blend within 60 m",
    "insolation, exact shadows", "insolation, interpolated shadows",
    "insolation, weather records, Perez, PV", "insolation on a fixed surface, Hay-Davies",
    "insolation, exact shadows, clear sky, monthly sums",
    "insolation, cumulative sky"};

/* Floats summed in another order over the directions (bands walk them in
 * two passes) or in another device's arithmetic move a result by about n
 * float roundings; degrees and W/m^2 take their own. */
static double tolerance(product p)
{
    switch (p) {
    case P_OPENNESS_NEGATIVE:
    case P_OPENNESS_RADIUS:
    case P_HORIZON:
    case P_VAT:
        return 2e-5;
    case P_INSOLATION_EXACT:
    case P_INSOLATION_INTERPOLATED:
    case P_INSOLATION_WEATHER_PV:
    case P_INSOLATION_SURFACE:
    case P_INSOLATION_CLEAR_MONTHLY:
    case P_INSOLATION_CUMULATIVE:
        return 2e-5;
    case P_HILLSHADE:
    case P_HILLSHADE_SWEPT:
        return 1e-5;
    default:
        return 2e-6;
    }
}

static ss_status run_product(ss_ctx *ctx, product p, int band_rows, results *out)
{
    ss_source src = test_source(&terrain, read_rows, NULL, band_rows, NULL);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 12;
    opt.offset_deg = 4.0;
    opt.grid_north_deg = 0.7;
    opt.earth_radius_m = p == P_HORIZON ? 4e4 : 0.0; /* curvature matters on a small planet */
    ss_insolation_options io = {.albedo = 0.2, .shadow_mode = SS_SHADOW_EXACT};
    ss_hillshade_options ho = {.azimuth_deg = 300.0, .altitude_deg = 25.0, .z_factor = 1.5};
    switch (p) {
    case P_SVF_GEOMETRIC:
        return ss_sky_rows(ctx, &src, &opt, SS_SKY_SVF_GEOMETRIC, 0, NULL, keep_rows, out);
    case P_SVF_RADIATIVE:
        return ss_sky_rows(ctx, &src, &opt, SS_SKY_SVF_RADIATIVE, 0, NULL, keep_rows, out);
    case P_SVF_RADIUS:
        return ss_sky_rows(ctx, &src, &opt, SS_SKY_SVF_HORIZONTAL, 100, NULL, keep_rows, out);
    case P_OPENNESS_NEGATIVE:
        return ss_sky_rows(ctx, &src, &opt, SS_SKY_OPENNESS_NEGATIVE, 0, NULL, keep_rows, out);
    case P_OPENNESS_RADIUS:
        return ss_sky_rows(ctx, &src, &opt, SS_SKY_OPENNESS_POSITIVE, 700, NULL, keep_rows, out);
    case P_HORIZON:
        return ss_horizon_rows(ctx, &src, &opt, SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT,
                               keep_rows, out);
    case P_SHADOW:
        return ss_shadow_rows(ctx, &src, &opt, sun_of, NULL, keep_rows, out);
    case P_HILLSHADE:
        return ss_hillshade_rows(ctx, &src, &opt, &ho, keep_rows, out);
    case P_HILLSHADE_SWEPT:
        ho.cast_shadows = 1;
        ho.sky_view = 0.4;
        return ss_hillshade_rows(ctx, &src, &opt, &ho, keep_rows, out);
    case P_VAT:
        ho.vat = 1;
        ho.radius_m = 60.0;
        return ss_hillshade_rows(ctx, &src, &opt, &ho, keep_rows, out);
    case P_INSOLATION_INTERPOLATED:
        io.shadow_mode = SS_SHADOW_INTERPOLATED;
        /* fall through */
    case P_INSOLATION_EXACT:
        return ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, sun_of, NULL,
                                  SS_INSOLATION_STEPS, NULL, keep_rows, out);
    case P_INSOLATION_WEATHER_PV:
        io.sky_model = SS_SKY_MODEL_PEREZ;
        io.pv = (ss_pv_options){.on = 1,
                                .gamma_pdc = -0.0047,
                                .losses = 0.1142,
                                .temp_air_c = 20,
                                .inverter_efficiency = 0.96,
                                .dc_ac_ratio = 1.2};
        return ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, sun_of, &io,
                                  SS_INSOLATION_MONTHLY | SS_INSOLATION_PV, NULL, keep_rows,
                                  out);
    case P_INSOLATION_SURFACE:
        io.sky_model = SS_SKY_MODEL_HAYDAVIES;
        io.surface = (ss_surface){SS_SURFACE_FIXED, 30.0, 200.0};
        return ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, sun_of, &io,
                                  SS_INSOLATION_MONTHLY, NULL, keep_rows, out);
    case P_INSOLATION_CLEAR_MONTHLY:
        return ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, sun_of, NULL,
                                  SS_INSOLATION_MONTHLY, NULL, keep_rows, out);
    case P_INSOLATION_CUMULATIVE:
        io.shadow_mode = SS_SHADOW_CUMULATIVE;
        io.sky_model = SS_SKY_MODEL_PEREZ;
        return ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, sun_of, &io,
                                  SS_INSOLATION_MONTHLY, NULL, keep_rows, out);
    default:
        return SS_ERR_INTERNAL;
    }
}

/* One product against the C twin's whole grid, every variant. */
static void check_product(product p, ss_ctx *twin, ss_ctx *ocl)
{
    static const int band_rows[] = {0, 1, 7, 200};
    static const int batches[] = {1, 12};
    results ref = {0};
    ss_ctx_set_batch(twin, 1);
    ss_status st = run_product(twin, p, 0, &ref);
    int runs = 0, failed = st != SS_OK || ref.twice;
    double worst = 0;
    char where[120] = "";
    /* The C twin; OpenCL with insolation's cells on the host, then on the
     * device (the same for the other products). */
    static const char *const device_names[] = {"C twin", "OpenCL", "OpenCL, cells on the device"};
    uint64_t on_device = 0;
    for (int device = 0; device < 3 && !failed; ++device) {
        ss_ctx *ctx = device ? ocl : twin;
        if (ctx && device)
            ss_ctx_set_cells(ctx, device == 2 ? SS_CELLS_DEVICE : SS_CELLS_HOST);
        for (int b = 0; ctx && b < 2 && !failed; ++b)
            for (size_t r = 0; r < sizeof band_rows / sizeof *band_rows && !failed; ++r) {
                if (!device && b == 0 && r == 0)
                    continue; /* the reference itself */
                results got = {0};
                ss_ctx_set_batch(ctx, batches[b]);
                uint64_t before = ss_ctx_counters(ctx).cell_steps_on_device;
                st = run_product(ctx, p, band_rows[r], &got);
                on_device += ss_ctx_counters(ctx).cell_steps_on_device - before;
                runs++;
                double e = st == SS_OK && !got.twice ? worst_difference(&ref, &got) : INFINITY;
                if (e > worst || st != SS_OK) {
                    worst = e;
                    char rows[40] = "the whole grid read by rows";
                    if (band_rows[r] > 0)
                        snprintf(rows, sizeof rows, "bands of %d rows", band_rows[r]);
                    snprintf(where, sizeof where, "%s, %s, batch %d%s%s",
                             device_names[device], rows, batches[b],
                             st != SS_OK ? ": " : "", st != SS_OK ? ss_ctx_message(ctx) : "");
                }
                failed |= st != SS_OK;
                results_free(&got);
            }
    }
    /* Insolation's steps reach the device, exact or interpolated, with their
     * per-step outputs (the cumulative sky has no steps). */
    int device_steps = ocl && p >= P_INSOLATION_EXACT && p != P_INSOLATION_CUMULATIVE;
    tap_ok(!failed && worst <= tolerance(p) && (on_device > 0) == device_steps,
           "%s: %d runs (whole grid, bands of 1, 7, 200 rows; C twin%s; batches of 1 and 12) "
           "== the C twin's whole grid (worst %.2g relative, at %s); %llu cell-steps on the "
           "device",
           product_names[p], runs, ocl ? ", OpenCL with cells on the host and on the device" : "",
           worst, where[0] ? where : "none", (unsigned long long)on_device);
    if (failed && ref.twice)
        tap_diag("the reference wrote %d cells twice", ref.twice);
    results_free(&ref);
}

/* Processes sharing a run add their band sums in turn, so each must finish
 * its bands in one order whatever steps it holds: one a sun walking down,
 * one walking up, one none. The order the global's rows arrive in is kept. */
typedef struct {
    int row0[64], n, reduced;
} band_order;

static ss_status keep_order(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    band_order *o = user;
    (void)n_rows, (void)values;
    if (output == SS_OUT_GLOBAL && index == 0 && o->n < 64)
        o->row0[o->n++] = row0;
    return SS_OK;
}

static ss_status count_reduce(void *user, float *sums, size_t n)
{
    (void)sums, (void)n;
    ((band_order *)user)->reduced++;
    return SS_OK;
}

static void check_share_band_order(ss_ctx *ctx)
{
    enum { BAND_ROWS = 7, BANDS = (H + BAND_ROWS - 1) / BAND_ROWS };
    band_order first = {0};
    int same = 1, shares = 0;
    for (int k = 0; k <= N_STEPS; ++k) { /* share k = N_STEPS holds no step */
        ss_source src = test_source(&terrain, read_rows, NULL, BAND_ROWS, NULL);
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.directions = 4;
        ss_insolation_options io = {.albedo = 0.2, .shadow_mode = SS_SHADOW_EXACT};
        band_order got = {0};
        ss_share share = {k, N_STEPS + 1, count_reduce, &got};
        ss_status st = ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, sun_of, NULL, 0, &share,
                                          keep_order, &got);
        if (k == 0)
            first = got;
        same &= st == SS_OK && got.n == BANDS && got.reduced == BANDS && got.n == first.n &&
                !memcmp(got.row0, first.row0, sizeof(int) * (size_t)got.n);
        shares++;
    }
    tap_ok(same, "%d shares of a run in bands of 7 rows (suns walking down, up, none) finish "
           "their %d bands in one order, each band's sums reduced once", shares, BANDS);
}

int main(void)
{
    terrain = test_grid(W, H, 20, 25);
    test_fill(&terrain, TERRAIN_SMOOTH, 31, 400);
    test_holes(&terrain, 8, 3, 4);
    terrain.z_origin_m = 850.0;
    ss_ctx *twin = ss_ctx_new(), *ocl = ss_ctx_new();
    ss_ctx_use_device(twin, "reference");
    /* The first OpenCL device, if any opens here. */
    if (ss_ctx_use_device(ocl, NULL) != SS_OK || strstr(ss_ctx_device_name(ocl), "reference") ||
        strstr(ss_ctx_device_name(ocl), "no device")) {
        tap_diag("no OpenCL device opens here (%s): the C twin alone is checked",
                 ss_ctx_device_name(ocl));
        ss_ctx_free(ocl);
        ocl = NULL;
    }
    for (int p = 0; p < N_PRODUCTS; ++p)
        check_product((product)p, twin, ocl);
    check_share_band_order(twin);
    ss_ctx_free(twin);
    ss_ctx_free(ocl);
    ss_grid_free(&terrain);
    return tap_done();
}
