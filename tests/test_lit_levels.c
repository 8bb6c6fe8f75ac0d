/* The per-cell horizon bounds of each azimuth sector (src/core/
 * lit_levels.c) against the walks they bound: on terrains made to break
 * them (spikes far and near, cliffs, plateaus of ties, nodata holes, cells
 * longer one way, grids of one row or column up, city blocks of walls, one
 * tower seen in 720 azimuths, a shield island in a nodata sea) and on the Gothenburg DSM
 * and the Kilauea DEM where ../shared/data has them, every horizon the
 * library's interpolated and box walks (few and many families) give a
 * cell, in up to 240 azimuths (the axes and diagonals, and others a
 * hundredth of a degree off them) with and without curvature, lies below
 * its level's angle in the sector of the walk's azimuth. Digital lines have no per-cell bound. A bound that failed would light a shaded cell. Then the walks
 * that stop past the last cell a sun may not clear (ss_walk.lit_levels),
 * and give no horizon to the cells the bounds know lit: every cell is lit
 * or shaded as by the whole walk, and the cells the bounds leave open
 * keep the whole walk's horizon to the bit. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lines.h"
#include "lit_levels.h"
#include "products_internal.h"
#include "shared_dem.h"
#include "tap.h"
#include "testlib.h"

typedef struct {
    const unsigned char *levels;
    size_t cells;
    long checked, above;
    double worst_deg; /* the highest horizon minus its cell's level angle */
} check_state;

/* The bounds of the sector holding a walk's azimuth. */
static const unsigned char *sector_levels(const unsigned char *levels, size_t cells,
                                          double azimuth_deg)
{
    return levels + (size_t)ss_lit_sector(azimuth_deg) * cells;
}

static int check_direction(int index, double azimuth_deg, const float *angle_deg,
                           const float *dist_m, const float *cast_height_m, void *user)
{
    (void)index;
    (void)dist_m;
    (void)cast_height_m;
    check_state *s = user;
    /* The options' grid north is 0: the azimuth is the grid's. */
    const unsigned char *levels = sector_levels(s->levels, s->cells, azimuth_deg);
    for (size_t c = 0; c < s->cells; ++c) {
        if (!isfinite(angle_deg[c]) || angle_deg[c] == SS_NODATA ||
            levels[c] == SS_LIT_UNBOUNDED)
            continue;
        double over = angle_deg[c] - ss_lit_level_deg(levels[c]);
        s->checked++;
        s->above += over >= 0.0;
        if (over > s->worst_deg)
            s->worst_deg = over;
    }
    return 1;
}

/* Lines to bound: interpolated (families 0) or box lines of `families`;
 * bounds made of the grid held whole (band_rows 0) or read in bands of
 * band_rows rows (ss_lit_bands_make); per sector, or one_bound: one for
 * every azimuth (ss_lit_sectors_for). */
typedef struct {
    int families, band_rows, one_bound;
} line_kind;

static const line_kind INTERPOLATED = {0, 0, 0};

static int sectors_of(line_kind k)
{
    return k.one_bound ? 1 : SS_LIT_SECTORS;
}

/* The levels of a grid read in bands, every row's (NULL: none made). */
static unsigned char *banded_levels(const ss_grid *g, line_kind k, ss_lit_bands **bands)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_source src = ss_source_of_grid(g);
    src.band_rows = k.band_rows;
    ss_lit_bands *lb = NULL;
    unsigned char *out = NULL;
    if (ss_lit_bands_make(ctx, &src, k.families, sectors_of(k), &lb) == SS_OK && lb &&
        (out = malloc(ss_lit_bands_bytes(lb, g->height))) &&
        ss_lit_bands_read(lb, 0, g->height, out) != SS_OK) {
        free(out);
        out = NULL;
    }
    if (bands)
        *bands = lb;
    else
        ss_lit_bands_free(lb);
    ss_ctx_free(ctx);
    return out;
}

static unsigned char *levels_for(const ss_grid *g, line_kind k)
{
    if (k.band_rows > 0)
        return banded_levels(g, k, NULL);
    return k.families ? ss_lit_levels_box(g->z, g->width, g->height, g->cell_x_m, g->cell_y_m,
                                          k.families, sectors_of(k))
                      : ss_lit_levels(g->z, g->width, g->height, g->cell_x_m, g->cell_y_m,
                                      sectors_of(k));
}

static void use_lines(ss_sweep_options *o, line_kind k)
{
    o->lines = k.families ? SS_LINES_BOX : SS_LINES_INTERPOLATED;
    if (k.families)
        o->box_lines = k.families;
}

static const char *lines_name(line_kind k)
{
    static char name[112];
    int n = k.families ? snprintf(name, sizeof name, "box lines x%d", k.families)
                       : snprintf(name, sizeof name, "interpolated lines");
    if (k.band_rows > 0)
        n += snprintf(name + n, sizeof name - (size_t)n, ", bounds in bands of %d rows",
                      k.band_rows);
    if (k.one_bound)
        snprintf(name + n, sizeof name - (size_t)n, ", one bound for every azimuth");
    return name;
}

/* Every horizon of g in `directions` azimuths from offset_deg, curvature
 * on (earth_radius_m > 0) or off, against the bounds. */
static void check_grid(const char *name, const ss_grid *g, int directions, double offset_deg,
                       double earth_radius_m, line_kind k)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    unsigned char *levels = levels_for(g, k);
    size_t cells = (size_t)g->width * g->height;
    ss_sweep_options o;
    ss_sweep_options_default(&o);
    o.directions = directions;
    o.offset_deg = offset_deg;
    use_lines(&o, k);
    o.earth_radius_m = earth_radius_m;
    o.refraction_k = 0.0;
    check_state s = {levels, cells, 0, 0, -INFINITY};
    ss_status st = levels ? ss_horizon(ctx, g, &o, 0, check_direction, &s) : SS_ERR_MEMORY;
    long bounded = 0;
    double level_sum = 0;
    for (size_t i = 0; levels && i < cells * SS_LIT_SECTORS; ++i)
        if (isfinite(g->z[i % cells]) && levels[i] != SS_LIT_UNBOUNDED) {
            bounded++;
            level_sum += ss_lit_level_deg(levels[i]);
        }
    tap_ok(st == SS_OK && s.above == 0,
           "%s, %s (%d x %d, %d directions from %g deg, curvature %s): status %d%s%s, %ld horizons of %ld at or above their "
           "cell's sector bound (want 0), the closest %.3f deg from it; %ld cell-sectors "
           "bounded, mean bound %.1f deg",
           name, lines_name(k), g->width, g->height, directions, offset_deg,
           earth_radius_m > 0 ? "on" : "off", (int)st,
           st == SS_OK ? "" : ": ", st == SS_OK ? "" : ss_ctx_message(ctx), s.above,
           s.checked, s.worst_deg, bounded, bounded ? level_sum / bounded : 0.0);
    free(levels);
    ss_ctx_free(ctx);
}

/* The rows of a whole-grid horizon walk, copied out. */
static ss_status keep_angles(void *user, int index, const ss_band_view *band,
                             const ss_dir_rows *rows, float *planes)
{
    (void)index, (void)planes;
    float *out = user;
    size_t n = (size_t)band->n_rows * band->width;
    for (size_t c = 0; c < n; ++c)
        out[(size_t)band->row0 * band->width + c] = rows->angle[c];
    return SS_OK;
}

/* The shadow walk of one azimuth on a device, whole or stopping early for
 * cells of levels above lit_level (levels and bands NULL: whole), over the
 * grid held whole or in bands of band_rows rows (bands: their bounds). */
static ss_status shadow_angles(const char *device, const ss_grid *g, const ss_sweep_options *o,
                               double azimuth_deg, const unsigned char *levels,
                               ss_lit_bands *bands, int band_rows, int lit_level, float *out)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    ss_source src = ss_source_of_grid(g);
    src.band_rows = band_rows;
    ss_engine_dir dir = {azimuth_deg, 1, 0, lit_level};
    ss_consumer consumer = {.planes = 0, .direction = keep_angles};
    ss_engine_job job = {.walk = {.term = SS_TERM_HORIZON,
                                  .none_deg = 0.0f,
                                  .lit_levels = levels,
                                  .lit_bands = bands},
                         .dirs = &dir,
                         .n_dirs = 1,
                         .consumer = &consumer,
                         .user = out,
                         .what = "shadow"};
    ss_status st = ss_rows_begin(ctx, &src, o, NULL);
    if (st == SS_OK)
        st = ss_engine_run(ctx, &src, o, &job);
    ss_ctx_free(ctx);
    return st;
}

/* Suns in 16 azimuths (off the axes) at 5 elevations, curvature on or off,
 * on a device ("reference", or the default OpenCL device). */
static void check_early_stops(const char *device, const char *name, const ss_grid *g,
                              double earth_radius_m, line_kind k)
{
    static const double elevations[] = {2.0, 8.0, 20.0, 40.0, 65.0};
    ss_lit_bands *bands = NULL;
    unsigned char *levels = k.band_rows > 0 ? banded_levels(g, k, &bands) : levels_for(g, k);
    size_t n = (size_t)g->width * g->height;
    float *whole = malloc(n * sizeof(float)), *early = malloc(n * sizeof(float));
    ss_sweep_options o;
    ss_sweep_options_default(&o);
    o.earth_radius_m = earth_radius_m;
    use_lines(&o, k);
    long verdicts = 0, flipped = 0, open = 0, changed = 0, known = 0, stopped = 0;
    long failed = !levels;
    for (int a = 0; a < 16 && !failed; ++a) {
        double az = 7.3 + 22.5 * a;
        failed |= shadow_angles(device, g, &o, az, NULL, NULL, 0, -1, whole) != SS_OK;
        const unsigned char *sector = levels ? sector_levels(levels, n, az) : NULL;
        for (size_t e = 0; e < sizeof elevations / sizeof *elevations && !failed; ++e) {
            int lit_level = ss_lit_level_below(elevations[e]);
            failed |= shadow_angles(device, g, &o, az, bands ? NULL : levels, bands,
                                    k.band_rows, lit_level, early) != SS_OK;
            for (size_t c = 0; c < n; ++c) {
                if (!isfinite(g->z[c]))
                    continue;
                verdicts++;
                flipped += (elevations[e] > whole[c]) != (elevations[e] > early[c]);
                if (sector[c] > lit_level) {
                    open++;
                    changed += memcmp(&whole[c], &early[c], sizeof(float)) != 0;
                } else {
                    known++;
                    /* a horizon the walk left short or gave none: it did stop */
                    stopped += memcmp(&whole[c], &early[c], sizeof(float)) != 0;
                }
            }
        }
    }
    tap_ok(!failed && flipped == 0 && changed == 0 && stopped > 0,
           "%s, %s on %s, curvature %s: walks stopped early light and shade %ld cell-suns as whole "
           "walks (%ld differ, want 0); %ld cells left open keep their horizons to the bit (%ld "
           "differ); %.0f %% of cell-suns known lit by their bounds, %ld of them with a horizon "
           "left short or none (want some)",
           name, lines_name(k), device, earth_radius_m > 0 ? "on" : "off", verdicts, flipped, open, changed,
           verdicts ? 100.0 * known / verdicts : 0.0, stopped);
    free(levels);
    ss_lit_bands_free(bands);
    free(whole);
    free(early);
}

/* The same on PoCL where there is one. */
static void check_early_stops_on_pocl(int have_pocl, const char *name, const ss_grid *g,
                                      double earth_radius_m, line_kind k)
{
    if (have_pocl)
        check_early_stops("Portable", name, g, earth_radius_m, k);
    else
        tap_skip("walks stopped early on PoCL", "no PoCL device");
}

/* A shield island: a broad dome with a summit caldera and a steep-sided
 * pit crater on its flank, rising from a sea of nodata. */
static ss_grid shield_island(void)
{
    ss_grid g = test_grid(180, 160, 30.0, 30.0);
    for (int y = 0; y < g.height; ++y)
        for (int x = 0; x < g.width; ++x) {
            double r = hypot(x - 90.0, y - 80.0), pit = hypot(x - 120.0, y - 60.0);
            double z = r < 70.0 ? 1250.0 * (1.0 - pow(r / 70.0, 1.6)) : NAN;
            if (r < 9.0)
                z -= 180.0; /* caldera floor */
            if (pit < 3.5)
                z -= 120.0; /* pit crater */
            g.z[(size_t)y * g.width + x] = (float)z;
        }
    return g;
}

/* A city of 1 m cells: blocks of houses and towers (walls of one cell's
 * step up to 60 m) on a plain with a few nodata courtyards, the bounds'
 * sectors facing toward or away from walls at every distance. */
static ss_grid city_blocks(void)
{
    ss_grid g = test_grid(160, 140, 1.0, 1.0);
    unsigned seed = 11;
    for (size_t c = 0; c < (size_t)160 * 140; ++c)
        g.z[c] = 2.0f;
    for (int b = 0; b < 40; ++b) {
        seed = seed * 1103515245u + 12345u;
        int x0 = (int)(seed >> 8) % 150, y0 = (int)(seed >> 16) % 130;
        int bw = 2 + (int)(seed >> 4) % 14, bh = 2 + (int)(seed >> 12) % 14;
        float top = 4.0f + (float)((seed >> 20) % 57);
        for (int y = y0; y < y0 + bh && y < 140; ++y)
            for (int x = x0; x < x0 + bw && x < 160; ++x)
                g.z[(size_t)y * 160 + x] = b % 13 == 12 ? NAN : top;
    }
    return g;
}

typedef struct {
    int directions;
    line_kind kind;
} shared_case;

/* Bounds against walks on a DEM of ../shared/data (shared_dem_run). */
static void check_dem(const char *name, const ss_grid *g, void *user)
{
    const shared_case *k = user;
    check_grid(name, g, k->directions, 0.0, 0.0, k->kind);
    check_grid(name, g, k->directions / 2, 0.01, 6371000.0, k->kind);
}

static void check_shared(const char *file, const char *name, int directions, line_kind k)
{
    shared_case c = {directions, k};
    shared_dem_run(file, name, check_dem, &c);
}

int main(void)
{
    static const struct {
        const char *name;
        terrain_kind kind;
        int width, height;
        double cell_x, cell_y, relief;
        int holes;
    } cases[] = {
        {"smooth hills", TERRAIN_SMOOTH, 120, 90, 30.0, 30.0, 400.0, 0},
        {"random heights (cliffs everywhere)", TERRAIN_NOISE, 70, 60, 10.0, 10.0, 30.0, 0},
        {"spikes on a plain", TERRAIN_SPIKES, 150, 130, 20.0, 20.0, 900.0, 0},
        {"plateaus of ties", TERRAIN_PLATEAUS, 90, 100, 5.0, 5.0, 40.0, 0},
        {"hills with nodata holes", TERRAIN_SMOOTH, 110, 80, 25.0, 25.0, 600.0, 6},
        {"spikes, cells 3 times longer north-south", TERRAIN_SPIKES, 100, 70, 10.0, 30.0, 500.0,
         3},
        {"noise, cells 4 times longer east-west", TERRAIN_NOISE, 40, 90, 40.0, 10.0, 50.0, 2},
        {"a long strip", TERRAIN_SMOOTH, 300, 9, 30.0, 30.0, 300.0, 0},
        {"one row", TERRAIN_NOISE, 50, 1, 10.0, 10.0, 20.0, 0},
        {"one column", TERRAIN_NOISE, 1, 50, 10.0, 10.0, 20.0, 0},
        {"gentle hills", TERRAIN_SMOOTH, 260, 200, 30.0, 30.0, 60.0, 4},
        {"three by two", TERRAIN_NOISE, 3, 2, 10.0, 10.0, 20.0, 0},
    };
    /* Box lines of 2 families put a centre a quarter cell beside its line,
     * of 32 (the default on city DSMs) a 64th. */
    static const line_kind box_few = {2, 0, 0}, box_many = {32, 0, 0};
    /* Bounds made band by band: bands shorter than a window's reach, so
     * that the far levels come from the pyramid held whole. */
    static const line_kind banded = {0, 17, 0}, banded_box = {32, 23, 0};
    /* One bound for every azimuth, whole and in bands. */
    static const line_kind one_bound = {0, 0, 1}, one_bound_box = {4, 0, 1},
                           one_bound_banded = {4, 19, 1};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        ss_grid g = test_grid(cases[i].width, cases[i].height, cases[i].cell_x, cases[i].cell_y);
        test_fill(&g, cases[i].kind, 17 + (unsigned)i, cases[i].relief);
        if (cases[i].holes)
            test_holes(&g, 5 + (unsigned)i, cases[i].holes, 8);
        /* Box lines take cells at most twice as long one way. */
        int box = ss_box_lines_take_cells(cases[i].cell_x, cases[i].cell_y);
        check_grid(cases[i].name, &g, 240, 0.37, 0.0, INTERPOLATED);
        if (box) {
            check_grid(cases[i].name, &g, 96, 0.0, 0.0, box_few);
            check_grid(cases[i].name, &g, 24, 0.01, 0.0, box_many);
        }
        if (i == 2 || i == 4 || i == 5 || i == 10) {
            check_grid(cases[i].name, &g, 96, 0.37, 0.0, banded);
            if (box)
                check_grid(cases[i].name, &g, 24, 0.01, 0.0, banded_box);
        }
        if (i < 3 || i == 10) {
            check_grid(cases[i].name, &g, 97, 1.9, 6371000.0, INTERPOLATED);
            check_grid(cases[i].name, &g, 24, 1.9, 6371000.0, box_many);
        }
        ss_grid_free(&g);
    }
    /* One tall spike far from a low plain: only the far rings see it, and
     * the bound must hold at every distance the rings cover. */
    ss_grid far = test_grid(400, 380, 30.0, 30.0);
    for (size_t c = 0; c < (size_t)400 * 380; ++c)
        far.z[c] = 0.0f;
    far.z[(size_t)371 * 400 + 393] = 3000.0f;
    far.z[(size_t)5 * 400 + 7] = 1500.0f;
    check_grid("two spikes far apart on a plain", &far, 240, 0.11, 0.0, INTERPOLATED);
    check_grid("two spikes far apart on a plain", &far, 96, 0.0, 0.0, box_few);
    check_grid("two spikes far apart on a plain", &far, 96, 0.11, 0.0, banded);
    check_grid("two spikes far apart on a plain", &far, 48, 0.0, 6371000.0, banded_box);
    check_grid("two spikes far apart on a plain", &far, 96, 0.11, 0.0, one_bound);
    check_grid("two spikes far apart on a plain", &far, 48, 0.0, 0.0, one_bound_banded);
    ss_grid_free(&far);
    ss_grid city = city_blocks();
    check_grid("city blocks", &city, 240, 0.0, 0.0, INTERPOLATED);
    check_grid("city blocks", &city, 97, 0.003, 6371000.0, INTERPOLATED);
    check_grid("city blocks", &city, 96, 0.0, 0.0, box_few);
    check_grid("city blocks", &city, 48, 0.01, 0.0, box_many);
    check_grid("city blocks", &city, 48, 0.01, 0.0, banded_box);
    ss_grid_free(&city);
    /* One tower on a plain, in 720 azimuths: every sector's edge. */
    ss_grid tower = test_grid(120, 100, 2.0, 2.0);
    for (size_t c = 0; c < (size_t)120 * 100; ++c)
        tower.z[c] = 0.0f;
    tower.z[(size_t)50 * 120 + 60] = 80.0f;
    check_grid("one tower on a plain", &tower, 720, 0.0, 0.0, INTERPOLATED);
    check_grid("one tower on a plain", &tower, 720, 0.0, 0.0, box_few);
    ss_grid_free(&tower);
    ss_grid island = shield_island();
    check_grid("a shield island", &island, 240, 0.0, 0.0, INTERPOLATED);
    check_grid("a shield island", &island, 240, 0.01, 6371000.0, INTERPOLATED);
    check_grid("a shield island", &island, 96, 0.0, 0.0, box_few);
    check_grid("a shield island", &island, 24, 0.01, 6371000.0, box_many);
    check_grid("a shield island", &island, 96, 0.0, 0.0, banded);
    check_grid("a shield island", &island, 24, 0.01, 6371000.0, banded_box);
    check_grid("a shield island", &island, 48, 0.0, 0.0, one_bound_box);
    ss_grid_free(&island);
    check_shared("goteborg_kronenhuset_dsm_1m.tif", "the Gothenburg 1 m DSM", 96, INTERPOLATED);
    check_shared("goteborg_kronenhuset_dsm_1m.tif", "the Gothenburg 1 m DSM", 24, box_many);
    check_shared("goteborg_kronenhuset_dsm_1m.tif", "the Gothenburg 1 m DSM", 64, box_few);
    check_shared("hawaii_kilauea_utm5n_30m.tif", "the Kilauea 30 m DEM", 16, INTERPOLATED);
    check_shared("hawaii_kilauea_utm5n_30m.tif", "the Kilauea 30 m DEM", 8, box_few);
    check_shared("goteborg_kronenhuset_dsm_1m.tif", "the Gothenburg 1 m DSM", 24, banded_box);
    check_shared("hawaii_kilauea_utm5n_30m.tif", "the Kilauea 30 m DEM", 16, banded);

    ss_grid hills = test_grid(150, 120, 30.0, 30.0);
    test_fill(&hills, TERRAIN_SMOOTH, 3, 150.0);
    test_holes(&hills, 9, 5, 7);
    int have_pocl = test_have_pocl();
    check_early_stops("reference", "hills with holes", &hills, 0.0, INTERPOLATED);
    check_early_stops("reference", "hills with holes", &hills, 6371000.0, INTERPOLATED);
    check_early_stops_on_pocl(have_pocl, "hills with holes", &hills, 6371000.0, INTERPOLATED);
    check_early_stops("reference", "hills with holes", &hills, 0.0, box_many);
    check_early_stops_on_pocl(have_pocl, "hills with holes", &hills, 0.0, box_many);
    check_early_stops("reference", "hills with holes", &hills, 6371000.0, banded);
    check_early_stops("reference", "hills with holes", &hills, 0.0, banded_box);
    ss_grid_free(&hills);
    ss_grid gentle = test_grid(130, 110, 10.0, 20.0);
    test_fill(&gentle, TERRAIN_SMOOTH, 8, 15.0);
    test_holes(&gentle, 4, 3, 6);
    check_early_stops("reference", "gentle hills, cells twice as long north-south", &gentle, 0.0,
                      INTERPOLATED);
    check_early_stops("reference", "gentle hills, cells twice as long north-south", &gentle, 0.0,
                      box_few);
    ss_grid_free(&gentle);
    ss_grid town = city_blocks();
    check_early_stops("reference", "city blocks", &town, 0.0, box_many);
    check_early_stops_on_pocl(have_pocl, "city blocks", &town, 0.0, box_many);
    check_early_stops("reference", "city blocks", &town, 0.0, banded_box);
    check_early_stops("reference", "city blocks", &town, 0.0, INTERPOLATED);
    ss_grid_free(&town);
    ss_grid spikes = test_grid(90, 110, 20.0, 20.0);
    test_fill(&spikes, TERRAIN_SPIKES, 8, 60.0);
    check_early_stops("reference", "spikes on a plain", &spikes, 0.0, INTERPOLATED);
    check_early_stops_on_pocl(have_pocl, "spikes on a plain", &spikes, 0.0, INTERPOLATED);
    check_early_stops("reference", "spikes on a plain", &spikes, 0.0, box_many);
    check_early_stops("reference", "spikes on a plain", &spikes, 0.0, banded);
    check_early_stops("reference", "spikes on a plain", &spikes, 0.0, one_bound_box);
    check_early_stops("reference", "spikes on a plain", &spikes, 0.0, one_bound_banded);
    ss_grid_free(&spikes);
    return tap_done();
}
