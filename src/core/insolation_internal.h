/* What the stages of an insolation run share (insolation.c: the steps;
 * insolation_terms.c: each cell's terms; insolation_cumulative.c: the
 * cumulative sky). Each stage is a run of the one driver (engine.h). */
#ifndef SS_INSOLATION_INTERNAL_H
#define SS_INSOLATION_INTERNAL_H

#include <stdint.h>

#include "cell_store.h"
#include "insolation_cell.h"
#include "products_internal.h"
#include "ss_stored_horizon.h"

typedef struct {
    ss_ctx *ctx;
    const ss_source *src;
    const ss_sweep_options *opt;
    const ss_insolation_options *io;
    const ss_share *share;
    ss_sun_rows_fn sun_rows;
    void *sun_user;
    int want; /* SS_INSOLATION_* */
    ss_rows_sink sink;
    void *user;
    int perez_band; /* weather records under Perez's sky: the horizon band each cell sees */
    /* Per cell: the surface's sky view (plane 0) and the share of Perez's
     * horizon band it sees (plane 1). */
    ss_cell_store *cells;
    /* Interpolated shadows and the cumulative sky: each cell's horizon at the
     * D directions (kernels/ss_stored_horizon.h), one plane each. */
    ss_cell_store *horizons;
    /* Trees under Perez's sky: per cell of the whole grid, the share of the
     * horizon band crowns hide (ss_insolation_trees_band); else NULL. */
    float *trees_band_hidden;
    /* Beer-Lambert crowns: per cell of the whole grid, the mean of
     * exp(-G LAD L) over the sky they hide and over the horizon band they
     * hide (ss_insolation_trees_sky, ss_insolation_trees_band); else NULL. */
    float *trees_sky_through, *trees_band_through;
} ss_insolation_job;

/* Perez's horizon band spans the 6.5 degrees above the horizontal (Perez
 * et al. 1987). */
#define SS_PEREZ_BAND_DEG 6.5f

/* The gradient (east, north) of a fixed surface in the grid's frame (0, 0
 * for the cell's own surface, whose gradient is its slope's). */
void ss_insolation_surface_gradient(const ss_surface *s, const ss_sweep_options *opt,
                                    float *dz_de, float *dz_dn);

/* Each cell's sky view and horizon band into job->cells (a summed walk, and
 * a horizon walk where Perez's band or a surface other than the cell's
 * own needs it), and, for interpolated shadows and the cumulative sky, the
 * horizons at the D directions into job->horizons (from that walk where
 * there is one). */
ss_status ss_insolation_cell_inputs(ss_insolation_job *job);
/* The terms of a band's own cells (SVF and band from job->cells, the
 * surface's gradient, the air pressure at the cell's height). */
ss_status ss_insolation_band_terms(const ss_insolation_job *job, const ss_band_view *band,
                                   ss_cell_terms *terms);

/* The planes an insolation run sums per cell: the five outputs, and the
 * months and PV yields where asked for (-1: not kept). */
typedef struct {
    int global, beam, diffuse, reflected, hours, monthly, pv, pv_ac;
    int count;
} ss_insolation_planes;
ss_insolation_planes ss_insolation_planes_of(int want);
/* A band's sums, added over the processes that share the run, with
 * SS_NODATA at nodata, to the sink. */
ss_status ss_insolation_write_band(const ss_insolation_job *job, const ss_band_view *band,
                                   float *planes);

/* What insolation.c's steps and the cumulative sky share of a weather
 * record: its irradiance (W/m^2), or 0 where it is missing; with count, the
 * record's oddities go into the context's counters. */
int ss_insolation_sky_record(ss_ctx *ctx, const ss_sun_step *sun,
                             const ss_insolation_options *io, ss_sky_record *rec, int *light,
                             int count);
/* The cumulative sky: what an insolation run does in that mode. */
ss_status ss_insolation_cumulative(ss_insolation_job *job, int n_steps);

#endif
