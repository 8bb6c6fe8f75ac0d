/* Trees in insolation's steps (skysweep.h's ss_insolation_trees,
 * doc/vegetation.md "insolation"): each step's transmissivity, the crowns
 * its sun's ray crosses, and the sky view the crowns leave. */
#ifndef SS_INSOLATION_TREES_H
#define SS_INSOLATION_TREES_H

#include "insolation_internal.h"

/* Refuses trees on another grid or a transmissivity outside 0..1. */
ss_status ss_insolation_trees_check(ss_ctx *ctx, const ss_insolation_options *io,
                                    const ss_source *src);
/* The transmissivity of step k: leaf off or on. */
float ss_insolation_trees_transmissivity(const ss_insolation_trees *t, int k);
/* The share of Perez's horizon band crowns hide, per cell of the whole
 * grid, as the run's surfaces face it (ss_canopy_band_hidden) into
 * job->trees_band_hidden, and with Beer-Lambert the mean light the crowns
 * pass over it into job->trees_band_through. */
ss_status ss_insolation_trees_band(ss_insolation_job *job);
/* Beer-Lambert: the mean light the crowns pass over the sky they hide,
 * per cell of the whole grid (ss_canopy_sky_through, the run's
 * directions and trunk gaps), into job->trees_sky_through; nothing for
 * the constant model or without sky_hidden. */
ss_status ss_insolation_trees_sky(ss_insolation_job *job);
/* The terms of a band's own cells with the crowns' sky at transmissivity
 * T, or with beer_lambert at each cell's own (job->trees_sky_through and
 * trees_band_through): each cell's sky view less sky_hidden x (1 - T),
 * and the share of the horizon band it sees less the job's
 * trees_band_hidden x (1 - T) (NULL: none), each at least 0. */
void ss_insolation_trees_terms(const ss_insolation_job *job, const ss_band_view *band, float T,
                               int beer_lambert, const ss_cell_terms *in, ss_cell_terms *out);
/* crossed[c] (indexed over the whole grid) for at least rows [row0, row0 +
 * n_rows), for the step's sun at the grid's centre: 1 where the ray toward
 * it crosses a crown (ss_canopy_crossed_where_lit). With the step's box
 * shadows by each cell's own ray over those rows (solid_angle, from row0;
 * NULL: none), the cells they shade from every sun of the step may be
 * left 0: no crown changes their light. */
ss_status ss_insolation_trees_crossed(ss_ctx *ctx, const ss_insolation_trees *t,
                                      const ss_sweep_options *opt, const ss_sun_step *sun,
                                      int row0, int n_rows, const float *solid_angle,
                                      unsigned char *crossed);
/* Whether step k's beam crosses crowns by Beer-Lambert (leaf on, and a
 * leaf area density given). */
int ss_insolation_trees_beer_lambert(const ss_insolation_trees *t, int k);
/* Beer-Lambert: through[c] over the whole grid for the step's sun at the
 * grid's centre, the fraction of the beam that arrives, exp(-G LAD path)
 * of the ray's path inside crowns (1 where it crosses none, SS_NODATA at
 * nodata). */
ss_status ss_insolation_trees_through(ss_ctx *ctx, const ss_insolation_trees *t,
                                      const ss_sun_step *sun, float *through);
/* The same for a sun at a grid azimuth and apparent elevation (degrees):
 * the cumulative sky's bins. */
ss_status ss_insolation_trees_crossed_at(ss_ctx *ctx, const ss_insolation_trees *t,
                                         const ss_sweep_options *opt, double grid_azimuth_deg,
                                         double apparent_elevation_deg, unsigned char *crossed);

#endif
