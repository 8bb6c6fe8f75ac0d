/* Helpers shared by the products (each a consumer of the one driver,
 * engine.h). */
#ifndef SS_PRODUCTS_INTERNAL_H
#define SS_PRODUCTS_INTERNAL_H

#include "engine.h"

/* curv_k = 1 / (2 R_eff), R_eff = R / (1 - k); 0 when curvature is off. */
float ss_curvature_k(const ss_sweep_options *opt);

/* Whether cast shadows on box lines are each cell's own ray by bounds and
 * march (box_shadow.h): asked for (box_shadows), on a grid held whole or
 * read in bands (a march reads columns anywhere upstream: a banded run
 * holds the heights whole for it, ss_source_heights, 4 bytes a cell that
 * the CLI's and Python's memory plans count). The march runs on the host
 * whatever the device, and so do the products' steps that use it (a GPU
 * keeps insolation's per-cell terms on the host then), so every device and
 * every band height gives the same box shadows. */
int ss_box_shadows_marched(const ss_sweep_options *opt);
/* Where ss_box_shadows_marched: the box shadows toward azimuth_deg (the
 * options' frame) handed to direction band by band (the source's band
 * rows; one band of the grid held whole), each cell's horizon right for
 * every sun from el_lo_deg to el_hi_deg (box_shadow.h), as a walk's would
 * be; the views hold every row. */
ss_status ss_box_shadow_march(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                              double azimuth_deg, double el_lo_deg, double el_hi_deg,
                              ss_status (*direction)(void *, int, const ss_band_view *,
                                                     const ss_dir_rows *, float *),
                              void *user);

/* ss_canopy_crossed for rows [row0, row0 + n_rows) at least (a band's;
 * crossed is the whole grid's: by each cell's own ray those rows alone are
 * written, the lines' walks write every row), where by each cell's own ray
 * leaving 0 unasked the cells whose solid horizon (solid_angle, over those
 * rows from row0; NULL: none given) is at least solid_el_hi: the solid
 * shades them from every sun of the step (box_crowns.h). */
ss_status ss_canopy_crossed_where_lit(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                      const ss_sweep_options *lines, double sun_grid_azimuth_deg,
                                      double sun_elevation_deg, int row0, int n_rows,
                                      const float *solid_angle, double solid_el_hi,
                                      unsigned char *crossed);

/* Line set of direction i; returns the direction's azimuth in the grid's
 * frame, radians (the frame the sweep and cell slopes live in). */
double ss_product_lines(const ss_grid *grid, const ss_sweep_options *opt, int i,
                        ss_line_set *ls);
/* The same for any azimuth (in the options' frame, degrees). */
double ss_product_lines_at(const ss_grid *grid, const ss_sweep_options *opt,
                           double azimuth_deg, ss_line_set *ls);

/* A cell's value from the sum of its terms over the directions: the SVF
 * definitions (SS_SVF_*) or openness (SS_TERM_ELEVATION: 90 - mean). */
float ss_product_finish(int term, float sum, int directions);

/* Whether a sky walk (ss_sky_walk) of radius radius_m (0: none) takes
 * each cell's own ray (box_sky.h) on box lines: asked for (box_sky), on a
 * grid held whole or read in bands (a ray reads columns anywhere: a banded
 * run holds the heights whole, ss_source_heights, 4 bytes a cell that the
 * CLI's and Python's memory plans count), on the host whatever the device.
 * Radius-limited horizons take no box lines. */
int ss_box_sky_marched(const ss_sweep_options *opt, double radius_m);

/* Runs a horizon walk (job's term SS_TERM_HORIZON): where
 * ss_box_sky_marched (no radius, heights not negated), each cell's own
 * ray, the box model exactly, handed to the consumer band by band as the
 * engine hands its walks (the views hold every row; the heights held whole
 * as for the sky view); else ss_engine_run. */
ss_status ss_horizon_walk(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                          const ss_engine_job *job);

/* ss_sky_rows on arguments its caller has checked (sky_walk.c; ss_rows_begin, or a
 * product of its own that needs the sky view). */
ss_status ss_sky_walk(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                      ss_sky_term term, double radius_m, const ss_share *share,
                      ss_rows_sink sink, void *user);
/* Checks a share of a run's directions or steps (NULL: all). */
ss_status ss_share_check(ss_ctx *ctx, const ss_share *share);
/* What every row-wise call does before it runs: checks the share, the DEM
 * (held heights are scanned once here) and the options, which
 * ss_engine_run takes as checked however often a product runs it; and
 * zeroes the DEM's band stats, which those runs add to. */
ss_status ss_rows_begin(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                        const ss_share *share);
/* Whether direction or step k is this process's. */
int ss_share_has(const ss_share *share, int k);
/* Adds the processes' sums of a band where the run is shared. */
ss_status ss_share_reduce(const ss_share *share, float *sums, size_t n);

/* A sink for the whole-grid calls: rows of (output, index) are copied into
 * the grid grid_of names (NULL: not wanted), rows apart by width. */
typedef struct {
    float *(*grid_of)(void *user, int output, int index);
    void *user;
    int width;
} ss_grid_sink;
ss_status ss_grid_sink_rows(void *sink, int output, int index, int row0, int n_rows,
                            const float *values);

/* Horn's cos(incidence) of the sun (grid azimuth and elevation, degrees,
 * per cell where the arrays are given: one value per output cell) for rows
 * [row0, row1) of grid into out (SS_NODATA at nodata). */
void ss_incidence_rows(const ss_grid *grid, int row0, int row1, double grid_azimuth_deg,
                       double elevation_deg, const float *grid_azimuth_per_cell_deg,
                       const float *elevation_per_cell_deg, float *out);
/* gdaldem's hillshade of rows [row0, row1) of grid into out (values 1..255,
 * SS_NODATA at nodata), options checked by ss_hillshade_check. */
void ss_hillshade_of_rows(const ss_grid *grid, int row0, int row1,
                          const ss_hillshade_options *ho, float *out);

/* The held rows of a band as a grid of their own (Horn's slopes inside it
 * are the whole grid's). */
ss_grid ss_band_grid(const ss_band_view *band, const ss_source *src);

/* ss_horizon_bound_deg for any source: one visit of its bands. */
ss_status ss_horizon_bound_of(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                              double *deg);

/* Trees in Perez's horizon band (doc/vegetation.md, "insolation"): per
 * cell, the share of the band (elevations 0 to band_deg) that crowns of
 * other cells hide above the solid horizon, as ss_canopy_sky's crowns hide
 * the sky (digital lines, the gaps under crowns as `gaps` says, the earth
 * flat), each direction's share weighted as Perez's band is: by the cosine
 * of its incidence on the cell's surface (dz_de, dz_dn: the gradient in
 * the grid's frame), the directions behind the surface not counted; the
 * options' directions on the engine's lines (grid_north_deg taken off).
 * 0 where the surface faces no direction, SS_NODATA at nodata. */
ss_status ss_canopy_band_hidden(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                const ss_sweep_options *opt, ss_trunk_gaps gaps, double band_deg,
                                const float *dz_de, const float *dz_dn, double per_m,
                                float *hidden, float *through);
/* Beer-Lambert through the crowns' sky (doc/vegetation.md, "Beer-Lambert
 * in insolation"): per cell, the mean of exp(-per_m L) over the sky that
 * ss_canopy_sky (horizontal definition, the same options and gaps) finds
 * the crowns hide, weighted as it weighs them, L the ray's path inside
 * crowns in each direction: the crown cells it passes on the digital line
 * (the rises from each one's bottom, or with the gaps ignored the solid
 * horizon, to its top) x the line's run through a cell x sec(elevation).
 * Exact on the lines (E_3 in closed form between the crowns' ends). 1
 * where the crowns hide nothing, SS_NODATA at nodata. ss_canopy_band_hidden
 * gives the same for Perez's band in `through` (NULL: not wanted; per_m
 * then unused), each direction weighted as the band's hidden share. */
ss_status ss_canopy_sky_through(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                const ss_sweep_options *opt, ss_trunk_gaps gaps,
                                double per_m, float *through);

/* The insolation options and step count, as every insolation path needs them. */
ss_status ss_insolation_check(ss_ctx *ctx, const ss_insolation_options *io, int n_steps);

#endif
