/* Trees on the command line (doc/vegetation.md): the options that give a
 * canopy, declared once for every command that takes them (shadow, svf,
 * hillshade, horizon), and its reading onto the DEM's grid, its checks and its
 * metadata. */
#ifndef SS_CLI_TREES_H
#define SS_CLI_TREES_H

#include "commands.h"
#include "run.h"

typedef struct {
    const char *canopy, *trunk;
    double trunk_ratio, transmissivity;
    int canopy_heights; /* index into "above-ground|absolute" */
    int trunk_gaps;     /* index into "ignore|open": an ss_trunk_gaps (svf's) */
} tree_settings;

#define TREE_OPTIONS_MAX 8
/* The tree options into out, their values in a tree_settings at `base` in
 * the command's settings; `sky` adds the sky view's --trunk-gaps; `bands`
 * ends --canopy's help with the bands it adds. Returns out. */
const opt_spec *tree_options(size_t base, int sky, const char *bands,
                             opt_spec out[TREE_OPTIONS_MAX]);

/* Tree options without --canopy, and --trunk-ratio beside --trunk, are
 * refused rather than ignored: an exit code, or -1 when they are fine. */
int trees_options_alone(const char *command, const opt_spec *const *tables, const void *settings,
                        const tree_settings *set);

/* The trees of a run (--canopy), on the DEM's grid and held whole, with
 * the DSM's heights they stand on. */
typedef struct {
    ss_canopy canopy;
    float *height, *trunk, *z;
    int z_owned;         /* z read here: the DEM is swept in bands */
    int warped;          /* the canopy or the trunks were warped onto the DEM's grid */
    size_t below_ground; /* absolute tops below the DSM, taken as no tree */
} trees;

/* Bytes per cell svf's trees hold for the whole grid beside the sweep
 * (counted by the memory planner): the crown heights, the trunks, the DSM
 * read whole, band 1 kept, bands 2 and 3, and ss_canopy_sky's two sums of
 * doubles. */
#define TREES_SKY_CELL_BYTES (6.0 * sizeof(float) + 2.0 * sizeof(double))

/* ... and shadow's: the crown heights, the trunks, the DSM, the sunlit
 * band kept, the classes and fractions, and a byte a cell for the crowns
 * crossed. */
#define TREES_SHADOW_CELL_BYTES (6.0 * sizeof(float) + 1.0)

/* ... and hillshade's: the crown heights, the trunks, the DSM, and a byte
 * a cell for the crowns the light crosses. */
#define TREES_HILLSHADE_CELL_BYTES (3.0 * sizeof(float) + 1.0)

/* ... and horizon's: the crown heights, the trunks, the DSM, the crowns'
 * horizon of one direction and a band of canopy-horizon rows (at most the
 * grid). */
#define TREES_HORIZON_CELL_BYTES (5.0 * sizeof(float))

/* Reads --canopy and --trunk onto the DEM's grid and checks them. */
ss_status trees_open(sweep_job *job, const tree_settings *set, trees *t);
/* The same on a DEM held whole (z: its heights, which the trees keep
 * without owning), for runs without a sweep_job (site horizons). */
ss_status trees_read(ss_ctx *ctx, const ss_dem *dem, float *z, const tree_settings *set,
                     trees *t);
void trees_free(trees *t);
/* The DSM the crowns stand on: the DEM's grid with the heights held whole. */
ss_grid trees_ground(const sweep_job *job, const trees *t);
/* CANOPY, TRUNK and TRANSMISSIVITY. */
void trees_metadata(ss_raster_writer *w, const tree_settings *set, const trees *t);
/* How ss_canopy_crossed meets the crowns under opt, for summaries and
 * CROWN_LINES: "digital" (digital lines, or where digital says so), "box,
 * each cell's own ray" (box_shadows march) or "box lines". */
const char *trees_crown_lines(const ss_sweep_options *opt, int digital);
/* "canopy.tif (heights above ground), transmissivity 0.03": the summary's. */
void trees_describe(const tree_settings *set, const trees *t, char *buf, size_t size);

#endif
