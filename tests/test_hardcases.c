/* Hard cases that must stay numerically stable. Every case runs through
 * every product (horizon with distances, SVF in all three definitions, cast
 * shadow, hillshade, insolation) on the OpenCL path and on the C reference,
 * and every output must hold:
 *   - no NaN or Inf anywhere;
 *   - SS_NODATA exactly where the input has no height (NaN or +-Inf);
 *   - values inside their physical range: horizons in [-90, 90] degrees,
 *     distances in [0, grid diagonal], SVF in [0, 1], sunlit in {0, 1},
 *     hillshade in [1, 255], irradiation >= 0 with global = beam + diffuse +
 *     reflected, hours of sun within the daylight steps' hours;
 *   - the two devices agree;
 * and, where the case has one, the known answer, whose reason is written
 * next to each case. Grids are small to keep the suite quick: the sweep's
 * cost is per cell, and these cases are about values, not sizes (the
 * large-and-odd sizes run once). The CLI half (reader data types,
 * geographic grids) is tests/test_hardcases_cli.sh. */
#include "config.h"

#include <math.h>
#include <stdarg.h>
#include <string.h>

#include "reference_march.h"
#include "tap.h"
#include "testlib.h"

static ss_ctx *ctxs[2];
static const char *dev_names[2] = {"OpenCL", "reference"};

static void report(int pass, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void report(int pass, const char *fmt, ...)
{
    char msg[1200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    tap_ok(pass, "%s", msg);
}

/* ---- running every product ------------------------------------------------ */

typedef struct {
    int directions;
    double offset_deg;
    ss_line_model lines;
    double earth_radius_m, refraction_k;
    double sun_az, sun_el;      /* cast shadow */
    double light_az, light_alt; /* hillshade */
    ss_shadow_mode shadow_mode; /* insolation */
} run_opts;

static run_opts default_opts(void)
{
    run_opts o = {16,    0.0,  SS_LINES_INTERPOLATED, 0.0, 0.0, 135.0, 20.0,
                  315.0, 45.0, SS_SHADOW_EXACT};
    return o;
}

/* Insolation over three one-hour steps given directly (no place on Earth
 * needed): a high sun, a low sun, and night. Two hours of daylight. */
static const double insol_steps[3][2] = {{135.0, 30.0}, {250.0, 4.0}, {300.0, -20.0}};
#define INSOL_DAYLIGHT_H 2.0

typedef struct {
    const double (*steps)[2];
    int n;
} steps_user;

static ss_status fixed_sun(ss_ctx *ctx, int k, ss_sun_step *step, void *user)
{
    (void)ctx;
    const steps_user *u = user;
    memset(step, 0, sizeof *step);
    step->duration_h = 1.0;
    step->linke = 3.0;
    step->extraterrestrial_w_m2 = 1361.0;
    step->azimuth_deg = step->grid_azimuth_deg = u->steps[k][0];
    step->elevation_deg = step->apparent_elevation_deg = u->steps[k][1];
    return SS_OK;
}

typedef struct {
    size_t n;
    int directions;
    float *angle, *dist; /* directions x cells */
    float *svf[3];
    float *lit, *sun_horizon;
    float *shade;
    ss_insolation_out ins;
    char error[400]; /* the first product that failed, and why */
} products;

typedef struct {
    products *p;
} horizon_user;

static int keep_horizon(int index, double az, const float *angle, const float *dist,
                        const float *cast, void *user)
{
    (void)cast;
    (void)az;
    products *p = user;
    memcpy(p->angle + (size_t)index * p->n, angle, p->n * sizeof(float));
    memcpy(p->dist + (size_t)index * p->n, dist, p->n * sizeof(float));
    return 1;
}

static void free_products(products *p)
{
    free(p->angle);
    free(p->dist);
    for (int d = 0; d < 3; ++d)
        free(p->svf[d]);
    free(p->lit);
    free(p->sun_horizon);
    free(p->shade);
    free(p->ins.global);
    free(p->ins.beam);
    free(p->ins.diffuse);
    free(p->ins.reflected);
    free(p->ins.sun_hours);
    memset(p, 0, sizeof *p);
}

static ss_sweep_options sweep_opts(const run_opts *o)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = o->directions;
    opt.offset_deg = o->offset_deg;
    opt.lines = o->lines;
    opt.earth_radius_m = o->earth_radius_m;
    opt.refraction_k = o->refraction_k;
    return opt;
}

/* Runs every product; returns 0 and notes the failure if one fails. */
static int run_products(int dev, const ss_grid *g, const run_opts *o, products *p)
{
    memset(p, 0, sizeof *p);
    ss_ctx *ctx = ctxs[dev];
    size_t n = (size_t)g->width * g->height;
    p->n = n;
    p->directions = o->directions;
    ss_sweep_options opt = sweep_opts(o);
    p->angle = malloc(n * o->directions * sizeof(float));
    p->dist = malloc(n * o->directions * sizeof(float));
    ss_status st = ss_horizon(ctx, g, &opt, 1, keep_horizon, p);
    const char *what = "horizon";
    for (int d = 0; d < 3 && st == SS_OK; ++d) {
        p->svf[d] = malloc(n * sizeof(float));
        st = ss_svf(ctx, g, &opt, (ss_svf_definition)d, p->svf[d]);
        what = "svf";
    }
    if (st == SS_OK) {
        p->lit = malloc(n * sizeof(float));
        p->sun_horizon = malloc(n * sizeof(float));
        st = ss_cast_shadow(ctx, g, &opt, o->sun_az, o->sun_el, NULL, p->lit, p->sun_horizon);
        what = "shadow";
    }
    if (st == SS_OK) {
        p->shade = malloc(n * sizeof(float));
        st = ss_hillshade(ctx, g, o->light_az, o->light_alt, 1.0, 0, 0, p->shade);
        what = "hillshade";
    }
    if (st == SS_OK) {
        float **b[5] = {&p->ins.global, &p->ins.beam, &p->ins.diffuse, &p->ins.reflected,
                        &p->ins.sun_hours};
        for (int k = 0; k < 5; ++k)
            *b[k] = malloc(n * sizeof(float));
        ss_insolation_options io = {
            .albedo = 0.2, .shadow_mode = o->shadow_mode};
        steps_user su = {insol_steps, 3};
        st = ss_insolation(ctx, g, &opt, &io, 3, fixed_sun, &su, NULL, NULL, &p->ins);
        what = "insolation";
    }
    if (st != SS_OK)
        snprintf(p->error, sizeof p->error, "%s failed (%d): %s", what, (int)st,
                 ss_ctx_message(ctx));
    return st == SS_OK;
}

/* ---- invariants --------------------------------------------------------- */

typedef struct {
    char first[300];
    size_t bad;
} verdict;

static void fail(verdict *v, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void fail(verdict *v, const char *fmt, ...)
{
    if (!v->bad++) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(v->first, sizeof v->first, fmt, ap);
        va_end(ap);
    }
}

/* One output array: finite, nodata exactly at the input's nodata, within
 * [lo, hi]. */
static void check_band(verdict *v, const char *name, const ss_grid *g, const float *x, double lo,
                       double hi)
{
    size_t n = (size_t)g->width * g->height;
    for (size_t c = 0; c < n; ++c) {
        int nodata_in = !isfinite(g->z[c]);
        if (!isfinite(x[c]))
            fail(v, "%s: %g at cell %zu", name, x[c], c);
        else if (nodata_in != (x[c] == SS_NODATA))
            fail(v, "%s: %g at cell %zu whose input is %g", name, x[c], c, g->z[c]);
        else if (!nodata_in && !(x[c] >= lo && x[c] <= hi))
            fail(v, "%s: %g at cell %zu outside [%g, %g]", name, x[c], c, lo, hi);
    }
}

static void check_invariants(const char *label, int dev, const ss_grid *g, const products *p)
{
    verdict v = {"", 0};
    size_t n = p->n;
    double diag = hypot(g->width * g->cell_x_m, g->height * g->cell_y_m);
    char name[64];
    for (int i = 0; i < p->directions; ++i) {
        snprintf(name, sizeof name, "horizon %d", i);
        check_band(&v, name, g, p->angle + (size_t)i * n, -90, 90);
        snprintf(name, sizeof name, "distance %d", i);
        check_band(&v, name, g, p->dist + (size_t)i * n, 0, diag);
    }
    static const char *defs[3] = {"svf geometric", "svf horizontal", "svf tilted"};
    for (int d = 0; d < 3; ++d)
        check_band(&v, defs[d], g, p->svf[d], 0, 1);
    check_band(&v, "sunlit", g, p->lit, 0, 1);
    for (size_t c = 0; c < n; ++c)
        if (isfinite(g->z[c]) && p->lit[c] != 0 && p->lit[c] != 1)
            fail(&v, "sunlit %g at cell %zu is neither 0 nor 1", p->lit[c], c);
    check_band(&v, "shadow horizon", g, p->sun_horizon, -90, 90);
    check_band(&v, "hillshade", g, p->shade, 1, 255);
    check_band(&v, "global", g, p->ins.global, 0, INFINITY);
    check_band(&v, "beam", g, p->ins.beam, 0, INFINITY);
    check_band(&v, "diffuse", g, p->ins.diffuse, 0, INFINITY);
    check_band(&v, "reflected", g, p->ins.reflected, 0, INFINITY);
    check_band(&v, "sun hours", g, p->ins.sun_hours, 0, INSOL_DAYLIGHT_H);
    for (size_t c = 0; c < n; ++c) {
        if (!isfinite(g->z[c]))
            continue;
        double sum = (double)p->ins.beam[c] + p->ins.diffuse[c] + p->ins.reflected[c];
        if (!(fabs(sum - p->ins.global[c]) <= 1e-4 * fmax(1.0, sum)))
            fail(&v, "global %g != beam + diffuse + reflected %g at cell %zu", p->ins.global[c],
                 sum, c);
    }
    report(!v.bad,
           "%s, %s: every product finite, nodata exactly at the input's, in range (%zu "
           "violations%s%s)",
           label, dev_names[dev], v.bad, v.bad ? "; first: " : "", v.first);
}

/* OpenCL and the C twin compute the same functions. Horizons may differ by
 * float rounding (1e-3 deg allows for the arctangent), and a cell whose
 * horizon ties the sun to rounding may be lit on one and not the other. */
static void check_devices_agree(const char *label, const ss_grid *g, const products *a,
                                const products *b, const run_opts *o)
{
    verdict v = {"", 0};
    size_t n = a->n;
    for (size_t i = 0; i < n * a->directions; ++i)
        if (!(fabs(a->angle[i] - b->angle[i]) <= 1e-3))
            fail(&v, "horizon %g vs %g at %zu", a->angle[i], b->angle[i], i);
    for (int d = 0; d < 3; ++d)
        for (size_t c = 0; c < n; ++c)
            if (!(fabs(a->svf[d][c] - b->svf[d][c]) <= 1e-4))
                fail(&v, "svf %d: %g vs %g at %zu", d, a->svf[d][c], b->svf[d][c], c);
    for (size_t c = 0; c < n; ++c) {
        if (a->lit[c] != b->lit[c] && fabs(a->sun_horizon[c] - o->sun_el) > 1e-3)
            fail(&v, "sunlit %g vs %g at %zu (horizon %g, sun %g)", a->lit[c], b->lit[c], c,
                 a->sun_horizon[c], o->sun_el);
        if (!(fabs(a->shade[c] - b->shade[c]) <= 1e-3))
            fail(&v, "hillshade %g vs %g at %zu", a->shade[c], b->shade[c], c);
        if (!(fabs(a->ins.global[c] - b->ins.global[c]) <= 1e-3 * fmax(1.0, b->ins.global[c])) &&
            a->ins.sun_hours[c] == b->ins.sun_hours[c])
            fail(&v, "global %g vs %g at %zu", a->ins.global[c], b->ins.global[c], c);
    }
    (void)g;
    report(!v.bad, "%s: OpenCL and the C reference agree (%zu differences%s%s)", label, v.bad,
           v.bad ? "; first: " : "", v.first);
}

/* Runs a case on both devices with the invariants; results in p[0..1]. */
static int run_case(const char *label, const ss_grid *g, const run_opts *o, products p[2])
{
    int ok = 1;
    for (int dev = 0; dev < 2; ++dev) {
        if (!run_products(dev, g, o, &p[dev])) {
            report(0, "%s, %s: %s", label, dev_names[dev], p[dev].error);
            ok = 0;
            continue;
        }
        check_invariants(label, dev, g, &p[dev]);
    }
    if (ok)
        check_devices_agree(label, g, &p[0], &p[1], o);
    return ok;
}

/* Every product refuses the grid with the status given and a message. */
static void expect_refused(const char *label, const ss_grid *g, ss_status want)
{
    for (int dev = 0; dev < 2; ++dev) {
        ss_ctx *ctx = ctxs[dev];
        run_opts o = default_opts();
        ss_sweep_options opt = sweep_opts(&o);
        size_t n = (size_t)g->width * g->height;
        float *buf = malloc(n * 64 * sizeof(float) + 64);
        products dummy = {0};
        dummy.n = n;
        dummy.angle = dummy.dist = buf;
        ss_status st[6];
        char msg[6][200];
        st[0] = ss_horizon(ctx, g, &opt, 1, keep_horizon, &dummy);
        snprintf(msg[0], 200, "%s", ss_ctx_message(ctx));
        st[1] = ss_svf(ctx, g, &opt, SS_SVF_DEF_RADIATIVE, buf);
        snprintf(msg[1], 200, "%s", ss_ctx_message(ctx));
        st[2] = ss_cast_shadow(ctx, g, &opt, 135, 20, NULL, buf, NULL);
        snprintf(msg[2], 200, "%s", ss_ctx_message(ctx));
        st[3] = ss_hillshade(ctx, g, 315, 45, 1, 0, 0, buf);
        snprintf(msg[3], 200, "%s", ss_ctx_message(ctx));
        ss_insolation_out out = {
            .global = buf, .beam = buf, .diffuse = buf, .reflected = buf, .sun_hours = buf};
        steps_user su = {insol_steps, 3};
        ss_insolation_options io = {
            .albedo = 0.2, .shadow_mode = SS_SHADOW_EXACT};
        st[4] = ss_insolation(ctx, g, &opt, &io, 3, fixed_sun, &su, NULL, NULL, &out);
        snprintf(msg[4], 200, "%s", ss_ctx_message(ctx));
        st[5] = ss_sun_incidence(ctx, g, 135, 20, NULL, NULL, buf);
        snprintf(msg[5], 200, "%s", ss_ctx_message(ctx));
        int ok = 1;
        for (int k = 0; k < 6; ++k)
            ok &= st[k] == want && msg[k][0] != 0;
        tap_ok(ok,
               "%s, %s: every product refuses it with status %d and a message (statuses %d %d "
               "%d %d %d %d; \"%s\")",
               label, dev_names[dev], (int)want, st[0], st[1], st[2], st[3], st[4], st[5], msg[1]);
        free(buf);
    }
}

/* ---- helpers for known answers ------------------------------------------- */

/* Rise of the plane along azimuth phi: a cell on it sees every point of it
 * ahead at atan(rise) (negative downhill). */
static double plane_horizon_deg(double slope_deg, double aspect_deg, double phi_deg)
{
    return atan(-tan(slope_deg * M_PI / 180) * cos((phi_deg - aspect_deg) * M_PI / 180)) * 180 /
           M_PI;
}

/* Whether a line from the cell in azimuth phi (grid frame) meets another
 * cell centre's row or column inside the grid at least `cells` away: then
 * there is terrain ahead. Conservative: the cell must lie `cells` cells
 * inside the grid in both axis directions the azimuth points to. */
static int inside_ahead(const ss_grid *g, int c, int r, double phi_deg, int cells)
{
    double s = sin(phi_deg * M_PI / 180), co = cos(phi_deg * M_PI / 180);
    if (s > 1e-12 && c + cells >= g->width)
        return 0;
    if (s < -1e-12 && c - cells < 0)
        return 0;
    if (co > 1e-12 && r - cells < 0)
        return 0;
    if (co < -1e-12 && r + cells >= g->height)
        return 0;
    return 1;
}

/* The SVFs a tilted plane must give with D directions from offset: the
 * discrete means of the exact plane horizons (physics.md 2.2, 6.2), in
 * double, by the reference's own formulas. */
static void plane_svf(double slope_deg, double aspect_deg, int D, double offset, double svf[3])
{
    double *h = malloc(sizeof(double) * D);
    for (int i = 0; i < D; ++i)
        h[i] = plane_horizon_deg(slope_deg, aspect_deg, offset + 360.0 * i / D);
    double t = tan(slope_deg * M_PI / 180), a = aspect_deg * M_PI / 180;
    /* Gradient of a plane falling toward A: dz/de = -t sin A, dz/dn = -t cos A. */
    ref_svf_from_horizons(h, D, offset, -t * sin(a), -t * cos(a), svf);
    free(h);
}

/* ---- the cases ------------------------------------------------------------ */

/* Flat planes at sea level, Everest, the Dead Sea shore and 100 km (and
 * 100 km as the grid's origin with zero heights): two cells inside the
 * grid every horizon is exactly 0 (all samples at the same height); at the
 * edge an interpolated line may have a sample with nothing ahead (-90)
 * beside one that sees the plane (0), and the cell gets their weighted
 * mean, so there only [-90, 0] is asked; SVF exactly
 * 1 in every definition; a 20-degree sun lights every cell; the hillshade
 * of a level cell is 1 + 254 sin(45 deg) = 180.605; the irradiation is the
 * same in every cell and nothing is reflected (the whole sky is seen). */
static void flat_planes(void)
{
    const double heights[5] = {0.0, 8848.0, -430.0, 1e5, 0.0};
    for (int i = 0; i < 5; ++i) {
        ss_grid g = test_grid(24, 20, 30, 30);
        for (int k = 0; k < 24 * 20; ++k)
            g.z[k] = (float)heights[i];
        if (i == 4)
            g.z_origin_m = 1e5;
        char label[80];
        snprintf(label, sizeof label, "flat plane at %g m%s", i == 4 ? 1e5 : heights[i],
                 i == 4 ? " (as the grid's origin)" : "");
        run_opts o = default_opts();
        products p[2];
        if (run_case(label, &g, &o, p))
            for (int dev = 0; dev < 2; ++dev) {
                double worst_h = 0, worst_svf = 0, worst_shade = 0, lo = INFINITY, hi = 0;
                int dark = 0, edge_bad = 0;
                for (int d = 0; d < o.directions; ++d)
                    for (int k = 0; k < 24 * 20; ++k) {
                        float h = p[dev].angle[(size_t)d * 480 + k];
                        int r = k / 24, c = k % 24;
                        if (r >= 2 && r < 18 && c >= 2 && c < 22)
                            worst_h = fmax(worst_h, fabs(h));
                        else
                            edge_bad += !(h >= -90 && h <= 0);
                    }
                for (int k = 0; k < 480; ++k) {
                    for (int def = 0; def < 3; ++def)
                        worst_svf = fmax(worst_svf, fabs(p[dev].svf[def][k] - 1));
                    dark += p[dev].lit[k] != 1;
                    worst_shade =
                        fmax(worst_shade, fabs(p[dev].shade[k] - (1 + 254 * sin(M_PI / 4))));
                    lo = fmin(lo, p[dev].ins.global[k]);
                    hi = fmax(hi, p[dev].ins.global[k] + p[dev].ins.reflected[k]);
                }
                tap_ok(worst_h == 0 && edge_bad == 0 && worst_svf == 0 && dark == 0 &&
                           worst_shade < 1e-3 && hi - lo <= 1e-5 * hi && hi > 0,
                       "%s, %s: horizons 0 two cells inside (worst %g), in [-90, 0] at the "
                       "edge (%d not), SVF 1 (worst %g), all lit (%d dark), hillshade 180.605 "
                       "(worst %.1e), uniform irradiation %.2f..%.2f Wh/m2",
                       label, dev_names[dev], worst_h, edge_bad, worst_svf, dark, worst_shade, lo,
                       hi);
            }
        for (int dev = 0; dev < 2; ++dev)
            free_products(&p[dev]);
        ss_grid_free(&g);
    }
}

/* Constant slopes of 0.001 and 89 degrees facing south: uphill (north) the
 * horizon is the slope itself, downhill its negative (every point of the
 * plane is seen at atan(rise)); the SVFs are the discrete means of those
 * horizons; a sun from the north below the slope is hidden by the plane
 * itself and one above it is not; the hillshade of a plane is exactly
 * 1 + 254 cos(i) (Horn's gradient is exact on planes). */
static void slopes(void)
{
    const double slope[2] = {0.001, 89.0}, sun_below[2] = {0.0005, 60.0},
                 sun_above[2] = {0.002, 89.5};
    for (int i = 0; i < 2; ++i) {
        ss_grid g = test_grid(25, 25, 30, 30);
        test_plane(&g, slope[i], 180);
        char label[80];
        snprintf(label, sizeof label, "constant %g-degree slope", slope[i]);
        run_opts o = default_opts();
        o.directions = 32;
        o.sun_az = 0;
        o.sun_el = sun_below[i];
        o.light_az = 20;
        o.light_alt = 40;
        products p[2];
        if (run_case(label, &g, &o, p)) {
            double want_svf[3];
            plane_svf(slope[i], 180, 32, 0, want_svf);
            double cos_i =
                cos(slope[i] * M_PI / 180) * sin(40 * M_PI / 180) +
                sin(slope[i] * M_PI / 180) * cos(40 * M_PI / 180) * cos((20 - 180) * M_PI / 180);
            double want_shade = cos_i > 0 ? 1 + 254 * cos_i : 1;
            for (int dev = 0; dev < 2; ++dev) {
                double worst_h = 0, worst_svf = 0, worst_shade = 0;
                int wrong_lit = 0;
                for (int r = 2; r < 23; ++r)
                    for (int c = 2; c < 23; ++c) {
                        size_t k = (size_t)r * 25 + c;
                        /* Directions 0 (north) and 16 (south) of 32. */
                        worst_h = fmax(worst_h, fabs(p[dev].angle[k] - slope[i]));
                        worst_h = fmax(worst_h, fabs(p[dev].angle[16 * 625 + k] + slope[i]));
                        for (int d = 0; d < 3; ++d)
                            worst_svf = fmax(worst_svf, fabs(p[dev].svf[d][k] - want_svf[d]));
                        worst_shade = fmax(worst_shade, fabs(p[dev].shade[k] - want_shade));
                        wrong_lit += p[dev].lit[k] != 0;
                    }
                /* float32 heights of up to 40 km round by 2 mm over 30 m. */
                double tol_h = i ? 5e-3 : 1e-5;
                tap_ok(worst_h <= tol_h && worst_svf <= 1e-4 && worst_shade <= 2e-2 &&
                           wrong_lit == 0,
                       "%s, %s: horizon +-%g uphill/downhill (worst %.1e deg), SVF %.6f %.6f "
                       "%.6f (worst %.1e), hillshade %.3f (worst %.1e), sun from the north at "
                       "%g deg shadowed by the slope (%d lit)",
                       label, dev_names[dev], slope[i], worst_h, want_svf[0], want_svf[1],
                       want_svf[2], worst_svf, want_shade, worst_shade, sun_below[i], wrong_lit);
            }
        }
        for (int dev = 0; dev < 2; ++dev) {
            free_products(&p[dev]);
            float *lit = malloc(sizeof(float) * 625);
            ss_sweep_options opt = sweep_opts(&o);
            ss_status st = ss_cast_shadow(ctxs[dev], &g, &opt, 0, sun_above[i], NULL, lit, NULL);
            int dark = 0;
            for (int k = 0; st == SS_OK && k < 625; ++k)
                dark += lit[k] != 1;
            tap_ok(st == SS_OK && dark == 0, "%s, %s: a sun from the north at %g deg lights it all",
                   label, dev_names[dev], sun_above[i]);
            free(lit);
        }
        ss_grid_free(&g);
    }
}

/* A 10 km cliff between two columns (0 m west of column 70, 10 000 m from
 * it on), 30 m cells: looking east from a low cell the cliff's top edge
 * casts the horizon atan(1e4 / d), d the distance to column 70; looking
 * west from the edge cell the farthest low cell does, -atan(1e4 / 2100 m),
 * and from farther on the plateau itself, 0; a sun
 * in the east at 80 degrees leaves a shadow 1e4 / tan 80 = 1763 m long:
 * columns 12..69 dark (d <= 1740 m), 0..11 lit (d >= 1770 m). */
static void cliff(void)
{
    ss_grid g = test_grid(100, 5, 30, 30);
    for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 100; ++c)
            g.z[r * 100 + c] = c >= 70 ? 1e4f : 0.0f;
    for (int model = 0; model < 2; ++model) {
        run_opts o = default_opts();
        o.directions = 4; /* 0, 90, 180, 270: lines along rows and columns */
        o.lines = (ss_line_model)model;
        o.sun_az = 90;
        o.sun_el = 80;
        char label[80];
        snprintf(label, sizeof label, "10 km cliff, %s lines", model ? "digital" : "interpolated");
        products p[2];
        if (run_case(label, &g, &o, p))
            for (int dev = 0; dev < 2; ++dev) {
                double worst = 0;
                int wrong_lit = 0;
                for (int c = 0; c < 100; ++c) {
                    size_t k = 2 * 100 + c;
                    double east = p[dev].angle[1 * 500 + k], west = p[dev].angle[3 * 500 + k];
                    double want_e = c < 70 ? atan(1e4 / ((70 - c) * 30.0)) * 180 / M_PI
                                           : (c < 99 ? 0.0 : -90.0);
                    double want_w =
                        c == 70 ? -atan(1e4 / (70 * 30.0)) * 180 / M_PI : (c > 0 ? 0.0 : -90.0);
                    worst = fmax(worst, fmax(fabs(east - want_e), fabs(west - want_w)));
                    int want_lit = c <= 11 || c >= 70;
                    wrong_lit += p[dev].lit[k] != want_lit;
                }
                tap_ok(worst < 1e-3 && wrong_lit == 0,
                       "%s, %s: horizons to and from the cliff edge (worst %.1e deg); shadow "
                       "of a sun at 80 deg reaches 1763 m (%d cells wrong)",
                       label, dev_names[dev], worst, wrong_lit);
            }
        for (int dev = 0; dev < 2; ++dev)
            free_products(&p[dev]);
    }
    ss_grid_free(&g);
}

/* A single 10 km spike on a flat plane, 1 km cells, earth curvature off and
 * on (R = 6371 km, k = 0.13): from j cells south of it the spike is seen at
 * atan((1e4 - d^2 / 2R_eff) / d), d = j km; from its top every horizon
 * looks down to the grid's edge, where (-1e4 - d^2 / 2R_eff) / d is
 * largest (it grows with d below sqrt(2 R_eff 1e4) = 383 km), and its SVF
 * is 1. */
static void spike(void)
{
    ss_grid g = test_grid(41, 41, 1000, 1000);
    for (int k = 0; k < 41 * 41; ++k)
        g.z[k] = 0.0f;
    g.z[20 * 41 + 20] = 1e4f;
    for (int curv = 0; curv < 2; ++curv) {
        run_opts o = default_opts();
        o.directions = 4;
        o.earth_radius_m = curv ? 6371000.0 : 0.0;
        o.refraction_k = curv ? 0.13 : 0.0;
        double ck = curv ? 0.5 * (1 - 0.13) / 6371000.0 : 0.0;
        char label[80];
        snprintf(label, sizeof label, "10 km spike, curvature %s", curv ? "on" : "off");
        products p[2];
        if (run_case(label, &g, &o, p))
            for (int dev = 0; dev < 2; ++dev) {
                double worst = 0;
                for (int j = 1; j <= 20; ++j) {
                    double d = j * 1000.0;
                    double want = atan((1e4 - d * d * ck) / d) * 180 / M_PI;
                    worst = fmax(worst, fabs(p[dev].angle[(size_t)(20 + j) * 41 + 20] - want));
                }
                double top = p[dev].angle[20 * 41 + 20];
                double want_top = atan((-1e4 - 2e4 * 2e4 * ck) / 2e4) * 180 / M_PI;
                double svf_top = p[dev].svf[0][20 * 41 + 20];
                tap_ok(worst < 1e-3 && fabs(top - want_top) < 1e-3 && svf_top == 1,
                       "%s, %s: spike seen at atan((H - d^2/2R_eff)/d) from 1..20 km (worst "
                       "%.1e deg); from its top %.4f deg (want %.4f), SVF 1 (%g)",
                       label, dev_names[dev], worst, top, want_top, svf_top);
            }
        for (int dev = 0; dev < 2; ++dev)
            free_products(&p[dev]);
    }
    ss_grid_free(&g);
}

/* A 1 m pit in a flat plane of 1 m cells, 8 directions: from the pit's
 * bottom the rims are 1 m up at 1 m on the axes (45 deg) and at sqrt 2 m on
 * the diagonals (35.26 deg); SVF_Z = 1 - (sin 45 + 1/sqrt 3)/2 = 0.357771,
 * SVF_D = (1/2 + 2/3)/2 = 0.583333 for the horizontal and (the gradient
 * being 0) the tilted cell. Lines on axes and diagonals pass through cell
 * centres, so both line models are exact. */
static void pit(void)
{
    ss_grid g = test_grid(21, 21, 1, 1);
    for (int k = 0; k < 21 * 21; ++k)
        g.z[k] = 0.0f;
    g.z[10 * 21 + 10] = -1.0f;
    double want[3] = {1 - (sin(M_PI / 4) + 1 / sqrt(3.0)) / 2, (0.5 + 2.0 / 3) / 2,
                      (0.5 + 2.0 / 3) / 2};
    for (int model = 0; model < 2; ++model) {
        run_opts o = default_opts();
        o.directions = 8;
        o.lines = (ss_line_model)model;
        char label[80];
        snprintf(label, sizeof label, "1 m pit, %s lines", model ? "digital" : "interpolated");
        products p[2];
        if (run_case(label, &g, &o, p))
            for (int dev = 0; dev < 2; ++dev) {
                double worst_h = 0, worst_s = 0;
                for (int d = 0; d < 8; ++d)
                    worst_h = fmax(worst_h, fabs(p[dev].angle[(size_t)d * 441 + 220] -
                                                 (d % 2 ? 35.2643897 : 45.0)));
                for (int def = 0; def < 3; ++def)
                    worst_s = fmax(worst_s, fabs(p[dev].svf[def][220] - want[def]));
                tap_ok(worst_h < 1e-4 && worst_s < 1e-5,
                       "%s, %s: bottom horizons 45 / 35.26 deg (worst %.1e), SVF %.6f %.6f "
                       "%.6f (worst %.1e)",
                       label, dev_names[dev], worst_h, want[0], want[1], want[2], worst_s);
            }
        for (int dev = 0; dev < 2; ++dev)
            free_products(&p[dev]);
    }
    ss_grid_free(&g);
}

/* Plateaus and exact ties. A staircase z = column (1 m cells) puts every
 * sample ahead of a cell, looking east, on one straight line: all tie at
 * 45 deg, and the distance reported must be one of theirs (a whole number
 * of metres, 1 .. the cells left); looking west every sample is at -45.
 * Random plateaus (heights in four levels, long runs of one) only need the
 * invariants and the twins' agreement. */
static void plateaus_and_ties(void)
{
    ss_grid g = test_grid(30, 4, 1, 1);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 30; ++c)
            g.z[r * 30 + c] = (float)c;
    run_opts o = default_opts();
    o.directions = 4;
    products p[2];
    if (run_case("staircase of exact ties", &g, &o, p))
        for (int dev = 0; dev < 2; ++dev) {
            double worst = 0;
            int bad_dist = 0;
            for (int c = 0; c < 30; ++c) {
                size_t k = 30 + c;
                float e = p[dev].angle[120 + k], w = p[dev].angle[360 + k];
                float de = p[dev].dist[120 + k];
                worst = fmax(worst, fabs(e - (c < 29 ? 45.0 : -90.0)));
                worst = fmax(worst, fabs(w - (c > 0 ? -45.0 : -90.0)));
                if (c < 29)
                    bad_dist += !(fabs(de - nearbyint(de)) < 1e-3 && de >= 1 && de <= 29 - c);
            }
            tap_ok(worst < 1e-4 && bad_dist == 0,
                   "staircase of exact ties, %s: 45 deg east, -45 west (worst %.1e); distance "
                   "one of the tied samples' (%d wrong)",
                   dev_names[dev], worst, bad_dist);
        }
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);
    g = test_grid(40, 40, 1, 1);
    test_fill(&g, TERRAIN_PLATEAUS, 3, 4);
    o = default_opts();
    run_case("random plateaus", &g, &o, p);
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);
}

/* Grid shapes: 1 x 1 has no horizon and is refused clearly; 1 x N, N x 1,
 * 2 x 2, a long thin strip and odd sizes run. On a plane along a one-cell
 * strip the horizon along the strip is still atan(rise), and across it
 * nothing lies ahead (-90). */
static void grid_shapes(void)
{
    ss_grid g = test_grid(1, 1, 30, 30);
    g.z[0] = 100.0f;
    expect_refused("1 x 1 grid", &g, SS_ERR_INPUT);
    ss_grid_free(&g);
    const struct {
        int w, h;
    } sizes[] = {{1, 40}, {40, 1}, {2, 2}, {3000, 2}, {2, 3000}, {4099, 3}};
    for (int i = 0; i < 6; ++i) {
        g = test_grid(sizes[i].w, sizes[i].h, 10, 10);
        test_plane(&g, 20, sizes[i].w == 1 ? 0 : 90); /* rises along the long axis */
        if (sizes[i].w * sizes[i].h > 100)
            test_fill(&g, TERRAIN_SMOOTH, 5, 50);
        char label[80];
        snprintf(label, sizeof label, "%d x %d grid", sizes[i].w, sizes[i].h);
        run_opts o = default_opts();
        o.directions = sizes[i].w * sizes[i].h > 100 ? 8 : 4;
        products p[2];
        if (run_case(label, &g, &o, p) && sizes[i].w * sizes[i].h <= 100 &&
            (sizes[i].w == 1 || sizes[i].h == 1))
            for (int dev = 0; dev < 2; ++dev) {
                /* The strip's azimuths: 0/180 for 1 x N, 90/270 for N x 1. */
                int along = sizes[i].w == 1 ? 0 : 1, across = 1 - along;
                double aspect = sizes[i].w == 1 ? 0 : 90;
                double worst = 0;
                int len = sizes[i].w * sizes[i].h;
                for (int k = 1; k < len - 1; ++k) {
                    for (int s = 0; s < 2; ++s) {
                        int d = along + 2 * s; /* direction index of 4 */
                        double want = plane_horizon_deg(20, aspect, d * 90.0);
                        worst = fmax(worst, fabs(p[dev].angle[(size_t)d * len + k] - want));
                        int dx = across + 2 * s;
                        worst = fmax(worst, fabs(p[dev].angle[(size_t)dx * len + k] + 90));
                    }
                }
                tap_ok(worst < 1e-4,
                       "%s, %s: along the strip atan(rise), across it nothing ahead (-90) "
                       "(worst %.1e deg)",
                       label, dev_names[dev], worst);
            }
        for (int dev = 0; dev < 2; ++dev)
            free_products(&p[dev]);
        ss_grid_free(&g);
    }
}

/* Non-square pixels (30 x 10 m): on a tilted plane the interpolated
 * samples lie on the plane, so horizons are atan(rise) at any azimuth, and
 * Horn's gradient (with the cell sizes) gives the hillshade 1 + 254 cos(i)
 * exactly. */
static void non_square(void)
{
    ss_grid g = test_grid(31, 31, 30, 10);
    test_plane(&g, 30, 120);
    run_opts o = default_opts();
    o.directions = 8;
    o.offset_deg = 10;
    o.light_az = 300;
    o.light_alt = 35;
    products p[2];
    if (run_case("30 x 10 m cells", &g, &o, p)) {
        double cos_i = cos(30 * M_PI / 180) * sin(35 * M_PI / 180) +
                       sin(30 * M_PI / 180) * cos(35 * M_PI / 180) * cos((300 - 120) * M_PI / 180);
        double want_shade = cos_i > 0 ? 1 + 254 * cos_i : 1;
        for (int dev = 0; dev < 2; ++dev) {
            double worst = 0, worst_shade = 0;
            for (int d = 0; d < 8; ++d) {
                double az = 10 + 45.0 * d, want = plane_horizon_deg(30, 120, az);
                for (int r = 1; r < 30; ++r)
                    for (int c = 1; c < 30; ++c)
                        if (inside_ahead(&g, c, r, az, 2))
                            worst = fmax(worst,
                                         fabs(p[dev].angle[(size_t)d * 961 + r * 31 + c] - want));
            }
            for (int r = 1; r < 30; ++r)
                for (int c = 1; c < 30; ++c)
                    worst_shade = fmax(worst_shade, fabs(p[dev].shade[r * 31 + c] - want_shade));
            tap_ok(worst < 1e-3 && worst_shade < 1e-2,
                   "30 x 10 m cells, %s: horizons atan(rise) (worst %.1e deg), hillshade %.3f "
                   "(worst %.1e)",
                   dev_names[dev], worst, want_shade, worst_shade);
        }
    }
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);
}

/* Nodata: holes in rough terrain; a nodata border around a plane (it only
 * removes samples, so inner horizons stay atan(rise)); all nodata but one
 * cell (nothing ahead anywhere: horizons -90, SVF 1, lit, level hillshade);
 * +-Inf heights are nodata like NaN; all nodata is refused clearly. */
static void nodata(void)
{
    ss_grid g = test_grid(40, 36, 20, 20);
    test_fill(&g, TERRAIN_SMOOTH, 9, 300);
    test_holes(&g, 4, 10, 6);
    products p[2];
    run_opts o = default_opts();
    run_case("rough terrain with nodata holes", &g, &o, p);
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);

    g = test_grid(30, 30, 10, 10);
    test_plane(&g, 25, 300);
    for (int k = 0; k < 30; ++k)
        g.z[k] = g.z[29 * 30 + k] = g.z[k * 30] = g.z[k * 30 + 29] = NAN;
    o = default_opts();
    o.directions = 8;
    if (run_case("plane with a nodata border", &g, &o, p))
        for (int dev = 0; dev < 2; ++dev) {
            double worst = 0;
            for (int d = 0; d < 8; ++d)
                for (int r = 3; r < 27; ++r)
                    for (int c = 3; c < 27; ++c)
                        if (inside_ahead(&g, c, r, 45.0 * d, 3))
                            worst = fmax(worst, fabs(p[dev].angle[(size_t)d * 900 + r * 30 + c] -
                                                     plane_horizon_deg(25, 300, 45.0 * d)));
            tap_ok(worst < 1e-3,
                   "plane with a nodata border, %s: inner horizons atan(rise) "
                   "(worst %.1e deg)",
                   dev_names[dev], worst);
        }
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);

    g = test_grid(15, 11, 30, 30);
    g.z[5 * 15 + 7] = 250.0f;
    o = default_opts();
    if (run_case("all nodata but one cell", &g, &o, p))
        for (int dev = 0; dev < 2; ++dev) {
            size_t k = 5 * 15 + 7;
            int worst = 0;
            for (int d = 0; d < o.directions; ++d)
                worst += p[dev].angle[(size_t)d * 165 + k] != -90;
            tap_ok(worst == 0 && p[dev].svf[0][k] == 1 && p[dev].svf[2][k] == 1 &&
                       p[dev].lit[k] == 1 &&
                       fabs(p[dev].shade[k] - (1 + 254 * sin(M_PI / 4))) < 1e-3,
                   "all nodata but one cell, %s: nothing ahead (%d directions see terrain), "
                   "SVF %g, lit %g, level hillshade %.3f",
                   dev_names[dev], worst, p[dev].svf[0][k], p[dev].lit[k], p[dev].shade[k]);
        }
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);

    /* +-Inf heights: nodata (ss_grid: NAN marks nodata; any non-finite
     * height cannot be terrain). */
    for (int k = 0; k < 165; ++k)
        g.z[k] = (float)(k % 7);
    g.z[3] = INFINITY;
    g.z[50] = -INFINITY;
    g.z[100] = NAN;
    o = default_opts();
    run_case("heights +Inf, -Inf and NaN", &g, &o, p);
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    for (int k = 0; k < 165; ++k)
        g.z[k] = NAN;
    expect_refused("all nodata", &g, SS_ERR_INPUT);
    ss_grid_free(&g);
}

/* Directions exactly on and 1e-9 degrees off the axes and diagonals: on a
 * plane the interpolated lines' samples stay on the plane, so a single
 * direction's horizon is atan(rise) whichever side of the axis the line
 * tips to; the shadow of a sun 0.5 deg below / above that is dark / lit. */
static void azimuth_edges(void)
{
    ss_grid g = test_grid(31, 31, 25, 25);
    test_plane(&g, 20, 63);
    const double axes[6] = {0, 45, 90, 135, 180, 270};
    verdict v[2] = {{"", 0}, {"", 0}};
    for (int a = 0; a < 6; ++a)
        for (int off = -1; off <= 1; ++off) {
            double az = axes[a] + off * 1e-9;
            if (az < 0)
                az += 360;
            run_opts o = default_opts();
            o.directions = 1;
            o.offset_deg = az;
            o.sun_az = az;
            double want = plane_horizon_deg(20, 63, az);
            o.sun_el = want - 0.5;
            char label[80];
            snprintf(label, sizeof label, "azimuth %.9f", az);
            products p[2];
            if (run_case(label, &g, &o, p))
                for (int dev = 0; dev < 2; ++dev)
                    for (int r = 2; r < 29; ++r)
                        for (int c = 2; c < 29; ++c) {
                            if (!inside_ahead(&g, c, r, az, 2))
                                continue;
                            size_t k = (size_t)r * 31 + c;
                            if (!(fabs(p[dev].angle[k] - want) < 1e-3))
                                fail(&v[dev], "az %.9f cell %zu: %g, want %g", az, k,
                                     p[dev].angle[k], want);
                            if (want - 0.5 > -90 && p[dev].lit[k] != 0)
                                fail(&v[dev], "az %.9f cell %zu lit under its horizon", az, k);
                        }
            for (int dev = 0; dev < 2; ++dev)
                free_products(&p[dev]);
        }
    for (int dev = 0; dev < 2; ++dev)
        tap_ok(!v[dev].bad,
               "azimuths on and 1e-9 deg off 0, 45, 90, 135, 180, 270, %s: horizons atan(rise), "
               "shadowed 0.5 deg below (%zu wrong%s%s)",
               dev_names[dev], v[dev].bad, v[dev].bad ? "; first: " : "", v[dev].first);
    ss_grid_free(&g);
}

/* Numbers of directions 1, 2, 3, 7 and 360 on a plane: the SVFs are the
 * discrete means of the exact horizons (plane_svf), in both shadow modes
 * of the insolation; 3600 directions on a flat 2 x 2 grid give SVF 1. */
static void direction_counts(void)
{
    ss_grid g = test_grid(31, 31, 20, 20);
    test_plane(&g, 30, 200);
    const int counts[5] = {1, 2, 3, 7, 360};
    for (int i = 0; i < 5; ++i)
        for (int mode = 0; mode < 2; ++mode) {
            run_opts o = default_opts();
            o.directions = counts[i];
            o.offset_deg = 5;
            o.shadow_mode = (ss_shadow_mode)mode;
            char label[80];
            snprintf(label, sizeof label, "D = %d, %s shadows", counts[i],
                     mode ? "interpolated" : "exact");
            products p[2];
            if (run_case(label, &g, &o, p) && mode == 0) {
                double want[3];
                plane_svf(30, 200, counts[i], 5, want);
                for (int dev = 0; dev < 2; ++dev) {
                    double worst = 0;
                    /* Cells far enough inside that every direction has
                     * terrain ahead. */
                    for (int r = 8; r < 23; ++r)
                        for (int c = 8; c < 23; ++c)
                            for (int d = 0; d < 3; ++d)
                                worst = fmax(worst, fabs(p[dev].svf[d][r * 31 + c] - want[d]));
                    tap_ok(worst < 1e-4,
                           "%s, %s: SVF = discrete means of the plane's horizons %.6f %.6f "
                           "%.6f (worst %.1e)",
                           label, dev_names[dev], want[0], want[1], want[2], worst);
                }
            }
            for (int dev = 0; dev < 2; ++dev)
                free_products(&p[dev]);
        }
    ss_grid_free(&g);
    g = test_grid(2, 2, 10, 10);
    for (int k = 0; k < 4; ++k)
        g.z[k] = 42.0f;
    run_opts o = default_opts();
    o.directions = 3600;
    products p[2];
    if (run_case("D = 3600 on a flat 2 x 2 grid", &g, &o, p))
        for (int dev = 0; dev < 2; ++dev) {
            double worst = 0;
            for (int k = 0; k < 4; ++k)
                for (int d = 0; d < 3; ++d)
                    worst = fmax(worst, fabs(p[dev].svf[d][k] - 1));
            tap_ok(worst == 0, "D = 3600 on a flat 2 x 2 grid, %s: SVF exactly 1 (worst %g)",
                   dev_names[dev], worst);
        }
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);
}

/* The sun on the horizon and near it. On a flat plane every horizon is 0
 * (none ahead counts as 0 for shadows): a sun exactly on it or 1e-6 deg
 * below is not above the terrain, so dark; 1e-6 above, lit; at the zenith
 * every cell of rough terrain is lit (no DEM horizon reaches 90 deg);
 * below -18 (astronomical night) dark. The hillshade of a level cell is
 * 1 + 254 sin(alt): 1 with the light on the horizon, 255 at the zenith; a
 * light below the horizon is refused. Insolation steps at those suns:
 * night steps (true elevation <= 0) add exactly nothing; a sun 1e-6 deg up
 * already lights slopes facing it (ESRA's air mass at the horizon is ~38,
 * not infinite, so the beam is ~100 W/m2 there), less than the zenith
 * step. */
static void sun_positions(void)
{
    ss_grid flat = test_grid(20, 20, 30, 30);
    for (int k = 0; k < 400; ++k)
        flat.z[k] = 500.0f;
    ss_grid rough = test_grid(30, 30, 20, 20);
    test_fill(&rough, TERRAIN_SMOOTH, 21, 400);
    const double els[6] = {0.0, 1e-6, -1e-6, 90.0, -18.5, -90.0};
    const float want_lit[6] = {0, 1, 0, 1, 0, 0};
    for (int dev = 0; dev < 2; ++dev) {
        ss_ctx *ctx = ctxs[dev];
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        float *lit = malloc(sizeof(float) * 900);
        int wrong = 0;
        char trail[200] = "";
        for (int i = 0; i < 6; ++i) {
            ss_status st = ss_cast_shadow(ctx, &flat, &opt, 200, els[i], NULL, lit, NULL);
            int bad = st != SS_OK;
            for (int k = 0; st == SS_OK && k < 400; ++k)
                bad += lit[k] != want_lit[i];
            size_t len = strlen(trail);
            snprintf(trail + len, sizeof trail - len, " %g:%s", els[i], bad ? "WRONG" : "ok");
            wrong += bad;
        }
        ss_status st = ss_cast_shadow(ctx, &rough, &opt, 200, 90.0, NULL, lit, NULL);
        int dark = st != SS_OK;
        for (int k = 0; st == SS_OK && k < 900; ++k)
            dark += lit[k] != 1;
        tap_ok(wrong == 0 && dark == 0,
               "%s: flat plane, sun at elevation (deg) ->%s; zenith sun lights all of rough "
               "terrain (%d dark)",
               dev_names[dev], trail, dark);
        float *shade = malloc(sizeof(float) * 400);
        ss_status s0 = ss_hillshade(ctx, &flat, 200, 0, 1, 0, 0, shade);
        float at0 = shade[55];
        ss_status s90 = ss_hillshade(ctx, &flat, 200, 90, 1, 0, 0, shade);
        float at90 = shade[55];
        ss_status sneg = ss_hillshade(ctx, &flat, 200, -18.5, 1, 0, 0, shade);
        tap_ok(s0 == SS_OK && s90 == SS_OK && fabs(at0 - 1) < 1e-4 && fabs(at90 - 255) < 1e-3 &&
                   sneg == SS_ERR_ARGUMENT,
               "%s: hillshade of a level cell %g with the light on the horizon, %g at the "
               "zenith; a light at -18.5 deg is refused (status %d)",
               dev_names[dev], at0, at90, (int)sneg);
        free(shade);
        /* Insolation, one step per sun. */
        const double steps[6][2] = {{200, 0.0},  {200, 1e-6},  {200, -1e-6},
                                    {200, 90.0}, {200, -18.5}, {200, -90.0}};
        double global[6];
        int finite = 1;
        for (int i = 0; i < 6; ++i) {
            ss_insolation_out out;
            float *b[5];
            for (int q = 0; q < 5; ++q)
                b[q] = malloc(sizeof(float) * 900);
            out = (ss_insolation_out){
                .global = b[0], .beam = b[1], .diffuse = b[2], .reflected = b[3], .sun_hours = b[4]};
            ss_insolation_options io = {
                .albedo = 0.2, .shadow_mode = SS_SHADOW_EXACT};
            steps_user su = {&steps[i], 1};
            ss_status si =
                ss_insolation(ctx, &rough, &opt, &io, 1, fixed_sun, &su, NULL, NULL, &out);
            global[i] = si == SS_OK ? 0 : NAN;
            for (int k = 0; si == SS_OK && k < 900; ++k) {
                finite &= isfinite(b[0][k]) && b[0][k] >= 0 && isfinite(b[4][k]);
                global[i] = fmax(global[i], b[0][k]);
            }
            for (int q = 0; q < 5; ++q)
                free(b[q]);
        }
        tap_ok(finite && global[0] == 0 && global[2] == 0 && global[4] == 0 && global[5] == 0 &&
                   global[1] > 0 && global[1] < global[3] && global[3] > 500,
               "%s: insolation steps with the sun at 0, 1e-6, -1e-6, 90, -18.5, -90 deg: "
               "largest global %g %g %g %g %g %g Wh/m2 (night adds exactly 0)",
               dev_names[dev], global[0], global[1], global[2], global[3], global[4], global[5]);
        free(lit);
    }
    ss_grid_free(&flat);
    ss_grid_free(&rough);
}

/* Extremes of scale the grid accepts: cells of 1 mm with a 8848 m spike
 * (slopes of 1e7), and heights of +-9.9e6 m (the limit is 1e7) side by side
 * on 1 km cells with curvature on. Only the invariants are asked: finite,
 * in range, nodata kept, the twins agreeing. (The second found that the
 * air-pressure factor of insolation overflowed below -748 km; heights
 * under -1000 m now get the -1000 m air.) */
static void extremes(void)
{
    ss_grid g = test_grid(20, 20, 1e-3, 1e-3);
    for (int k = 0; k < 400; ++k)
        g.z[k] = 0.0f;
    g.z[210] = 8848.0f;
    g.z[5] = NAN;
    run_opts o = default_opts();
    products p[2];
    run_case("1 mm cells with an 8848 m spike", &g, &o, p);
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);
    g = test_grid(16, 16, 1000, 1000);
    for (int k = 0; k < 256; ++k)
        g.z[k] = (k + k / 16) % 2 ? 9.9e6f : -9.9e6f;
    o = default_opts();
    o.earth_radius_m = 6371000;
    o.refraction_k = 0.13;
    run_case("+-9.9e6 m checkerboard, 1 km cells, curvature on", &g, &o, p);
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    /* The same heights without insolation's air mass are fine: every
     * sweep product alone. */
    for (int k = 0; k < 256; ++k)
        g.z[k] = (k + k / 16) % 2 ? 9.9e6f : -7e5f;
    run_case("+9.9e6 / -7e5 m checkerboard, 1 km cells, curvature on", &g, &o, p);
    for (int dev = 0; dev < 2; ++dev)
        free_products(&p[dev]);
    ss_grid_free(&g);
}

int main(void)
{
    for (int dev = 0; dev < 2; ++dev) {
        ctxs[dev] = ss_ctx_new();
        if (ss_ctx_use_device(ctxs[dev], dev ? "reference" : NULL) != SS_OK) {
            printf("Bail out! %s\n", ss_ctx_message(ctxs[dev]));
            return 99;
        }
    }
    flat_planes();
    slopes();
    cliff();
    spike();
    pit();
    plateaus_and_ties();
    grid_shapes();
    non_square();
    nodata();
    azimuth_edges();
    direction_counts();
    sun_positions();
    extremes();
    for (int dev = 0; dev < 2; ++dev)
        ss_ctx_free(ctxs[dev]);
    return tap_done();
}
