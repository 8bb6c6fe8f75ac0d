/* The effects planner: for one scene (a grid, where it lies, the product,
 * the time steps and the accuracy asked for) decide which physical effects
 * and which costly steps the run needs, say why in the scene's own numbers,
 * and state the error that leaving each out allows. The run then obeys the
 * plan: what is planned off is not computed. */
#include "config.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy_table.h"
#include "box_lines_table.h"
#include "ctx_internal.h"
#include "lines.h"
#include "lit_levels.h"
#include "shadow_table.h"
#include "skysweep_sun.h"

#define DEG (180.0 / M_PI)

/* The cost model of the estimate and of --device auto (doc/devices.md):
 * whole-process times on the 2-core development machine (doc/devices.sh)
 * and, for GPUs, the lent H200 (doc/gpu.md). Set-up in seconds, sweep
 * throughput in cell-directions per second, and the host's per-cell cost
 * of an insolation step, the same on every device. */
#define COST_REF_RATE 8e7        /* the C twin, OpenMP on 2 cores: nothing to set up */
#define COST_CPU_CL_SETUP_S 0.10 /* PoCL: platform, context, cached kernels (and 80 MiB) */
#define COST_CPU_CL_RATE 8e7     /* PoCL: no faster than the C twin on the same cores */
#define COST_GPU_SETUP_S 0.25    /* opening the H200 */
/* Per sweep, measured when each direction was a launch of its own; the
 * batched launches since are unmeasured on a GPU, and cheaper. */
#define COST_GPU_LAUNCH_S 2e-3
#define COST_GPU_RATE 1.5e9      /* ... with the H200's 132 compute units (scaled by a GPU's own) */
#define COST_GPU_UNITS 132.0
#define COST_BOX_PER_LINE 1.8    /* a box sweep per line per cell, in sweeps (doc/box_lines.md) */
/* Box shadows by each cell's own ray (box_shadow.h), in sweeps: the
 * bounds' walk and the marches, 1.1 ms for one sun on Gothenburg's DSM on
 * one core against 1.1 ms for a digital shadow walk. */
#define COST_BOX_MARCH 1.0
/* The box model's sky view by each cell's own ray (box_sky.h), per
 * direction in sweeps: 0.069 s for 32 directions on Gothenburg's DSM on
 * two cores in AVX2's lanes (0.112 s one cell at a time, without AVX2),
 * where its 32 digital sweeps take 0.017 s. A ray walks on while blocks
 * ahead could rise above its best angle: on terrain, up every slope (9
 * sweeps a direction on Kilauea at 2048 x 2048, less than 8 box lines
 * there; --lines auto takes box lines only for walls). */
#define COST_BOX_SKY_MARCH 4.0
#define PLAN_CELL_STEP_S 2e-8
#define PLAN_MAX_CANDIDATES 8

static ss_plan_item *add(ss_plan *p, const char *key, int on, double bound, const char *unit,
                         const char *fmt, ...) __attribute__((format(printf, 6, 7)));
static ss_plan_item *add(ss_plan *p, const char *key, int on, double bound, const char *unit,
                         const char *fmt, ...)
{
    if (p->n_items >= SS_PLAN_MAX_ITEMS)
        return NULL;
    ss_plan_item *it = &p->items[p->n_items++];
    snprintf(it->key, sizeof it->key, "%s", key);
    it->on = on;
    it->bound = bound;
    snprintf(it->unit, sizeof it->unit, "%s", unit);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(it->reason, sizeof it->reason, fmt, ap);
    va_end(ap);
    return it;
}

static int uses_horizons(ss_plan_kind kind)
{
    return kind != SS_PLAN_NO_SWEEP;
}

static int uses_sun(ss_plan_kind kind)
{
    return kind == SS_PLAN_SHADOW || kind == SS_PLAN_INSOLATION;
}

/* The accuracy a product is judged by, as the horizon angle it allows: SVF
 * moves by at most the horizon's change in radians (d sin h / dh <= 1). */
static double horizon_tolerance_deg(const ss_plan_request *r)
{
    return r->kind == SS_PLAN_SKY_VIEW ? r->svf_tolerance * DEG : r->horizon_tolerance_deg;
}

static void plan_curvature(ss_plan *p, const ss_plan_request *r, const ss_place *place)
{
    if (!uses_horizons(r->kind)) {
        add(p, "curvature", 0, 0, "deg", "this product reads no horizons");
        return;
    }
    double k = r->refraction_k;
    double lowering = (1.0 - k) * place->diagonal_m / (2.0 * place->earth_radius_m) * DEG;
    double tol = horizon_tolerance_deg(r);
    int on = r->curvature == SS_AUTO ? lowering > tol : r->curvature == SS_ON;
    const char *why = r->curvature == SS_AUTO ? (on ? "above" : "within") : "requested, tolerance";
    add(p, "curvature", on, on ? 0 : lowering, "deg",
        "horizons reach at most %.3g km across the DEM, where the earth's curvature with "
        "refraction k = %.2f lowers them by %.3g deg: %s the %.3g deg tolerance",
        place->diagonal_m / 1000, k, lowering, why, tol);
}

static void plan_north(ss_plan *p, const ss_plan_request *r, const ss_place *place)
{
    double tol = r->horizon_tolerance_deg;
    if (!place->georeferenced) {
        add(p, "true_north", 0, 0, "deg", "no CRS: azimuths are from the grid's north");
        return;
    }
    double off = fabs(place->grid_north_deg);
    double spread = fmax(fabs(place->grid_north_max_deg - place->grid_north_deg),
                         fabs(place->grid_north_min_deg - place->grid_north_deg));
    int on = r->true_north == SS_AUTO ? off > tol : r->true_north == SS_ON;
    if (on)
        add(p, "true_north", 1, spread, "deg",
            "grid north is %.4f deg from true north at the centre; azimuths are turned by it, "
            "and across the DEM it varies by %.4f deg more",
            place->grid_north_deg, spread);
    else
        add(p, "true_north", 0, off + spread, "deg",
            "grid north is %.4f deg from true north at the centre (%.4f deg at most over the "
            "DEM): %s the %.3g deg tolerance",
            place->grid_north_deg, off + spread,
            r->true_north == SS_AUTO ? "within" : "requested off,", tol);
}

/* Walls: neighbouring cells whose heights step by at least a storey
 * (SS_WALL_STEP_M) and more than SS_WALL_TAN cell sizes (79 deg). Measured
 * on the DEMs of ../shared/data (doc/model.md): at most 0.02 % of the pairs
 * on terrain, 1 m lidar ground included, and 4.4 % on Gothenburg's 1 m
 * DSM; above SS_WALL_SHARE a grid is a city of columns. */
#define SS_WALL_STEP_M 2.0
#define SS_WALL_TAN 5.0
#define SS_WALL_SHARE 0.005

/* Counts the pairs (a[i], b[i]) of valid heights and those that step like
 * a wall, steeper than `limit` metres. Without branches, so that the loop
 * vectorises: the plan of every sweeping product takes it over the DEM. */
static void count_steps(const float *a, const float *b, int n, double limit, size_t *pairs,
                        size_t *walls)
{
    size_t p = 0, w = 0;
#pragma omp simd reduction(+ : p, w)
    for (int i = 0; i < n; ++i) {
        double step = fabs((double)b[i] - (double)a[i]);
        int both = !!isfinite(a[i]) & !!isfinite(b[i]);
        p += (size_t)both;
        w += (size_t)(both & (step >= SS_WALL_STEP_M) & (step > limit));
    }
    *pairs += p;
    *walls += w;
}

static double wall_share(const ss_grid *g)
{
    size_t pairs = 0, walls = 0, width = (size_t)g->width;
    double across = SS_WALL_TAN * g->cell_x_m, down = SS_WALL_TAN * g->cell_y_m;
#pragma omp parallel for schedule(static) reduction(+ : pairs, walls)
    for (int r = 0; r < g->height; ++r) {
        const float *row = g->z + (size_t)r * width;
        count_steps(row, row + 1, g->width - 1, across, &pairs, &walls);
        if (r + 1 < g->height)
            count_steps(row, row + width, g->width, down, &pairs, &walls);
    }
    return pairs ? (double)walls / (double)pairs : 0.0;
}

/* The SVF error of tabulated count i: the worst 95th percentile over the
 * rows, the larger of its own and the next larger count's. */
static double box_lines_error(int i)
{
    double error = 0;
    for (int r = 0; r < ss_box_lines_n_rows; ++r)
        for (int j = i; j <= i + 1 && j < SS_BOX_LINES_N_COUNTS; ++j)
            error = fmax(error, ss_box_lines_rows[r].p95[j]);
    return error;
}

int ss_box_lines_for_tolerance(double svf_tolerance, double *expected_error)
{
    int chosen = 0;
    while (chosen + 1 < SS_BOX_LINES_N_COUNTS && box_lines_error(chosen) > svf_tolerance)
        chosen++;
    if (expected_error)
        *expected_error = box_lines_error(chosen);
    return ss_box_lines_counts[chosen];
}

/* The SVF error of `count` box lines from the table; 0 where it has none. */
static double box_lines_count_error(int count)
{
    for (int i = 0; i < SS_BOX_LINES_N_COUNTS; ++i)
        if (ss_box_lines_counts[i] == count)
            return box_lines_error(i);
    return 0;
}

/* Box lines per cell: as requested; for the sky view the fewest whose
 * measured SVF error meets --svf-tolerance (doc/box_lines.md); else the
 * default, as no table measures horizon angles' or shadows' error by the
 * count. Insolation keeps the default too: with --box-sky lines its
 * sky view, horizons and shadows share the one count; with --box-sky march
 * they are each cell's own ray, and the count serves the exact shadows of
 * --box-shadows lines and a canopy's sky view (plan_sky_box_lines gives
 * the sky view its own where the shadows take none). Writes what the lines item says of it to `said`,
 * and returns the SVF error expected (0: none measured). */
static double plan_box_lines(ss_plan *p, const ss_plan_request *r, char *said, size_t size)
{
    /* A product whose only horizons are its sky walk's, by each cell's own ray. */
    if (r->sky_walk && (r->kind == SS_PLAN_SKY_VIEW || r->kind == SS_PLAN_HORIZONS) &&
        r->box_sky == SS_BOX_SKY_MARCH && !(r->radius_m > 0)) {
        p->box_lines = r->box_lines > 0 ? r->box_lines : SS_BOX_LINES_DEFAULT;
        snprintf(said, size,
                 "none for the sky view and horizons: each cell's own ray, the box model exactly "
                 "(--box-sky march, doc/box_lines.md)");
        return 0;
    }
    if (r->box_lines > 0) {
        p->box_lines = r->box_lines;
        double error = r->kind == SS_PLAN_SKY_VIEW ? box_lines_count_error(r->box_lines) : 0;
        if (error > 0)
            snprintf(said, size,
                     "%d per cell, as requested (SVF error %.2g, 95th percentile on city DSMs, "
                     "doc/box_lines.md)",
                     r->box_lines, error);
        else
            snprintf(said, size, "%d per cell, as requested", r->box_lines);
        return error;
    }
    /* Insolation's sky view, horizons and stored horizons by each cell's own
     * ray, and its exact shadows too unless --box-shadows lines. */
    int insolation_rays = r->kind == SS_PLAN_INSOLATION && r->box_sky == SS_BOX_SKY_MARCH;
    if (insolation_rays && r->box_shadows == SS_BOX_SHADOWS_MARCH) {
        p->box_lines = SS_BOX_LINES_DEFAULT;
        snprintf(said, size,
                 "%d per cell, the default, for a canopy's sky view: the sky view, horizons "
                 "and shadows are each cell's own ray",
                 p->box_lines);
        return 0;
    }
    if (r->kind != SS_PLAN_SKY_VIEW) {
        p->box_lines = SS_BOX_LINES_DEFAULT;
        snprintf(said, size,
                 "%d per cell, the default: no table measures the error of %s by the count",
                 p->box_lines,
                 insolation_rays ? "exact shadows taken from the lines (--box-shadows lines)"
                 : r->kind == SS_PLAN_INSOLATION ? "insolation's shadows (which share its lines)"
                 : r->kind == SS_PLAN_SHADOW     ? "shadows taken from the lines"
                                                 : "horizon angles");
        return 0;
    }
    double error;
    p->box_lines = ss_box_lines_for_tolerance(r->svf_tolerance, &error);
    if (error <= r->svf_tolerance)
        snprintf(said, size,
                 "%d per cell, the fewest whose SVF error (95th percentile on city DSMs, "
                 "doc/box_lines.md) is within the %.3g tolerance",
                 p->box_lines, r->svf_tolerance);
    else
        snprintf(said, size,
                 "%d per cell, the most: no count brings the SVF error (95th percentile on "
                 "city DSMs, doc/box_lines.md) within the %.3g tolerance",
                 p->box_lines, r->svf_tolerance);
    return error;
}

/* Lines: as requested; otherwise box lines where the grid has walls (a
 * city DSM), interpolated lines on terrain. */
static void plan_lines(ss_plan *p, const ss_plan_request *r, const ss_grid *grid)
{
    char per_cell[200];
    double error = plan_box_lines(p, r, per_cell, sizeof per_cell);
    if (!uses_horizons(r->kind)) {
        p->lines = r->lines == SS_LINES_AUTO ? SS_LINES_INTERPOLATED : r->lines;
        return;
    }
    if (r->lines != SS_LINES_AUTO) {
        p->lines = r->lines;
        if (r->lines == SS_LINES_BOX)
            add(p, "lines", 1, error, "SVF", "box lines asked for: %s", per_cell);
        else
            add(p, "lines", 1, 0, "", "%s lines, as requested", ss_line_model_name(r->lines));
        return;
    }
    if (r->radius_m > 0) {
        p->lines = SS_LINES_INTERPOLATED;
        add(p, "lines", 1, 0, "",
            "interpolated lines: radius-limited horizons do not take box lines (doc/model.md)");
        return;
    }
    if (!grid->z) {
        p->lines = SS_LINES_INTERPOLATED;
        add(p, "lines", 1, 0, "",
            "interpolated lines: the DEM is read in bands and was not searched for walls "
            "(--lines box for a city DSM)");
        return;
    }
    double share = wall_share(grid);
    if (share > SS_WALL_SHARE && !ss_box_lines_take_cells(grid->cell_x_m, grid->cell_y_m)) {
        /* A wall share measured on such cells mostly says how long they are. */
        p->lines = SS_LINES_INTERPOLATED;
        add(p, "lines", 1, 0, "",
            "interpolated lines: %.2f %% of neighbouring cells step like walls, but box lines "
            "need cells at most twice as long as wide, and these are %.4g x %.4g m",
            100 * share, grid->cell_x_m, grid->cell_y_m);
        return;
    }
    p->lines = share > SS_WALL_SHARE ? SS_LINES_BOX : SS_LINES_INTERPOLATED;
    if (p->lines == SS_LINES_BOX)
        add(p, "lines", 1, error, "SVF",
            "box lines: %.2f %% of neighbouring cells step by %.0f m or more, steeper than "
            "%.0f deg: walls, so cells are taken as flat-topped columns (doc/model.md); %s",
            100 * share, SS_WALL_STEP_M, atan(SS_WALL_TAN) * DEG, per_cell);
    else
        add(p, "lines", 1, 0, "",
            "interpolated lines: %.3f %% of neighbouring cells step like walls (%.0f m or more, "
            "steeper than %.0f deg), under %.1f %%: terrain",
            100 * share, SS_WALL_STEP_M, atan(SS_WALL_TAN) * DEG, 100 * SS_WALL_SHARE);
}

/* Directions: as requested; for an SVF (and insolation's sky) the fewest
 * whose measured error meets --svf-tolerance (doc/accuracy.md); else 32. */
static void plan_directions(ss_plan *p, const ss_plan_request *r)
{
    int sky = r->kind == SS_PLAN_SKY_VIEW || r->kind == SS_PLAN_INSOLATION;
    if (r->directions) {
        p->directions = r->directions;
        if (sky || r->kind == SS_PLAN_HORIZONS)
            add(p, "directions", 1, 0, "", "%d directions, as requested", p->directions);
        return;
    }
    p->directions = 32;
    if (!sky || p->lines != SS_LINES_INTERPOLATED) {
        if (sky || r->kind == SS_PLAN_HORIZONS)
            add(p, "directions", 1, 0, "",
                "%d directions: the default (the accuracy table is measured on interpolated "
                "lines, doc/accuracy.md)",
                p->directions);
        return;
    }
    ss_svf_definition def =
        r->kind == SS_PLAN_INSOLATION ? SS_SVF_DEF_RADIATIVE : r->svf_definition;
    double error;
    int d = ss_directions_for_tolerance(def, r->svf_tolerance, &error);
    if (d <= 0)
        return;
    p->directions = d;
    if (error <= r->svf_tolerance)
        add(p, "directions", 1, error, "SVF",
            "%d directions: the fewest whose SVF error (95th percentile on mountain DEMs, "
            "doc/accuracy.md) is within the %.3g tolerance",
            d, r->svf_tolerance);
    else
        add(p, "directions", 1, error, "SVF",
            "%d directions: no number of directions brings the SVF error within %.3g on "
            "mountain DEMs (it is set by the line sampling near steep ground, doc/accuracy.md); "
            "the cheapest near the floor",
            d, r->svf_tolerance);
}

static void plan_cells(ss_plan *p, const ss_plan_request *r, const ss_place *place)
{
    /* A relative distance error e tilts a horizon h by (e/2) sin 2h <= e/2 rad. */
    double bound = 0.5 * place->cell_variation * DEG;
    if (!place->georeferenced)
        add(p, "cell_sizes", 0, 0, "deg", "no CRS: the given cell size is used");
    else
        add(p, "cell_sizes", 1, bound, "deg",
            "%s cell sizes at the DEM's centre; they vary by %.2g over the DEM, which tilts "
            "horizons by at most %.3g deg%s",
            place->geographic ? "geodesic" : "ground (projected / scale factor)",
            place->cell_variation, bound,
            bound > r->horizon_tolerance_deg ? " (above the tolerance: reproject the DEM to a "
                                               "local projection, or cut it into smaller parts)"
                                             : "");
}

/* Records in a run that the shadow table covers: a month of hours. It was
 * measured on the sums of days spread over a year (doc/shadow_modes.md);
 * a shorter run's sums are a shorter span, whose error the table does not
 * bound. */
#define SHADOW_TABLE_MIN_RECORDS 720

static const char *const shadow_names[] = {"exact", "interpolated", "cumulative"};

/* The scene kind of the shadow table a line model was measured on; -1:
 * none (digital lines). */
static int shadow_scene(ss_line_model lines)
{
    return lines == SS_LINES_BOX            ? SS_SHADOW_SCENE_CITY
           : lines == SS_LINES_INTERPOLATED ? SS_SHADOW_SCENE_TERRAIN
                                            : -1;
}

/* Why the shadow table does not cover a run (NULL: it does). */
static const char *shadow_table_gap(const ss_plan *p, const ss_plan_request *r)
{
    const ss_plan_weather *w = &r->weather;
    if (!w->what)
        return "the clear sky's steps are swept each (the table of modes is measured on weather "
               "records)";
    if (w->per_step)
        return "the per-step bands need each record on each cell, exactly";
    if (r->n_steps < SHADOW_TABLE_MIN_RECORDS)
        return "fewer than 720 records: the table of modes is measured on sums over a year";
    if (shadow_scene(p->lines) < 0)
        return "the table of modes is measured on box and interpolated lines, not digital";
    return NULL;
}

/* A sweep's cost in interpolated sweeps: a box sweep walks box_lines
 * lines per cell (the sky view's sky_box_lines where set). */
static double box_sweep_cost(const ss_plan *p)
{
    int lines = p->sky_box_lines > 0 ? p->sky_box_lines : p->box_lines;
    return p->lines == SS_LINES_BOX ? COST_BOX_PER_LINE * lines : 1.0;
}

/* Whether the product's sky walk is each cell's own ray (box_sky.h), as
 * ss_box_sky_marched decides it: box lines with --box-sky march and no
 * radius. */
static int sky_marched(const ss_plan *p, const ss_plan_request *r)
{
    return r->sky_walk && p->lines == SS_LINES_BOX && r->box_sky == SS_BOX_SKY_MARCH &&
           !(r->radius_m > 0);
}

/* Insolation's exact shadows on box lines by each cell's own ray (on
 * every device and band height) take nothing from its box lines; the sky
 * view then gets its own count, chosen from the SVF table as svf's is, and
 * the shadows keep the default. */
static void plan_sky_box_lines(ss_plan *p, const ss_plan_request *r)
{
    p->sky_box_lines = 0;
    if (r->kind != SS_PLAN_INSOLATION || p->lines != SS_LINES_BOX || r->box_lines > 0 ||
        p->shadow_mode != SS_SHADOW_EXACT || r->box_shadows != SS_BOX_SHADOWS_MARCH)
        return;
    double error;
    int sky = ss_box_lines_for_tolerance(r->svf_tolerance, &error);
    if (sky >= p->box_lines)
        return;
    p->sky_box_lines = sky;
    for (int i = 0; i < p->n_items; ++i)
        if (strcmp(p->items[i].key, "lines") == 0) {
            size_t used = strlen(p->items[i].reason);
            /* Marched, the count serves a canopy's sky view alone, which the
             * request does not know of: its error is said, not bound. */
            if (sky_marched(p, r))
                snprintf(p->items[i].reason + used, sizeof p->items[i].reason - used,
                         "; with exact shadows a canopy's sky view takes %d, the fewest within "
                         "the %.3g SVF tolerance (error %.2g)",
                         sky, r->svf_tolerance, error);
            else {
                snprintf(p->items[i].reason + used, sizeof p->items[i].reason - used,
                         "; the sky view takes %d, the fewest within the %.3g SVF tolerance", sky,
                         r->svf_tolerance);
                p->items[i].bound = error;
            }
        }
}

/* Whether cast shadows on box lines are each cell's own ray: asked for,
 * which runs (on the host, whatever the device and the bands). */
static int shadows_marched(const ss_plan *p, const ss_plan_request *r)
{
    return p->lines == SS_LINES_BOX && r->box_shadows == SS_BOX_SHADOWS_MARCH;
}

/* A cast shadow's, in sweeps: by each cell's own ray where marched, else
 * the lines' walks. */
static double shadow_sweep_cost(const ss_plan *p, const ss_plan_request *r)
{
    return shadows_marched(p, r) ? COST_BOX_MARCH : box_sweep_cost(p);
}

/* A direction of the sky view's or the stored horizons' walk, in sweeps:
 * by each cell's own ray where marched, else the lines' walks. */
static double sky_sweep_cost(const ss_plan *p, const ss_plan_request *r)
{
    return sky_marched(p, r) ? COST_BOX_SKY_MARCH : box_sweep_cost(p);
}

/* The modelled seconds per cell of a year's shadows in a mode with
 * `directions` (the sky's too), on the C twin: the sweeps (box sweeps
 * walking box_lines lines per cell, or each cell's own ray) and the
 * per-cell work per record, or,
 * for the cumulative sky, per bin of suns, at most directions x 90 (the
 * default 1 degree bins). Daylight records are taken as half the records
 * (a year's share; the plan's own count comes after the choice). */
static double shadow_seconds(const ss_plan *p, const ss_plan_request *r, ss_shadow_mode mode,
                             int directions, int n_steps)
{
    double daylight = 0.5 * n_steps;
    double sweeps = directions * sky_sweep_cost(p, r) +
                    (mode == SS_SHADOW_EXACT ? daylight * shadow_sweep_cost(p, r)
                                             : directions * sky_sweep_cost(p, r));
    double steps = mode == SS_SHADOW_CUMULATIVE ? fmin(daylight, 90.0 * directions) : daylight;
    return sweeps / COST_REF_RATE + steps * PLAN_CELL_STEP_S;
}

/* Insolation's shadow mode with --shadow auto: of the modes the table
 * covers, the cheapest in modelled time (shadow_seconds) whose expected
 * error (shadow_table.h) is within --insolation-tolerance, never with fewer
 * directions than the sky was planned with (or exactly those asked for);
 * at equal time the cumulative sky, whose bins are fewer than the bound
 * the model takes. Exact shadows where none is cheaper or none meets the
 * tolerance. Sets the plan's mode and directions, and *error to the error
 * expected. */
static void choose_shadows(ss_plan *p, const ss_plan_request *r, double *error)
{
    *error = 0;
    p->shadow_mode = r->shadow_mode;
    if (r->kind != SS_PLAN_INSOLATION || r->shadow_mode != SS_SHADOW_AUTO)
        return;
    p->shadow_mode = SS_SHADOW_EXACT;
    if (shadow_table_gap(p, r) || !(r->weather.tolerance_pct > 0)) /* 0: none allowed */
        return;
    double best = shadow_seconds(p, r, SS_SHADOW_EXACT, p->directions, r->n_steps);
    int directions = p->directions;
    for (int i = 0; i < ss_shadow_mode_n_rows; ++i) {
        const ss_shadow_mode_row *row = &ss_shadow_mode_rows[i];
        int d = r->directions ? r->directions : row->directions;
        if ((int)row->scene != shadow_scene(p->lines) || d < p->directions)
            continue;
        double e = ss_shadow_expected_error(row->scene, row->mode, d, r->weather.pv);
        double seconds = shadow_seconds(p, r, row->mode, d, r->n_steps);
        int cheaper = seconds < best || (seconds == best && row->mode == SS_SHADOW_CUMULATIVE &&
                                         p->shadow_mode != SS_SHADOW_CUMULATIVE);
        if (e <= r->weather.tolerance_pct && cheaper) { /* NAN: not covered */
            best = seconds;
            p->shadow_mode = row->mode;
            directions = d;
            *error = e;
        }
    }
    if (directions != p->directions)
        for (int i = 0; i < p->n_items; ++i)
            if (strcmp(p->items[i].key, "directions") == 0)
                snprintf(p->items[i].reason, sizeof p->items[i].reason,
                         "%d directions: for the shadow mode chosen (shadow_mode), more than the "
                         "%d the sky was planned with",
                         directions, p->directions);
    p->directions = directions;
}

/* The plan's word on the shadow mode chosen, and the error it expects. */
static void plan_shadows(ss_plan *p, const ss_plan_request *r, double error)
{
    if (r->kind != SS_PLAN_INSOLATION)
        return;
    const ss_plan_weather *w = &r->weather;
    if (r->shadow_mode != SS_SHADOW_AUTO) {
        add(p, "shadow_mode", 1, 0, "", "%s shadows, as requested", shadow_names[r->shadow_mode]);
        return;
    }
    const char *gap = shadow_table_gap(p, r);
    const char *scene = p->lines == SS_LINES_BOX ? "a city DSM on box lines"
                                                 : "terrain on interpolated lines";
    const char *sums = w->pv ? "annual and monthly globals and PV yield"
                             : "annual and monthly globals";
    if (p->shadow_mode != SS_SHADOW_EXACT) {
        add(p, "shadow_mode", 1, error, "%",
            "%s at %d directions (the sky's too): the cheapest mode whose measured error "
            "on %s (p95 over cells of the %s, doc/shadow_modes.md) is within the %.3g %% "
            "tolerance; modelled on the C twin, exact shadows would take about %.2g s, this "
            "%.2g s",
            p->shadow_mode == SS_SHADOW_CUMULATIVE ? "the cumulative sky" : "interpolated shadows",
            p->directions, scene, sums, w->tolerance_pct,
            p->cells * shadow_seconds(p, r, SS_SHADOW_EXACT, p->directions, r->n_steps),
            p->cells * shadow_seconds(p, r, p->shadow_mode, p->directions, r->n_steps));
        return;
    }
    if (gap) {
        add(p, "shadow_mode", 1, 0, "", "exact shadows: %s", gap);
        return;
    }
    /* The best the table offers on this scene, to say how far it is. */
    double least = NAN;
    int at = 0;
    for (int i = 0; i < ss_shadow_mode_n_rows; ++i) {
        const ss_shadow_mode_row *row = &ss_shadow_mode_rows[i];
        int d = r->directions ? r->directions : row->directions;
        double e = (int)row->scene == shadow_scene(p->lines) && d >= p->directions
                       ? ss_shadow_expected_error(row->scene, row->mode, d, w->pv)
                       : NAN;
        if (e < least || (isnan(least) && !isnan(e))) {
            least = e;
            at = i;
        }
    }
    if (isnan(least))
        add(p, "shadow_mode", 1, 0, "",
            "exact shadows: no other mode is measured for %s at %d directions", scene,
            p->directions);
    else if (least > w->tolerance_pct)
        add(p, "shadow_mode", 1, 0, "",
            "exact shadows: the least error measured on %s (%s) is %s shadows' at %d "
            "directions, %.3g %% (p95, doc/shadow_modes.md): above the %.3g %% tolerance",
            scene, sums, shadow_names[ss_shadow_mode_rows[at].mode],
            r->directions ? r->directions : ss_shadow_mode_rows[at].directions, least,
            w->tolerance_pct);
    else
        add(p, "shadow_mode", 1, 0, "",
            "exact shadows: cheaper in modelled time than the modes whose measured error on %s "
            "is within the %.3g %% tolerance",
            scene, w->tolerance_pct);
}

static void plan_sun(ss_plan *p, const ss_plan_request *r, const ss_place *place)
{
    if (!uses_sun(r->kind) || !place->georeferenced) {
        add(p, "sun_per_cell", 0, 0, "deg",
            uses_sun(r->kind) ? "no CRS: the sun is given for the whole DEM"
                                 : "this product has no sun");
        return;
    }
    /* The local vertical turns by the central angle between two cells. */
    double spread = place->diagonal_m / (2.0 * place->earth_radius_m) * DEG;
    if (p->shadow_mode == SS_SHADOW_CUMULATIVE) {
        add(p, "sun_per_cell", 0, spread, "deg",
            "the cumulative sky bins the suns of the DEM's centre; they differ by up to %.4f deg "
            "from a corner's",
            spread);
        return;
    }
    int on = r->sun_per_cell == SS_AUTO ? spread > r->sun_tolerance_deg : r->sun_per_cell == SS_ON;
    p->sun_per_cell = on;
    add(p, "sun_per_cell", on, on ? 0 : spread, "deg",
        "the sun's direction differs by up to %.4f deg between the centre and a corner: %s the "
        "%.3g deg sun tolerance",
        spread, r->sun_per_cell != SS_AUTO ? "requested, tolerance" : on ? "above" : "within",
        r->sun_tolerance_deg);
}

/* Whether insolation's shadow walks will stop early (insolation.c,
 * lit_levels.h): exact shadows with interpolated or box lines, with walks
 * enough (whole or in bands, on every device). */
static int stops_shadow_walks(const ss_plan *p, const ss_plan_request *r)
{
    int walked = r->n_steps - p->steps_night - p->steps_high_sun;
    return r->kind == SS_PLAN_INSOLATION && p->shadow_mode == SS_SHADOW_EXACT &&
           ss_lit_levels_used(walked, p->lines);
}

/* Counts of the time steps that need no work, from SPA at the centre;
 * bound_deg is 90 where none is known, for the reason held_whole tells. */
static ss_status plan_steps(ss_ctx *ctx, ss_plan *p, const ss_plan_request *r,
                            const ss_place *place, double bound_deg, int held_whole,
                            double spread_deg)
{
    if (!uses_sun(r->kind) || r->n_steps == 0 || !place->georeferenced)
        return SS_OK;
    ss_spa_params sp;
    ss_spa_params_default(&sp);
    for (int k = 0; k < r->n_steps; ++k) {
        ss_spa_result s;
        ss_status st = ss_spa(ctx, r->step_unix_s[k], place->centre_lat_deg,
                              place->centre_lon_deg, &sp, &s);
        if (st != SS_OK)
            return st;
        if (s.elevation_deg + spread_deg <= 0.0)
            p->steps_night++;
        else if (s.apparent_elevation_deg - spread_deg > bound_deg)
            p->steps_high_sun++;
    }
    p->steps_total = r->n_steps;
    if (r->kind == SS_PLAN_INSOLATION)
        add(p, "night_steps", 1, 0, "",
            "%d of %d time steps have the sun below the horizontal at every cell: skipped "
            "exactly%s",
            p->steps_night, r->n_steps,
            r->weather.what ? ", unless their record holds light (then isotropic diffuse)" : "");
    if (p->shadow_mode == SS_SHADOW_CUMULATIVE)
        add(p, "shadow_sweeps", 1, 0, "",
            "cumulative sky: the %d daylight records' suns binned by the nearest of the %d "
            "directions and by elevation, one horizon sweep per direction instead of one per "
            "record",
            r->n_steps - p->steps_night, p->directions);
    else if (p->shadow_mode == SS_SHADOW_INTERPOLATED)
        add(p, "shadow_sweeps", 1, 0, "",
            "interpolated shadows: horizons stored at the %d directions in one sweep each and "
            "interpolated to each of the %d daylight records' suns, no sweep per record",
            p->directions, r->n_steps - p->steps_night);
    else if (bound_deg >= 90.0)
        add(p, "shadow_sweeps", 1, 0, "",
            "%s, so no bound on its horizons is known: every one of the %d daylight steps "
            "gets its shadow sweep%s%s",
            held_whole ? "its box lines may touch a column's face" : "the DEM is read in bands",
            r->n_steps - p->steps_night,
            r->weather.what ? ", but records with neither beam nor circumsolar light" : "",
            stops_shadow_walks(p, r) && (held_whole || ctx->use_reference)
                ? "; their walks stop past the last cell of each line "
                  "whose own proven horizon bound the sun may not clear"
                : "");
    else
        add(p, "shadow_sweeps", 1, 0, "",
            "%d of %d daylight steps have the sun above %.2f deg, the highest horizon this "
            "terrain can cast (proven bound): no shadow sweep for them%s%s",
            p->steps_high_sun, r->n_steps - p->steps_night, bound_deg,
            r->weather.what ? ", nor for records with neither beam nor circumsolar light" : "",
            stops_shadow_walks(p, r) ? "; the others' walks stop past the last cell of each "
                                       "line whose own proven horizon bound the sun may not "
                                       "clear (the cost below counts whole walks, for "
                                       "every record)"
                                     : "");
    return SS_OK;
}

typedef enum { DEVICE_REF, DEVICE_CPU_CL, DEVICE_GPU } device_kind;

/* Seconds a device takes for the sweeps: set-up, launches, throughput (a
 * GPU's scaled by its compute units against the H200's, never above it). */
static double device_seconds(device_kind kind, double sweeps, double cells, int compute_units)
{
    double work = sweeps * cells;
    switch (kind) {
    case DEVICE_REF:
        return work / COST_REF_RATE;
    case DEVICE_CPU_CL:
        return COST_CPU_CL_SETUP_S + work / COST_CPU_CL_RATE;
    case DEVICE_GPU:
        break;
    }
    double share = compute_units > 0 ? fmin(1.0, compute_units / COST_GPU_UNITS) : 1.0;
    return COST_GPU_SETUP_S + sweeps * COST_GPU_LAUNCH_S + work / (COST_GPU_RATE * share);
}

/* A test hook (doc/scale.md): SKYSWEEP_TEST_AUTO_DEVICE=P:D makes
 * --device auto pick that OpenCL device whatever the cost model says, so
 * that a machine without a GPU (PoCL is never faster than the C twin)
 * tests the run that auto hands to a device; NULL: none. */
static const char *auto_device_forced(void)
{
    const char *spec = getenv("SKYSWEEP_TEST_AUTO_DEVICE");
    return spec && spec[0] ? spec : NULL;
}

/* --device auto: the device the cost model finds fastest for this job. The
 * OpenCL platforms are only looked at when a device of some kind could beat
 * the C twin: loading them costs 20-30 ms and 60 MiB. */
static void plan_device(ss_plan *p, double sweeps, double host_s)
{
    const char *forced = auto_device_forced();
    double ref_s = device_seconds(DEVICE_REF, sweeps, p->cells, 0);
    double cpu_cl_s = device_seconds(DEVICE_CPU_CL, sweeps, p->cells, 0);
    double gpu_s = device_seconds(DEVICE_GPU, sweeps, p->cells, 0);
    snprintf(p->device, sizeof p->device, "reference");
    p->estimated_seconds = host_s + ref_s;
    if (ref_s <= fmin(cpu_cl_s, gpu_s) && !forced) {
        add(p, "device", 1, 0, "",
            "the C twin (host, OpenMP): its sweeps take about %.2g s, where PoCL would take "
            "%.2g s and a GPU %.2g s with their set-up, so none was looked for",
            ref_s, cpu_cl_s, gpu_s);
        return;
    }
    ss_device_candidate found[PLAN_MAX_CANDIDATES];
    int n = ss_opencl_devices(found, PLAN_MAX_CANDIDATES);
    double best_s = ref_s;
    int best = -1;
    char others[300] = "";
    size_t used = 0;
    for (int i = 0; i < n; ++i) {
        double s = device_seconds(found[i].is_cpu ? DEVICE_CPU_CL : DEVICE_GPU, sweeps, p->cells,
                                  found[i].compute_units);
        if (used < sizeof others)
            used += (size_t)snprintf(others + used, sizeof others - used, "%s%.60s (%s) %.2g s",
                                     used ? ", " : "", found[i].name, found[i].spec, s);
        if (forced ? strcmp(found[i].spec, forced) == 0 : s < best_s) {
            best_s = s;
            best = i;
        }
    }
    p->estimated_seconds = host_s + best_s;
    if (best >= 0) {
        snprintf(p->device, sizeof p->device, "%s", found[best].spec);
        add(p, "device", 1, 0, "",
            "%.100s (%s): its sweeps take about %.2g s with its set-up, against the C twin's "
            "%.2g s (OpenCL devices: %s)",
            found[best].name, found[best].spec, best_s, ref_s, others);
    } else if (n) {
        add(p, "device", 1, 0, "",
            "the C twin (host, OpenMP): its sweeps take about %.2g s, against %s with set-up",
            ref_s, others);
    } else {
        add(p, "device", 1, 0, "",
            "the C twin (host, OpenMP): its sweeps take about %.2g s; no OpenCL device was found",
            ref_s);
    }
}

ss_status ss_plan_make(ss_ctx *ctx, const ss_grid *grid, const ss_place *place,
                       const ss_plan_request *r, ss_plan *p)
{
    ss_call_begin(ctx);
    memset(p, 0, sizeof *p);
    if (!(r->horizon_tolerance_deg > 0) || !(r->svf_tolerance > 0) ||
        !(r->sun_tolerance_deg > 0) || r->directions < 0 || r->n_steps < 0)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "tolerances must be positive (horizon %g deg, SVF %g, sun %g deg)",
                       r->horizon_tolerance_deg, r->svf_tolerance, r->sun_tolerance_deg);
    if (r->lines < SS_LINES_AUTO || r->lines > SS_LINES_BOX)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown line model %d", (int)r->lines);
    if (r->shadow_mode < SS_SHADOW_AUTO || r->shadow_mode > SS_SHADOW_CUMULATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown shadow mode %d", (int)r->shadow_mode);
    if (!(place->earth_radius_m > 0) || !(place->diagonal_m >= 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "the place of the DEM is not known");
    p->cells = (double)grid->width * grid->height;

    plan_curvature(p, r, place);
    plan_north(p, r, place);
    plan_cells(p, r, place);
    p->curvature = p->items[0].on;
    p->true_north = p->items[1].on;

    plan_lines(p, r, grid);
    plan_directions(p, r);
    double shadow_error;
    choose_shadows(p, r, &shadow_error);
    plan_sky_box_lines(p, r);
    plan_sun(p, r, place);

    double spread = p->sun_per_cell ? 0.0 : place->diagonal_m / (2 * place->earth_radius_m) * DEG;
    double bound = uses_sun(r->kind) ? ss_horizon_bound_deg(grid, p->lines, p->box_lines) : 90.0;
    plan_shadows(p, r, shadow_error);
    ss_status st = plan_steps(ctx, p, r, place, bound, grid->z != NULL, spread);
    if (st != SS_OK)
        return st;
    if (r->kind == SS_PLAN_INSOLATION)
        add(p, "diffuse_reflected", 1, 0, "",
            "insolation needs the sky each cell sees: one radiative SVF sweep over %d "
            "directions for the diffuse and reflected terms",
            p->directions);
    const ss_plan_weather *w = &r->weather;
    if (r->kind == SS_PLAN_INSOLATION && w->what) {
        if (isnan(w->distance_km))
            add(p, "weather", 1, 0, "", "real sky from %s, which names no site", w->what);
        else
            add(p, "weather", 1, 0, "", "real sky from %s, whose site lies %.1f km from the DEM's "
                "centre%s", w->what, w->distance_km,
                w->distance_km > SS_WEATHER_NEAR_KM
                    ? ": farther than 100 km (--weather-far-ok), its weather may not be the DEM's"
                    : "");
    }
    /* Perez's band comes from the sweep that stores the horizons, where
     * shadows take stored horizons. */
    int band_sweep = w->what && w->horizon_band && p->shadow_mode == SS_SHADOW_EXACT;
    if (r->kind == SS_PLAN_INSOLATION && w->what && w->horizon_band)
        add(p, "horizon_band", 1, 0, "",
            band_sweep ? "Perez's sky: one more sweep over %d directions for the share of its "
                         "horizon band each cell sees"
                       : "Perez's sky: the share of its horizon band each cell sees, from the "
                         "sweep over %d directions that stores the horizons",
            p->directions);

    /* Work: sweeps of all cells (the sky's, and the cast shadows'), then
     * per-cell arithmetic for each step. */
    double sky = 0, shadows = 0;
    int daylight = p->steps_total - p->steps_night;
    switch (r->kind) {
    case SS_PLAN_HORIZONS:
    case SS_PLAN_SKY_VIEW:
        sky = p->directions;
        break;
    case SS_PLAN_SHADOW:
        shadows = 1;
        break;
    case SS_PLAN_NO_SWEEP:
        break;
    case SS_PLAN_INSOLATION:
        sky = p->directions + (band_sweep ? p->directions : 0);
        if (p->shadow_mode == SS_SHADOW_EXACT)
            shadows = daylight - p->steps_high_sun;
        else
            sky += p->directions;
        break;
    }
    p->sweeps = (int)(sky + shadows);
    /* The march runs on the host (at the C twin's rate) whatever device
     * walks the rest. */
    int marched = shadows_marched(p, r);
    /* The sky's and the horizons' directions, where they are each cell's
     * own ray (horizon_walk.c: the sky view, Perez's band and the stored
     * horizons alike). */
    double sky_rays = sky_marched(p, r) ? sky : 0.0;
    double sweeps = (sky - sky_rays) * box_sweep_cost(p) +
                    (marched ? 0.0 : shadows * box_sweep_cost(p));
    double host_s = daylight * p->cells * PLAN_CELL_STEP_S +
                    (marched ? shadows * COST_BOX_MARCH * p->cells / COST_REF_RATE : 0.0) +
                    sky_rays * COST_BOX_SKY_MARCH * p->cells / COST_REF_RATE;
    if (ctx->device_auto) {
        plan_device(p, sweeps, host_s);
    } else {
        device_kind kind = ctx->use_reference ? DEVICE_REF : DEVICE_CPU_CL;
        snprintf(p->device, sizeof p->device, "%s", ctx->use_reference ? "reference" : "opencl");
        p->estimated_seconds = host_s + device_seconds(kind, sweeps, p->cells, 0);
    }
    return SS_OK;
}

size_t ss_plan_format(const ss_plan *p, int json, char *buf, size_t size)
{
    size_t used = 0;
#define PUT(...)                                                                               \
    do {                                                                                       \
        int n_ = snprintf(buf + (used < size ? used : size), used < size ? size - used : 0,   \
                          __VA_ARGS__);                                                        \
        used += n_ > 0 ? (size_t)n_ : 0;                                                       \
    } while (0)
    if (json) {
        PUT("{\"directions\": %d, \"sweeps\": %d, \"estimated_seconds\": %.3g, "
            "\"device\": \"%s\", \"steps\": %d, \"night_steps\": %d, \"high_sun_steps\": %d, "
            "\"effects\": [",
            p->directions, p->sweeps, p->estimated_seconds, p->device, p->steps_total,
            p->steps_night, p->steps_high_sun);
        for (int i = 0; i < p->n_items; ++i) {
            const ss_plan_item *it = &p->items[i];
            PUT("%s{\"effect\": \"%s\", \"on\": %s, \"bound\": %.6g, \"unit\": \"%s\", "
                "\"reason\": \"",
                i ? ", " : "", it->key, it->on ? "true" : "false", it->bound, it->unit);
            for (const char *c = it->reason; *c; ++c)
                PUT(*c == '"' || *c == '\\' ? "\\%c" : "%c", *c);
            PUT("\"}");
        }
        PUT("]}\n");
    } else {
        for (int i = 0; i < p->n_items; ++i) {
            const ss_plan_item *it = &p->items[i];
            PUT("%-18s %-3s %s", it->key, it->on ? "ON" : "OFF", it->reason);
            if (it->bound > 0)
                PUT(" [error allowed: %.3g %s]", it->bound, it->unit);
            PUT("\n");
        }
        PUT("%-18s     %d sweeps of %.3g Mcells, about %.2g s on %s\n", "cost", p->sweeps,
            p->cells / 1e6, p->estimated_seconds,
            strcmp(p->device, "reference") == 0 ? "the C twin (modelled on 2 cores)"
            : strcmp(p->device, "opencl") == 0  ? "OpenCL (modelled as PoCL on 2 cores)"
                                                : "the OpenCL device chosen (modelled as the H200)");
    }
#undef PUT
    return used;
}

void ss_plan_sweep_options(const ss_plan *plan, const ss_place *place, double refraction_k,
                           ss_sweep_options *opt)
{
    opt->directions = plan->directions;
    opt->lines = plan->lines;
    opt->box_lines = plan->box_lines;
    opt->sky_box_lines = plan->sky_box_lines;
    opt->earth_radius_m = plan->curvature ? place->earth_radius_m : 0.0;
    opt->refraction_k = plan->curvature ? refraction_k : 0.0;
    opt->grid_north_deg = plan->true_north ? place->grid_north_deg : 0.0;
}
