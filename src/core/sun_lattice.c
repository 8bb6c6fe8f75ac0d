/* Per-cell suns from a lattice of nodes (skysweep.h, ss_sun_lattice): the
 * one interpolation of them, which the sun field of the command line
 * (src/adapt/sun_field.c) fills its per-cell arrays with and insolation's
 * steps call on each run of cells, so that a step's suns need not pass
 * through memory. A device takes its cells one by one (ss_lattice_sun_at);
 * both compute each cell with kernels/ss_sun_lattice.h. */
#include "config.h"

#include "skysweep_sun.h"
#include "ss_sun_lattice.h"

size_t ss_sun_lattice_tx_count(const ss_sun_lattice *l)
{
    return (size_t)(l->cols[l->n_cols - 1] - l->cols[0] + l->n_cols);
}

void ss_sun_lattice_tx(const ss_sun_lattice *l, double *tx)
{
    const int *cols = l->cols;
    for (int i = 0; i + 1 < l->n_cols; ++i)
        for (int c = cols[i]; c <= cols[i + 1]; ++c)
            tx[cols[i] - cols[0] + i + (c - cols[i])] = ss_lattice_between(c, cols[i], cols[i + 1]);
}

/* Bilinear between nodes. So is refraction where the sun stands above the
 * horizontal at all four nodes: there it bends by at most 0.05 deg per
 * deg^2 of elevation in standard air (0.065 at -40 C and 1050 hPa), and
 * the nodes' elevations differ by 0.013 deg at most on the command line's
 * 1 km lattice, so interpolation errs by 1.4e-6 deg at most, 1/700 of the
 * default sun tolerance. Below, down to the cut-off where refraction
 * stops, it bends sharply: per cell. */
void ss_sun_lattice_cells(const ss_sun_lattice *l, const double *tx, int row, int col0, int n,
                          float *grid_azimuth_deg, float *elevation_deg, float *apparent_deg)
{
    const int *rows = l->rows, *cols = l->cols;
    int nc = l->n_cols, nr = l->n_rows, col1 = col0 + n; /* cells [col0, col1) */
    int j = 0;
    while (j + 2 < nr && rows[j + 1] < row)
        ++j;
    double ty = ss_lattice_between(row, rows[j], rows[j + 1]);
    const double *node_az = l->grid_azimuth_deg, *node_e0 = l->elevation_deg;
    const double *node_refr = l->refraction_deg;
    int i = 0;
    while (i + 2 < nc && cols[i + 1] <= col0)
        ++i;
    for (; i + 1 < nc && cols[i] < col1; ++i) {
        /* The segment's cells among those asked for: those it starts,
         * and the last column in the last segment. */
        int last = i + 2 == nc;
        int c_lo = cols[i] > col0 ? cols[i] : col0;
        int c_hi = (last ? cols[i + 1] + 1 : cols[i + 1]) < col1
                       ? (last ? cols[i + 1] + 1 : cols[i + 1])
                       : col1;
        /* The row's values at the segment's two ends, then linear along it. */
        size_t a = (size_t)j * nc + i, b = a + 1, d = a + nc, e = d + 1;
        double az0 = ss_lattice_blend(ty, node_az[a], node_az[d]);
        double az1 = ss_lattice_blend(ty, node_az[b], node_az[e]);
        double e00 = ss_lattice_blend(ty, node_e0[a], node_e0[d]);
        double e01 = ss_lattice_blend(ty, node_e0[b], node_e0[e]);
        double r0 = ss_lattice_blend(ty, node_refr[a], node_refr[d]);
        double r1 = ss_lattice_blend(ty, node_refr[b], node_refr[e]);
        int smooth = node_e0[a] > 0 && node_e0[b] > 0 && node_e0[d] > 0 && node_e0[e] > 0;
        const double *tx_of = tx + (i - cols[0]); /* by column: segment i's place */
        if (smooth) {
            /* No call and no branch: the cells run in vector lanes. */
#pragma omp simd
            for (int c = c_lo; c < c_hi; ++c) {
                double t = tx_of[c];
                double e0 = ss_lattice_blend(t, e00, e01);
                grid_azimuth_deg[c - col0] = (float)ss_lattice_blend(t, az0, az1);
                elevation_deg[c - col0] = (float)e0;
                apparent_deg[c - col0] = (float)(e0 + ss_lattice_blend(t, r0, r1));
            }
            continue;
        }
        for (int c = c_lo; c < c_hi; ++c) {
            double t = tx_of[c];
            double e0 = ss_lattice_blend(t, e00, e01);
            grid_azimuth_deg[c - col0] = (float)ss_lattice_blend(t, az0, az1);
            elevation_deg[c - col0] = (float)e0;
            apparent_deg[c - col0] =
                (float)(e0 + ss_refraction_deg(e0, l->pressure_hpa, l->temperature_c,
                                               l->atmos_refract_deg));
        }
    }
}
