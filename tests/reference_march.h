/* An independent continuous reference for horizons and sky-view factors
 * (DESIGN.md "Accuracy as a first-class output"): slow and simple on
 * purpose, and sharing no code with kernels/ or src/core, so that errors of
 * the sweep's discrete model show up against it.
 *
 * The terrain is the bilinear interpolation of the float grid between cell
 * centres (the continuous surface the DEM stands for). From a cell centre a
 * ray runs in the exact azimuth (the grid frame: 0 = up the columns) to the
 * edge of the grid (the hull of the cell centres); it is sampled every
 * step_cells of the smaller cell side and, in addition, wherever it crosses
 * a row or column of cell centres (where the bilinear surface may kink, so
 * planes, V-shapes and one-cell ramps are sampled exactly at their corners).
 * The horizon is the largest elevation angle atan((dz - d^2 k) / d) over the
 * samples, k = 1 / (2 R_eff) for earth curvature with refraction, or 0.
 * A sample whose bilinear stencil gives positive weight to a nodata cell is
 * skipped. -90 degrees where no sample lies ahead.
 *
 * Sky-view factors integrate the horizons over n_az >= 3600 evenly spaced
 * azimuths (the rectangle rule on a periodic integrand) with the formulas of
 * reference/physics.md sec. 2.2 written out again here. */
#ifndef SS_REFERENCE_MARCH_H
#define SS_REFERENCE_MARCH_H

#include "skysweep.h"

typedef struct {
    const ss_grid *grid;
    double curvature_k; /* 1 / (2 R_eff) per metre, 0 for a flat earth */
    double step_cells;  /* ray step as a fraction of the smaller cell side (<= 1/8) */
    /* Shortcuts that cannot change the answer (a sample can only win if it
     * rises above the best slope so far, and none rises above these): */
    double z_max;     /* highest valid height of the grid */
    float *block_max; /* highest height a sample in each 8 x 8 block can take */
    int blocks_x, blocks_y;
    int no_shortcuts; /* 1: march every ray to the edge (to test the shortcuts) */
} ref_march;

/* Prepares a march over grid; curvature_k as above; step_cells 0 means 1/8. */
void ref_march_init(ref_march *rm, const ss_grid *grid, double curvature_k, double step_cells);
void ref_march_free(ref_march *rm);

/* Horizon elevation angle, degrees, of cell (col, row) in azimuth_deg (grid
 * frame, clockwise from up the columns); -90 where nothing lies ahead.
 * NAN where the cell is nodata. If dist_m is given it receives the distance
 * of the sample that casts the horizon (0 where none, or where the
 * surface's own slope at the cell casts it: the limit d -> 0+). */
double ref_horizon_deg(const ref_march *rm, int col, int row, double azimuth_deg, double *dist_m);

/* Horn's (1981) gradient of the grid at a cell, one-sided where a neighbour
 * is outside the grid or nodata (the neighbour is replaced by the centre). */
void ref_gradient(const ss_grid *grid, int col, int row, double *dz_de, double *dz_dn);

/* The three sky-view factors of a cell (indexed by ss_svf_definition) by
 * integration over n_az azimuths starting at offset_deg; horizons_deg (n_az
 * values, may be NULL) receives the horizons used. NAN at nodata. */
void ref_svf(const ref_march *rm, int col, int row, int n_az, double offset_deg, double svf[3],
             double *horizons_deg);

/* SVFs from given horizons (n_az evenly spaced from offset_deg, degrees)
 * and a surface gradient: the same formulas, for other callers' horizons. */
void ref_svf_from_horizons(const double *horizons_deg, int n_az, double offset_deg, double dz_de,
                           double dz_dn, double svf[3]);

#endif
