/* The measurements behind doc/accuracy.md: error against an independent
 * reference and wall time of each accuracy knob, printed as CSV rows
 *     study,scene,class,setting,value,quantity,mean,p95,max,seconds,cells
 * (errors are absolute: degrees for horizons, SVF units, percent of the
 * reference for irradiation, percent of cells for shadow flips; mean, 95th
 * percentile and maximum; seconds is the wall time of the library call on
 * the whole grid of `cells` cells, kernel build excluded, the fastest of
 * --reps runs). Run by
 * doc/accuracy.sh; built by `make accuracy`.
 *
 *   directions  horizon and SVF error against the continuous reference
 *               (tests/reference_march.c) at sampled cells, for each number
 *               of directions and line model
 *   cost        wall time of the horizon and each SVF on the whole grid
 *   insolation  daily irradiation error for each time step and shadow mode
 *               against 1-minute steps with exact shadows
 *   effects     what switching each physical effect off changes
 *   machine     the device and its name */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "dem_io.h"
#include "frame.h"
#include "iso_time.h"
#include "reference_march.h"
#include "sun_field.h"

#define MAX_LIST 16

typedef struct {
    const char *mode, *scene, *klass, *dem_path, *shape, *date, *device;
    int crop_w, crop_h, cells, ref_az, margin;
    int dirs[MAX_LIST], n_dirs, digital_dirs[MAX_LIST], n_digital_dirs;
    int steps_min[MAX_LIST], n_steps, interp_dirs[MAX_LIST], n_interp_dirs;
    double ref_step_min, utc_offset_h;
    int insol_dirs;
    int reps; /* timed calls repeated, the fastest kept (the machine is shared) */
} args;

static ss_ctx *ctx;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The fastest of reps runs of a library call (the results are the same
 * each time; the machine is shared, so the fastest is the least disturbed). */
#define TIMED(reps, seconds, call, what)                                                           \
    do {                                                                                           \
        (seconds) = INFINITY;                                                                      \
        for (int rep_ = 0; rep_ < ((reps) > 0 ? (reps) : 1); ++rep_) {                             \
            double t_ = now_s();                                                                   \
            check((call), (what));                                                                 \
            (seconds) = fmin((seconds), now_s() - t_);                                             \
        }                                                                                          \
    } while (0)

static void die(const char *what)
{
    fprintf(stderr, "accuracy_driver: %s: %s\n", what, ctx ? ss_ctx_message(ctx) : "");
    exit(1);
}

static void check(ss_status st, const char *what)
{
    if (st != SS_OK)
        die(what);
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "accuracy_driver: out of memory\n");
        exit(1);
    }
    return p;
}

static int parse_list(const char *text, int *out)
{
    int n = 0;
    for (const char *p = text; *p && n < MAX_LIST;) {
        char *end;
        out[n++] = (int)strtol(p, &end, 10);
        p = *end == ',' ? end + 1 : end;
        if (end == p && *p)
            break;
    }
    return n;
}

/* ---- statistics and output -------------------------------------------- */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Mean, 95th percentile (nearest rank) and maximum of |v|; v is sorted. */
static void stats(double *v, size_t n, double out[3])
{
    out[0] = out[1] = out[2] = NAN;
    if (!n)
        return;
    double sum = 0;
    for (size_t i = 0; i < n; ++i)
        sum += (v[i] = fabs(v[i]));
    qsort(v, n, sizeof *v, cmp_double);
    size_t rank = (size_t)ceil(0.95 * (double)n);
    out[0] = sum / (double)n;
    out[1] = v[rank ? rank - 1 : 0];
    out[2] = v[n - 1];
}

static void row(const args *a, const char *study, const char *setting, double value,
                const char *quantity, const double s[3], double seconds, size_t cells)
{
    printf("%s,%s,%s,%s,%g,%s,%.6g,%.6g,%.6g,%.6f,%zu\n", study, a->scene, a->klass, setting, value,
           quantity, s[0], s[1], s[2], seconds, cells);
    fflush(stdout);
}

/* ---- scenes ------------------------------------------------------------- */

typedef struct {
    ss_dem dem; /* grid and georeferencing (crs_wkt NULL for shapes) */
    ss_dem_frame frame;
    int have_frame;
} scene;

/* The central crop_w x crop_h window of a DEM, georeferencing moved along. */
static void crop(ss_dem *dem, int w, int h)
{
    ss_grid *g = &dem->grid;
    if (w <= 0 || h <= 0 || (w >= g->width && h >= g->height))
        return;
    w = w < g->width ? w : g->width;
    h = h < g->height ? h : g->height;
    int x0 = (g->width - w) / 2, y0 = (g->height - h) / 2;
    ss_grid c;
    check(ss_grid_alloc(ctx, &c, w, h, g->cell_x_m, g->cell_y_m), "crop");
    c.z_origin_m = g->z_origin_m;
    for (int r = 0; r < h; ++r)
        memcpy(c.z + (size_t)r * w, g->z + (size_t)(r + y0) * g->width + x0, sizeof(float) * w);
    ss_grid_free(g);
    *g = c;
    double *gt = dem->geotransform;
    gt[0] += x0 * gt[1] + y0 * gt[2];
    gt[3] += x0 * gt[4] + y0 * gt[5];
}

/* Analytic shapes (reference/physics.md 2.4) on 30 m cells. */
static void make_shape(const char *shape, int n, ss_dem *dem)
{
    memset(dem, 0, sizeof *dem);
    check(ss_grid_alloc(ctx, &dem->grid, n, n, 30, 30), "shape");
    ss_grid *g = &dem->grid;
    double c0 = (n - 1) / 2.0;
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            double x = (c - c0) * 30, y = (c0 - r) * 30, rho = hypot(x, y), z;
            if (!strcmp(shape, "plane30"))
                z = -tan(30 * M_PI / 180) * -y; /* faces south */
            else if (!strcmp(shape, "vvalley"))
                z = tan(30 * M_PI / 180) * fabs(x); /* axis north-south */
            else if (!strcmp(shape, "bowl")) {
                double R = 0.4 * n * 30; /* hemisphere of radius R, flat beyond */
                z = rho < R ? R - sqrt(R * R - rho * rho) : R;
            } else {
                fprintf(stderr, "accuracy_driver: unknown shape %s\n", shape);
                exit(2);
            }
            g->z[(size_t)r * n + c] = (float)z;
        }
    snprintf(dem->description, sizeof dem->description, "shape %s", shape);
}

static void open_scene(const args *a, scene *s)
{
    memset(s, 0, sizeof *s);
    if (a->shape) {
        make_shape(a->shape, a->crop_w > 0 ? a->crop_w : 256, &s->dem);
        check(ss_dem_frame_open(ctx, &s->dem, &s->frame), "frame");
        s->have_frame = 1;
        return;
    }
    const char *paths[1] = {a->dem_path};
    check(ss_dem_read(ctx, paths, 1, NULL, &s->dem), a->dem_path);
    crop(&s->dem, a->crop_w, a->crop_h);
    check(ss_dem_frame_open(ctx, &s->dem, &s->frame), "frame");
    s->have_frame = 1;
}

static void close_scene(scene *s)
{
    if (s->have_frame)
        ss_dem_frame_close(&s->frame);
    ss_dem_free(&s->dem);
}

static size_t valid_cells(const ss_grid *g)
{
    size_t n = 0, all = (size_t)g->width * g->height;
    for (size_t c = 0; c < all; ++c)
        n += isfinite(g->z[c]);
    return n;
}

/* ---- directions: error against the continuous reference ----------------- */

typedef struct {
    const int *cells; /* sampled cell indices */
    int n_cells, directions;
    float *out; /* n_cells x directions */
} sample_sink;

static int keep_samples(int index, double az, const float *angle, const float *dist,
                        const float *cast, void *user)
{
    (void)cast;
    (void)az;
    (void)dist;
    sample_sink *s = user;
    for (int k = 0; k < s->n_cells; ++k)
        s->out[(size_t)k * s->directions + index] = angle[s->cells[k]];
    return 1;
}

static unsigned rng_state = 12345u;
static unsigned rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static void study_directions(const args *a)
{
    scene s;
    open_scene(a, &s);
    const ss_grid *g = &s.dem.grid;
    size_t n_all = valid_cells(g);
    ref_march rm;
    ref_march_init(&rm, g, 0, 0);
    /* Cells at least `margin` cells inside the grid, valid, with terrain
     * ahead in every azimuth (a coast looking out to sea has none, and an
     * interpolated -90 is not a horizon error). Drawn until enough. */
    int want = a->cells, n_cells = 0, n_az = a->ref_az;
    int *cells = xmalloc(sizeof(int) * want);
    double *ref_h = xmalloc(sizeof(double) * (size_t)want * n_az);
    double *ref_s = xmalloc(sizeof(double) * (size_t)want * 3);
    double t0 = now_s();
    int tries = 0;
    while (n_cells < want && tries < 50) {
        int batch = want - n_cells, *cand = xmalloc(sizeof(int) * batch);
        int *ok = xmalloc(sizeof(int) * batch);
        for (int k = 0; k < batch; ++k) {
            int c, r;
            do {
                c = a->margin + (int)(rng() % (unsigned)(g->width - 2 * a->margin));
                r = a->margin + (int)(rng() % (unsigned)(g->height - 2 * a->margin));
            } while (!isfinite(g->z[(size_t)r * g->width + c]));
            cand[k] = r * g->width + c;
        }
#pragma omp parallel for schedule(dynamic, 1)
        for (int k = 0; k < batch; ++k) {
            int idx = n_cells + k;
            double *h = ref_h + (size_t)idx * n_az;
            ref_svf(&rm, cand[k] % g->width, cand[k] / g->width, n_az, 0, ref_s + idx * 3, h);
            ok[k] = 1;
            for (int i = 0; i < n_az; ++i)
                ok[k] &= h[i] > -90;
        }
        int kept = n_cells;
        for (int k = 0; k < batch; ++k)
            if (ok[k]) {
                /* Compact: move row k's results to slot `kept`. */
                if (kept != n_cells + k) {
                    memcpy(ref_h + (size_t)kept * n_az, ref_h + (size_t)(n_cells + k) * n_az,
                           sizeof(double) * n_az);
                    memcpy(ref_s + kept * 3, ref_s + (n_cells + k) * 3, sizeof(double) * 3);
                }
                cells[kept++] = cand[k];
            }
        n_cells = kept;
        free(cand);
        free(ok);
        tries++;
    }
    fprintf(stderr, "%s: reference for %d cells x %d azimuths in %.1f s\n", a->scene, n_cells, n_az,
            now_s() - t0);
    /* What was measured: grid, cell size, sampled cells, reference azimuths. */
    char what[160];
    snprintf(what, sizeof what, "%d x %d cells of %.2f x %.2f m", g->width, g->height, g->cell_x_m,
             g->cell_y_m);
    double sampled[3] = {n_cells, n_az, NAN};
    row(a, "scene", what, 0, "sampled_cells_ref_azimuths", sampled, now_s() - t0, n_all);
    double *pairs = xmalloc(sizeof(double) * (size_t)n_cells * n_az);
    double *errs = xmalloc(sizeof(double) * n_cells);
    float *svf = xmalloc(sizeof(float) * (size_t)g->width * g->height);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 1;
    check(ss_svf(ctx, g, &opt, SS_SVF_DEF_GEOMETRIC, svf), "warm-up"); /* kernel build */
    static const char *def_names[3] = {"svf_geometric", "svf_horizontal", "svf_tilted"};
    for (int model = 0; model < 2; ++model) {
        const int *dirs = model ? a->digital_dirs : a->dirs;
        int n_dirs = model ? a->n_digital_dirs : a->n_dirs;
        const char *setting = model ? "lines=digital" : "lines=interpolated";
        /* SVFs at the sampled cells for every D, to measure the part of the
         * error directions control: against the largest D's own SVF. */
        float *kept = xmalloc(sizeof(float) * (size_t)n_dirs * 3 * n_cells);
        for (int di = 0; di < n_dirs; ++di) {
            int D = dirs[di];
            opt.directions = D;
            opt.lines = model ? SS_LINES_DIGITAL : SS_LINES_INTERPOLATED;
            sample_sink sink = {cells, n_cells, D, xmalloc(sizeof(float) * (size_t)n_cells * D)};
            double t_h, st[3];
            TIMED(a->reps, t_h, ss_horizon(ctx, g, &opt, 0, keep_samples, &sink), "horizon");
            /* At arbitrary azimuths: linear between the two nearest swept
             * directions, as horizon users (r.sun) interpolate. */
            size_t np = 0;
            for (int k = 0; k < n_cells; ++k)
                for (int i = 0; i < n_az; ++i) {
                    double p = (double)i * D / n_az;
                    int i0 = (int)floor(p);
                    double f = p - i0;
                    const float *hk = sink.out + (size_t)k * D;
                    double h = (1 - f) * hk[i0 % D] + f * hk[(i0 + 1) % D];
                    pairs[np++] = h - ref_h[(size_t)k * n_az + i];
                }
            stats(pairs, np, st);
            row(a, "directions", setting, D, "horizon_deg", st, t_h, n_all);
            /* At the swept azimuths themselves: the line model's own error. */
            np = 0;
            for (int i = 0; i < D; ++i) {
                double az = ss_direction_azimuth(&opt, i);
#pragma omp parallel for
                for (int k = 0; k < n_cells; ++k)
                    pairs[np + k] =
                        sink.out[(size_t)k * D + i] -
                        ref_horizon_deg(&rm, cells[k] % g->width, cells[k] / g->width, az, NULL);
                np += n_cells;
            }
            stats(pairs, np, st);
            row(a, "directions", setting, D, "horizon_at_swept_deg", st, t_h, n_all);
            free(sink.out);
            for (int def = 0; def < 3; ++def) {
                double t_s;
                TIMED(a->reps, t_s, ss_svf(ctx, g, &opt, (ss_svf_definition)def, svf), "svf");
                for (int k = 0; k < n_cells; ++k) {
                    errs[k] = svf[cells[k]] - ref_s[k * 3 + def];
                    kept[((size_t)di * 3 + def) * n_cells + k] = svf[cells[k]];
                }
                stats(errs, n_cells, st);
                row(a, "directions", setting, D, def_names[def], st, t_s, n_all);
            }
        }
        for (int di = 0; n_dirs > 1 && di < n_dirs - 1; ++di)
            for (int def = 0; def < 3; ++def) {
                double st[3];
                char q[64];
                for (int k = 0; k < n_cells; ++k)
                    errs[k] = kept[((size_t)di * 3 + def) * n_cells + k] -
                              kept[((size_t)(n_dirs - 1) * 3 + def) * n_cells + k];
                stats(errs, n_cells, st);
                snprintf(q, sizeof q, "%s_vs_D%d", def_names[def], dirs[n_dirs - 1]);
                row(a, "directions", setting, dirs[di], q, st, NAN, n_all);
            }
        free(kept);
    }
    free(cells);
    free(ref_h);
    free(ref_s);
    free(pairs);
    free(errs);
    free(svf);
    ref_march_free(&rm);
    close_scene(&s);
}

/* ---- insolation: time step and shadow mode ------------------------------ */

typedef struct {
    scene *s;
    const ss_sweep_options *opt;
    double start_s, step_s;
    int per_cell;
    ss_sun_field field;
    int have_field;
} sun_state;

static ss_status sun_step(ss_ctx *c, int k, ss_sun_step *step, void *user)
{
    sun_state *su = user;
    if (su->have_field)
        ss_sun_field_free(&su->field);
    su->have_field = 0;
    ss_spa_params p;
    ss_spa_params_default(&p);
    double mid = su->start_s + (k + 0.5) * su->step_s;
    ss_status st =
        ss_sun_field_compute(c, &su->s->dem, &su->s->frame, mid, &p, su->per_cell, &su->field);
    if (st != SS_OK)
        return st;
    su->have_field = 1;
    const ss_sun_field *f = &su->field;
    memset(step, 0, sizeof *step);
    step->duration_h = su->step_s / 3600.0;
    step->linke = 3.0;
    double r = f->centre.earth_sun_distance_au;
    step->extraterrestrial_w_m2 = 1367.0 / (r * r);
    step->grid_azimuth_deg = f->centre_grid_azimuth_deg;
    step->azimuth_deg = f->centre_grid_azimuth_deg + su->opt->grid_north_deg;
    step->elevation_deg = f->centre.elevation_deg;
    step->apparent_elevation_deg = f->centre.apparent_elevation_deg;
    step->spread_deg = f->spread_deg;
    step->grid_azimuth_per_cell = f->grid_azimuth_deg;
    step->elevation_per_cell = f->elevation_deg;
    step->apparent_per_cell = f->apparent_elevation_deg;
    return SS_OK;
}

typedef struct {
    float *global, *beam, *diffuse, *reflected, *sun_hours;
    double seconds;
} day_result;

/* One day from local midnight (date, utc_offset_h) in steps of step_min. */
static void run_day(const args *a, scene *s, int directions, ss_shadow_mode mode, double step_min,
                    int per_cell, day_result *out)
{
    size_t n = (size_t)s->dem.grid.width * s->dem.grid.height;
    float **bands[5] = {&out->global, &out->beam, &out->diffuse, &out->reflected, &out->sun_hours};
    for (int b = 0; b < 5; ++b)
        *bands[b] = xmalloc(n * sizeof(float));
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = directions;
    opt.grid_north_deg = s->frame.grid_north_deg;
    int y, m, d;
    if (sscanf(a->date, "%d-%d-%d", &y, &m, &d) != 3)
        die("--date YYYY-MM-DD");
    sun_state su = {s,
                    &opt,
                    ss_unix_from_civil(y, m, d, 0, 0, 0) - a->utc_offset_h * 3600,
                    step_min * 60,
                    per_cell,
                    {0},
                    0};
    int n_steps = (int)lround(1440 / step_min);
    ss_insolation_options io = {.albedo = 0.2, .shadow_mode = mode, .first = 0, .stride = 1};
    ss_insolation_out o = {.global = out->global,
                           .beam = out->beam,
                           .diffuse = out->diffuse,
                           .reflected = out->reflected,
                           .sun_hours = out->sun_hours};
    double t = now_s();
    check(ss_insolation(ctx, &s->dem.grid, &opt, &io, n_steps, sun_step, &su, NULL, NULL, &o),
          "insolation");
    out->seconds = now_s() - t;
    if (su.have_field)
        ss_sun_field_free(&su.field);
}

static void free_day(day_result *r)
{
    free(r->global);
    free(r->beam);
    free(r->diffuse);
    free(r->reflected);
    free(r->sun_hours);
}

/* Per-cell |run - ref| / ref in percent (cells with ref > 0), and hours of
 * sun |run - ref|. */
static void day_errors(const args *a, const char *setting, double value, const scene *s,
                       const day_result *run, const day_result *ref)
{
    size_t n = (size_t)s->dem.grid.width * s->dem.grid.height, m = 0, mh = 0;
    double *e = xmalloc(n * sizeof(double)), *eh = xmalloc(n * sizeof(double)), st[3];
    double *eb = xmalloc(n * sizeof(double));
    size_t mb = 0;
    for (size_t c = 0; c < n; ++c) {
        if (!isfinite(s->dem.grid.z[c]))
            continue;
        if (ref->global[c] > 0)
            e[m++] = 100.0 * (run->global[c] - ref->global[c]) / ref->global[c];
        if (ref->beam[c] > 0)
            eb[mb++] = 100.0 * (run->beam[c] - ref->beam[c]) / ref->beam[c];
        eh[mh++] = run->sun_hours[c] - ref->sun_hours[c];
    }
    size_t cells = valid_cells(&s->dem.grid);
    stats(e, m, st);
    row(a, "insolation", setting, value, "global_pct", st, run->seconds, cells);
    stats(eb, mb, st);
    row(a, "insolation", setting, value, "beam_pct", st, run->seconds, cells);
    stats(eh, mh, st);
    row(a, "insolation", setting, value, "sun_hours_h", st, run->seconds, cells);
    free(e);
    free(eb);
    free(eh);
}

static void study_insolation(const args *a)
{
    scene s;
    open_scene(a, &s);
    day_result ref;
    double st0[3] = {0, 0, 0};
    run_day(a, &s, a->insol_dirs, SS_SHADOW_EXACT, a->ref_step_min, 1, &ref);
    row(a, "insolation", "reference exact", a->ref_step_min, "global_pct", st0, ref.seconds,
        valid_cells(&s.dem.grid));
    for (int i = 0; i < a->n_steps; ++i) {
        day_result r;
        run_day(a, &s, a->insol_dirs, SS_SHADOW_EXACT, a->steps_min[i], 1, &r);
        day_errors(a, "step_min shadow=exact", a->steps_min[i], &s, &r, &ref);
        free_day(&r);
    }
    /* Interpolated shadows at the middle step, against the same reference:
     * the stored directions also carry the sky view, whose own change with
     * D is far smaller (radiative SVF converges fast, physics.md 6.2). */
    int mid_step = a->n_steps > 1 ? a->steps_min[a->n_steps / 2] : a->steps_min[0];
    for (int i = 0; i < a->n_interp_dirs; ++i) {
        day_result r;
        run_day(a, &s, a->interp_dirs[i], SS_SHADOW_INTERPOLATED, mid_step, 1, &r);
        char setting[64];
        snprintf(setting, sizeof setting, "shadow=interpolated step_min=%d", mid_step);
        day_errors(a, setting, a->interp_dirs[i], &s, &r, &ref);
        free_day(&r);
    }
    free_day(&ref);
    close_scene(&s);
}

/* ---- effects: each physical effect off against on ----------------------- */

typedef struct {
    float *angle; /* directions x cells */
    size_t n;
} all_sink;

static int keep_all(int index, double az, const float *angle, const float *dist,
                    const float *cast, void *user)
{
    (void)cast;
    (void)az;
    (void)dist;
    all_sink *s = user;
    memcpy(s->angle + (size_t)index * s->n, angle, s->n * sizeof(float));
    return 1;
}

static double horizons(const ss_grid *g, const ss_sweep_options *opt, float *out)
{
    all_sink sink = {out, (size_t)g->width * g->height};
    double t = now_s();
    check(ss_horizon(ctx, g, opt, 0, keep_all, &sink), "horizon");
    return now_s() - t;
}

/* Cells at least `margin` cells inside the grid: at the edge a horizon may
 * mix a sample with nothing ahead (-90) into its weights, and such a value
 * says nothing about an effect. */
static int inside(const ss_grid *g, size_t c, int margin)
{
    int col = (int)(c % g->width), r = (int)(c / g->width);
    return col >= margin && r >= margin && col < g->width - margin && r < g->height - margin;
}

/* |a - b| over valid cells inside the margin, every direction. */
static void horizon_diff(const args *a, const char *effect, const ss_grid *g, const float *on,
                         const float *off, int directions, double seconds)
{
    size_t n = (size_t)g->width * g->height, m = 0;
    double *e = xmalloc(n * directions * sizeof(double)), st[3];
    for (size_t i = 0; i < n * directions; ++i)
        if (isfinite(g->z[i % n]) && inside(g, i % n, a->margin) && on[i] > -90 && off[i] > -90)
            e[m++] = on[i] - off[i];
    stats(e, m, st);
    row(a, "effects", effect, directions, "horizon_deg", st, seconds, valid_cells(g));
    free(e);
}

static void flips(const args *a, const char *effect, const ss_grid *g, const float *x,
                  const float *y, double seconds)
{
    size_t n = (size_t)g->width * g->height, valid = 0, differ = 0;
    for (size_t c = 0; c < n; ++c)
        if (isfinite(g->z[c])) {
            valid++;
            differ += x[c] != y[c];
        }
    double st[3] = {100.0 * differ / (valid ? valid : 1), NAN, NAN};
    row(a, "effects", effect, 1, "shadow_flips_pct", st, seconds, valid);
}

/* The first minute of the date at which the sun at the centre stands at
 * least `elev` degrees high (a low morning sun, where shadows are long). */
static double low_sun_time(const args *a, scene *s, double elev)
{
    int y, m, d;
    if (sscanf(a->date, "%d-%d-%d", &y, &m, &d) != 3)
        die("--date YYYY-MM-DD");
    double t0 = ss_unix_from_civil(y, m, d, 0, 0, 0) - a->utc_offset_h * 3600;
    ss_spa_params p;
    ss_spa_params_default(&p);
    for (int k = 0; k < 1440; ++k) {
        ss_spa_result r;
        check(ss_spa(ctx, t0 + 60.0 * k, s->frame.centre_lat_deg, s->frame.centre_lon_deg, &p, &r),
              "spa");
        if (r.apparent_elevation_deg >= elev)
            return t0 + 60.0 * k;
    }
    return t0 + 43200;
}

static void study_effects(const args *a)
{
    scene s;
    open_scene(a, &s);
    const ss_grid *g = &s.dem.grid;
    size_t n = (size_t)g->width * g->height;
    int D = a->dirs[0];
    float *on = xmalloc(n * D * sizeof(float)), *off = xmalloc(n * D * sizeof(float));
    ss_sweep_options base;
    ss_sweep_options_default(&base);
    base.directions = D;
    float *warm = xmalloc(n * sizeof(float));
    ss_sweep_options w = base;
    w.directions = 1;
    check(ss_svf(ctx, g, &w, SS_SVF_DEF_GEOMETRIC, warm), "warm-up");
    fprintf(stderr, "%s: grid north %.4f deg, earth radius %.0f m, centre %.4f %.4f\n", a->scene,
            s.frame.grid_north_deg, s.frame.earth_radius_m, s.frame.centre_lat_deg,
            s.frame.centre_lon_deg);

    /* Earth curvature (with k = 0.13) on against off, and refraction
     * (curvature on, k = 0.13 against k = 0). */
    ss_sweep_options curved = base, airless = base;
    curved.earth_radius_m = airless.earth_radius_m = s.frame.earth_radius_m;
    curved.refraction_k = 0.13;
    double t_on = horizons(g, &curved, on), t_off = horizons(g, &base, off);
    horizon_diff(a, "curvature", g, on, off, D, t_on);
    double st[3];
    {
        float *s1 = xmalloc(n * sizeof(float)), *s2 = xmalloc(n * sizeof(float));
        double t = now_s();
        check(ss_svf(ctx, g, &curved, SS_SVF_DEF_GEOMETRIC, s1), "svf");
        double t1 = now_s() - t;
        check(ss_svf(ctx, g, &base, SS_SVF_DEF_GEOMETRIC, s2), "svf");
        double *e = xmalloc(n * sizeof(double));
        size_t m = 0;
        for (size_t c = 0; c < n; ++c)
            if (isfinite(g->z[c]) && inside(g, c, a->margin))
                e[m++] = s1[c] - s2[c];
        stats(e, m, st);
        row(a, "effects", "curvature", D, "svf_geometric", st, t1, valid_cells(g));
        free(e);
        free(s1);
        free(s2);
    }
    (void)t_off;
    double t_air = horizons(g, &airless, off);
    horizon_diff(a, "refraction", g, on, off, D, t_air);

    /* True north, on the continuous reference at sampled cells: turning
     * the sweep's lines by a fraction of a degree would move its samples
     * across the lines and measure the line model's own noise, not the
     * effect. Ignoring the convergence gamma reads the horizon of true
     * azimuth phi at grid azimuth phi instead of phi - gamma; a low sun (5
     * degrees) then lights a cell on the wrong side of its horizon. */
    double gamma = s.frame.grid_north_deg;
    ref_march rm;
    ref_march_init(&rm, g, 0, 0);
    int n_cells = a->cells, n_az = 360;
    int *cells = xmalloc(sizeof(int) * n_cells);
    for (int k = 0; k < n_cells; ++k) {
        int c, r;
        do {
            c = a->margin + (int)(rng() % (unsigned)(g->width - 2 * a->margin));
            r = a->margin + (int)(rng() % (unsigned)(g->height - 2 * a->margin));
        } while (!isfinite(g->z[(size_t)r * g->width + c]));
        cells[k] = r * g->width + c;
    }
    double *dh = xmalloc(sizeof(double) * n_cells * n_az);
    int *flip = xmalloc(sizeof(int) * n_cells);
    double t = now_s();
#pragma omp parallel for schedule(dynamic, 1)
    for (int k = 0; k < n_cells; ++k) {
        int c = cells[k] % g->width, r = cells[k] / g->width;
        flip[k] = 0;
        for (int i = 0; i < n_az; ++i) {
            double phi = 360.0 * i / n_az;
            double right = ref_horizon_deg(&rm, c, r, phi - gamma, NULL);
            double wrong = ref_horizon_deg(&rm, c, r, phi, NULL);
            dh[(size_t)k * n_az + i] = right > -90 && wrong > -90 ? right - wrong : 0;
            flip[k] += (5.0 > right) != (5.0 > wrong);
        }
    }
    double t_ref = now_s() - t;
    stats(dh, (size_t)n_cells * n_az, st);
    row(a, "effects", "north", n_az, "horizon_deg", st, t_ref, valid_cells(g));
    size_t flips_n = 0;
    for (int k = 0; k < n_cells; ++k)
        flips_n += flip[k];
    double fl[3] = {100.0 * flips_n / ((double)n_cells * n_az), NAN, NAN};
    row(a, "effects", "north", n_az, "shadow_flips_pct", fl, t_ref, valid_cells(g));
    double conv[3] = {fabs(gamma), NAN, NAN};
    row(a, "effects", "north", 0, "convergence_deg", conv, 0, valid_cells(g));
    free(dh);
    free(flip);
    free(cells);
    ref_march_free(&rm);

    /* Per-cell sun against one sun: shadows of a low (5 degree) sun, same
     * lines in both runs. */
    double when = low_sun_time(a, &s, 5.0);
    ss_spa_params p;
    ss_spa_params_default(&p);
    ss_sun_field field;
    check(ss_sun_field_compute(ctx, &s.dem, &s.frame, when, &p, 1, &field), "sun field");
    float *lit1 = xmalloc(n * sizeof(float)), *lit2 = xmalloc(n * sizeof(float));
    ss_sweep_options truen = base;
    truen.grid_north_deg = gamma;
    double az_true = field.centre_grid_azimuth_deg + gamma;
    double el = field.centre.apparent_elevation_deg;
    t = now_s();
    check(ss_cast_shadow(ctx, g, &truen, az_true, el, field.apparent_elevation_deg, lit1, NULL),
          "shadow");
    double t1 = now_s() - t;
    check(ss_cast_shadow(ctx, g, &truen, az_true, el, NULL, lit2, NULL), "shadow");
    flips(a, "sun_per_cell", g, lit1, lit2, t1);
    double spread[3] = {field.spread_deg, NAN, NAN};
    row(a, "effects", "sun_per_cell", 0, "sun_spread_deg", spread, 0, valid_cells(g));
    ss_sun_field_free(&field);

    /* A day's irradiation with per-cell sun against one sun. */
    day_result per, one;
    run_day(a, &s, 16, SS_SHADOW_EXACT, 15, 1, &per);
    run_day(a, &s, 16, SS_SHADOW_EXACT, 15, 0, &one);
    double *e = xmalloc(n * sizeof(double));
    size_t m = 0;
    for (size_t c = 0; c < n; ++c)
        if (isfinite(g->z[c]) && per.global[c] > 0)
            e[m++] = 100.0 * (one.global[c] - per.global[c]) / per.global[c];
    stats(e, m, st);
    row(a, "effects", "sun_per_cell", 1, "global_pct", st, per.seconds, valid_cells(g));
    double none[3] = {NAN, NAN, NAN};
    row(a, "effects", "sun_per_cell=off", 1, "seconds_only", none, one.seconds, valid_cells(g));
    free(e);
    free_day(&per);
    free_day(&one);
    free(lit1);
    free(lit2);
    free(on);
    free(off);
    free(warm);
    close_scene(&s);
}

/* ---- cost: wall time of each product on the whole grid ------------------- */

static int drop_all(int index, double az, const float *angle, const float *dist,
                    const float *cast, void *user)
{
    (void)cast;
    (void)index;
    (void)az;
    (void)angle;
    (void)dist;
    (void)user;
    return 1;
}

static void study_cost(const args *a)
{
    scene s;
    open_scene(a, &s);
    const ss_grid *g = &s.dem.grid;
    size_t n = (size_t)g->width * g->height, cells = valid_cells(g);
    float *out = xmalloc(n * sizeof(float));
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 1;
    check(ss_svf(ctx, g, &opt, SS_SVF_DEF_GEOMETRIC, out), "warm-up");
    double none[3] = {NAN, NAN, NAN};
    static const char *names[3] = {"svf_geometric", "svf_horizontal", "svf_tilted"};
    for (int i = 0; i < a->n_dirs; ++i) {
        opt.directions = a->dirs[i];
        for (int model = 0; model < 2; ++model) {
            opt.lines = model ? SS_LINES_DIGITAL : SS_LINES_INTERPOLATED;
            const char *setting = model ? "lines=digital" : "lines=interpolated";
            double t;
            TIMED(a->reps, t, ss_horizon(ctx, g, &opt, 0, drop_all, NULL), "horizon");
            row(a, "cost", setting, opt.directions, "horizon_deg", none, t, cells);
            for (int def = 0; def < 3; ++def) {
                TIMED(a->reps, t, ss_svf(ctx, g, &opt, (ss_svf_definition)def, out), "svf");
                row(a, "cost", setting, opt.directions, names[def], none, t, cells);
            }
        }
    }
    free(out);
    close_scene(&s);
}

/* ---- command line ------------------------------------------------------- */

static void usage(void)
{
    fprintf(stderr,
            "usage: accuracy_driver directions|cost|insolation|effects|machine --scene NAME "
            "[--class C] (--dem FILE | --shape plane30|vvalley|bowl) [--crop WxH] [--cells N] "
            "[--ref-az N] [--margin N] [--dirs LIST] [--digital-dirs LIST] [--steps LIST] "
            "[--ref-step MIN] [--interp-dirs LIST] [--insol-dirs N] [--date YYYY-MM-DD] "
            "[--utc-offset H] [--reps N] [--device NAME]\n");
    exit(2);
}

int main(int argc, char **argv)
{
    if (argc < 2)
        usage();
    args a = {0};
    a.mode = argv[1];
    a.scene = "scene";
    a.klass = "-";
    a.cells = 300;
    a.ref_az = 3600;
    a.margin = 8;
    a.n_dirs = parse_list("4,8,16,32,64,128,256,360", a.dirs);
    a.n_digital_dirs = parse_list("8,32,128,360", a.digital_dirs);
    a.n_steps = parse_list("60,30,15,5", a.steps_min);
    a.n_interp_dirs = parse_list("16,32,64,128,360", a.interp_dirs);
    a.ref_step_min = 1;
    a.insol_dirs = 32;
    a.date = "2026-12-21";
    for (int i = 2; i < argc; ++i) {
        const char *k = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v)
            usage();
        if (!strcmp(k, "--scene"))
            a.scene = v;
        else if (!strcmp(k, "--class"))
            a.klass = v;
        else if (!strcmp(k, "--dem"))
            a.dem_path = v;
        else if (!strcmp(k, "--shape"))
            a.shape = v;
        else if (!strcmp(k, "--crop"))
            sscanf(v, "%dx%d", &a.crop_w, &a.crop_h);
        else if (!strcmp(k, "--cells"))
            a.cells = atoi(v);
        else if (!strcmp(k, "--ref-az"))
            a.ref_az = atoi(v);
        else if (!strcmp(k, "--margin"))
            a.margin = atoi(v);
        else if (!strcmp(k, "--dirs"))
            a.n_dirs = parse_list(v, a.dirs);
        else if (!strcmp(k, "--digital-dirs"))
            a.n_digital_dirs = parse_list(v, a.digital_dirs);
        else if (!strcmp(k, "--steps"))
            a.n_steps = parse_list(v, a.steps_min);
        else if (!strcmp(k, "--interp-dirs"))
            a.n_interp_dirs = parse_list(v, a.interp_dirs);
        else if (!strcmp(k, "--ref-step"))
            a.ref_step_min = atof(v);
        else if (!strcmp(k, "--insol-dirs"))
            a.insol_dirs = atoi(v);
        else if (!strcmp(k, "--date"))
            a.date = v;
        else if (!strcmp(k, "--utc-offset"))
            a.utc_offset_h = atof(v);
        else if (!strcmp(k, "--device"))
            a.device = v;
        else if (!strcmp(k, "--reps"))
            a.reps = atoi(v);
        else
            usage();
        i++;
    }
    ss_gdal_init();
    ctx = ss_ctx_new();
    check(ss_ctx_use_device(ctx, a.device), "device");
    if (!strcmp(a.mode, "machine")) {
        printf("%s\n", ss_ctx_device_name(ctx));
    } else if (!a.dem_path && !a.shape) {
        usage();
    } else if (!strcmp(a.mode, "directions")) {
        study_directions(&a);
    } else if (!strcmp(a.mode, "cost")) {
        study_cost(&a);
    } else if (!strcmp(a.mode, "insolation")) {
        study_insolation(&a);
    } else if (!strcmp(a.mode, "effects")) {
        study_effects(&a);
    } else {
        usage();
    }
    ss_ctx_free(ctx);
    return 0;
}
