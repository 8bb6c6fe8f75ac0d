/* Trees in `skysweep insolation` (doc/vegetation.md, "insolation"): the
 * tree options with the leaf seasons, each step's season, the crowns' sky,
 * and what the outputs and the summary say of them. */
#ifndef SS_CLI_INSOLATION_TREES_H
#define SS_CLI_INSOLATION_TREES_H

#include <math.h>

#include "crown_light.h"
#include "trees.h"

typedef struct {
    tree_settings trees;
    double transmissivity_leaf_off;
    const char *leaf_on, *leaf_off; /* DAY of the year or MM-DD; NULL: UMEP's */
    int crown_lines;                /* index into "auto|digital" */
    crown_light_settings light;     /* insolation's own options (crown_light_options) */
} insolation_tree_settings;

#define INSOLATION_TREE_OPTIONS_MAX 5
/* The tree options (trees.h's, with --trunk-gaps) into trees_out, and the
 * seasons' into seasons_out, at `base` in the command's settings. */
void insolation_tree_options(size_t base, opt_spec trees_out[TREE_OPTIONS_MAX],
                             opt_spec seasons_out[INSOLATION_TREE_OPTIONS_MAX]);

/* Refuses tree or season options without --canopy and malformed leaf
 * dates: an exit code, or -1 when fine. */
int insolation_trees_usage(const opt_spec *const *tables, const void *settings,
                           const insolation_tree_settings *set);

/* Bytes a cell of the whole grid the trees hold (the memory planner's):
 * besides the sky's, the share of it hidden, a byte for the crowns
 * crossed; the crowns' horizon band (the share hidden and, while it is
 * swept, the surfaces' gradients and weights) stays within the sky's. */
#define INSOLATION_TREES_CELL_BYTES (TREES_SKY_CELL_BYTES + sizeof(float) + 1.0)
/* ... and Beer-Lambert's fractions of each step's beam, the mean light
 * through the sky and the horizon band the crowns hide, and those
 * means' two sums of doubles while they are swept. */
#define INSOLATION_BEER_LAMBERT_CELL_BYTES (3.0 * sizeof(float) + 2.0 * sizeof(double))
/* ... and more with the cumulative sky: a bit a cell for each (direction,
 * elevation) pair of its bins (insolation_cumulative.c's crossings), at
 * most every direction at every elevation step up to 90 degrees, and a
 * byte a cell for one pair's sweep. */
static inline double insolation_cumulative_crown_bytes(int directions, double elevation_step_deg)
{
    return directions * ceil(90.0 / elevation_step_deg) / 8.0 + 1.0;
}

/* A run's trees: the rasters, the sky they hide, each step's season and
 * the library's view of them. */
typedef struct {
    trees t;
    ss_grid ground;
    float *sky_hidden;
    unsigned char *leaf_off; /* per step */
    int leaf_off_steps;
    int on_day, off_day;     /* the season's days (0: given as MM-DD) */
    int south;               /* UMEP's days shifted by half a year */
    double sky_seconds;
    ss_insolation_trees lib;
} insolation_trees;

/* Reads the trees, sweeps the sky they hide and gives each of the n steps
 * (instants mid_s, UTC) its season by its local date at the DEM's centre. */
ss_status insolation_trees_open(sweep_job *job, const insolation_tree_settings *set,
                                const double *mid_s, int n, insolation_trees *it);
void insolation_trees_free(insolation_trees *it);
/* CANOPY, TRUNK, TRANSMISSIVITY (both seasons), SEASON, CROWN_LINES (under
 * the run's options opt) and CROWN_LIGHT. */
void insolation_trees_metadata(ss_raster_writer *w, const insolation_tree_settings *set,
                               const insolation_trees *it, const ss_sweep_options *opt);
/* The summary's trees lines (cumulative: the crowns were swept per sun
 * bin, not per step). */
void insolation_trees_print(const insolation_tree_settings *set, const insolation_trees *it,
                            const ss_sweep_options *opt, int n_steps, int shadows_forced,
                            int cumulative);

#endif
