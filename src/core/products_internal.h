/* Helpers shared by the sweep products. */
#ifndef SS_PRODUCTS_INTERNAL_H
#define SS_PRODUCTS_INTERNAL_H

#include "session.h"

/* curv_k = 1 / (2 R_eff), R_eff = R / (1 - k); 0 when curvature is off. */
float ss_curvature_k(const ss_sweep_options *opt);

/* Validates grid and options and opens a session with n_outputs grids. */
ss_status ss_product_begin(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                           int n_outputs, ss_session **session);

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

/* Terrain horizon of every cell in one azimuth (options' frame), degrees,
 * 0 where nothing lies ahead, into the session's output 0 (nodata cells
 * hold garbage). */
ss_status ss_sun_horizon(ss_session *s, const ss_grid *grid, const ss_sweep_options *opt,
                         double azimuth_deg, float **horizon_deg);

/* Insolation's per-cell terms (insolation_cell.h; perez: with the horizon
 * band) and the horizons stored at the options' directions (int16
 * hundredths of a degree, direction-major), as insolation.c and
 * insolation_cumulative.c need them. */
struct ss_cell_terms_s;
#define SS_HORIZON_SCALE 100.0f
ss_status ss_insolation_terms(ss_ctx *ctx, const ss_grid *g, const ss_sweep_options *opt,
                              const ss_insolation_options *io, struct ss_cell_terms_s **terms);
ss_status ss_insolation_store_horizons(ss_ctx *ctx, ss_session *s, const ss_grid *g,
                                       const ss_sweep_options *opt, int16_t **stored);
/* A weather step's record (insolation.c's sky_record_of). */
struct ss_sky_record_s;
int ss_insolation_sky_record(ss_ctx *ctx, const ss_sun_step *sun,
                             const ss_insolation_options *io, struct ss_sky_record_s *rec,
                             int *light);
/* The cumulative sky (insolation_cumulative.c): what ss_insolation does in
 * that mode. */
ss_status ss_insolation_cumulative(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                                   const ss_insolation_options *io, int n_steps,
                                   ss_sun_step_fn sun_at, void *sun_user, ss_insolation_out *out);

/* The insolation options and step count, as both insolation paths need them. */
ss_status ss_insolation_check(ss_ctx *ctx, const ss_insolation_options *io, int n_steps);
/* Whether step k is this process's (ss_insolation_options' share). */
int ss_insolation_step_is_mine(const ss_insolation_options *io, int k);

#endif
