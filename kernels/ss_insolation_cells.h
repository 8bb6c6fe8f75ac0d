/* One time step of insolation over a band's own cells on a device
 * (sweep.cl's insolation_cells, one work-item a cell; shared by kernels and
 * C): the cell's sun from the step's lattice (ss_sun_lattice.h) or the
 * step's one sun, its horizon in the sun's azimuth (the step's walk, left on
 * the device; the stored horizons of interpolated shadows, uploaded there
 * once a visit; or none), what the step adds (ss_cell_step.h) into the
 * band's planes, the PV yield, and the step's own global where the run
 * writes each step. The host runs the same cell functions in SIMD lanes
 * (src/core/insolation_lanes.h), a clear sky's sun terms read from tables
 * over the step's cells; a device computes those exactly, which costs it
 * less than reading tables. */
#ifndef SS_INSOLATION_CELLS_H
#define SS_INSOLATION_CELLS_H

#include "ss_cell_step.h"
#include "ss_pv.h"
#include "ss_stored_horizon.h"
#include "ss_sun_lattice.h"

/* Where a step's horizons come from (ss_cells_step's horizon). */
enum { SS_CELLS_NO_HORIZON, SS_CELLS_WALKED, SS_CELLS_STORED };

/* A step as the device takes it (4-byte fields only, so that the host's
 * struct and the device's agree). Planes are indices into the band's
 * planes (insolation's order, ss_insolation_planes), -1 where not kept. */
typedef struct {
    int cells, width, row0; /* the band's own cells, the grid's width, the band's first row */
    int horizon;            /* SS_CELLS_*: the walk's horizons (degrees), the stored
                               ones, or none (-90) */
    int stored0, stored1;   /* SS_CELLS_STORED: the stored directions around the sun ... */
    float stored_t;         /* ... and the weight of the second (ss_stored_horizon.h) */
    int step_out;           /* 1: each cell's global for the step, to the step's buffer */
    int real_sky;           /* a weather record (rec, sky), else the clear sky (linke, g0) */
    int lattice;            /* the cells' suns from the lattice, else the step's */
    int lattice_cols, lattice_rows;
    float h0_deg, az_deg, app_deg; /* the step's sun: true elevation, grid azimuth, apparent */
    ss_sun_centre centre;          /* the same, as a weather record's cells take it */
    float linke, g0, albedo, dt;
    ss_sky_record rec;
    ss_sky_parts sky;
    int beam, diffuse, reflected, total, hours, month, pv, pv_ac;
    ss_pv_step pv_step; /* where pv >= 0 */
} ss_cells_step;

/* Own cell c of the band, height z (NaN at nodata: nothing added), terms t
 * and horizon (degrees), adds the step into planes (cells floats apart)
 * and, where the step asks, writes the cell's global to step_out (the
 * output's nodata at nodata). */
SS_FN void ss_cells_step_at(const ss_cells_step *s, const ss_lattice_view *l, int c, float z,
                            float horizon_deg, const ss_cell_terms *t, SS_GLOBAL float *planes,
                            SS_GLOBAL float *step_out)
{
    if (!SS_ISFINITE(z)) {
        if (s->step_out)
            step_out[c] = SS_NODATA_OUT;
        return;
    }
    float h0_deg = s->h0_deg, az_deg = s->az_deg, app_deg = s->app_deg;
    if (s->lattice)
        ss_lattice_sun_at(l, s->row0 + c / s->width, c % s->width, &az_deg, &h0_deg, &app_deg);
    const float rad = 0.017453292519943295f; /* (float)(pi / 180), as the host's */
    float h0 = h0_deg * rad, az = az_deg * rad;
    if (!s->real_sky && !(h0 > 0.0f)) { /* the clear sky's cells below the horizontal add nothing */
        if (s->step_out)
            step_out[c] = 0.0f;
        return;
    }
    /* A weather record's sun as the host's lanes take it; the clear sky's
     * terms exactly, where the host reads tables of them. */
    ss_cell_sun sun = s->real_sky && ss_sun_near(&s->centre, h0, az)
                          ? ss_sun_near_of(&s->centre, h0, az)
                          : ss_cell_sun_exact(t, h0, az, s->linke, !s->real_sky);
    ss_cell_step add =
        s->real_sky ? ss_cell_step_weather(t, &sun, app_deg, horizon_deg, &s->rec, s->sky, s->dt)
                    : ss_cell_step_of(t, &sun, app_deg, horizon_deg, s->g0, s->albedo, s->dt);
    ss_i64 n = s->cells;
    planes[s->beam * n + c] += add.beam;
    planes[s->diffuse * n + c] += add.diffuse;
    planes[s->reflected * n + c] += add.reflected;
    planes[s->total * n + c] += add.total;
    planes[s->hours * n + c] += add.sun_hours;
    if (s->month >= 0)
        planes[s->month * n + c] += add.total;
    if (s->pv >= 0 && s->dt > 0.0f) {
        float dc, ac;
        ss_cell_pv_yield(&s->pv_step, add.total, s->dt, &dc, &ac);
        planes[s->pv * n + c] += dc;
        planes[s->pv_ac * n + c] += ac;
    }
    if (s->step_out)
        step_out[c] = add.total;
}

/* Own cell c's horizon (degrees) as the step gives it: the walk's (from
 * walked, the band's own rows of the step's slot), the stored directions'
 * (stored: the band's own cells, one plane a direction) or none. */
SS_FN float ss_cells_horizon(const ss_cells_step *s, int c, SS_GLOBAL const float *walked,
                             SS_GLOBAL const short *stored)
{
    if (s->horizon == SS_CELLS_WALKED)
        return walked[c];
    if (s->horizon == SS_CELLS_STORED)
        return ss_stored_horizon_between(stored[(ss_i64)s->stored0 * s->cells + c],
                                         stored[(ss_i64)s->stored1 * s->cells + c], s->stored_t);
    return -90.0f;
}

#endif
