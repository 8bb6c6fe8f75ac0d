/* Per-cell maths shared by kernels and C: what a product makes of one
 * cell's horizon in one direction. Formulas and sources:
 * ../doc/model.md and reference/physics.md sec. 2. */
#ifndef SS_TERMS_H
#define SS_TERMS_H

#include "ss_compat.h"

/* What a walk takes from every sample (one set of values for the per-sample
 * terms; part of the kernel interface). SVF definitions: */
#define SS_SVF_GEOMETRIC 0  /* Zaksek et al. 2011 / RVT: 1 - mean sin h+ */
#define SS_SVF_HORIZONTAL 1 /* radiative, horizontal surface: mean cos^2 h+ */
#define SS_SVF_TILTED 2     /* radiative, tilted cell: Dozier & Frew 1990 eq. 7b */
#define SS_TERM_ELEVATION 3 /* the horizon's elevation in degrees (0 where nothing lies
                               ahead): positive openness is 90 - its mean */
/* The terms above are summed over directions per cell; this one is not: */
#define SS_TERM_HORIZON 4   /* each direction's horizon angle (a weighted mean over the
                               cell's samples), and where wanted its distance and the
                               casting point's height (SS_HORIZON_WANT_*) */
#define SS_HORIZON_WANT_DIST 1
#define SS_HORIZON_WANT_CAST 2 /* needs the distances too */

/* atan(x) for x >= 0 to within about 1e-7 rad: reduced to [0, 1] by
 * atan(x) = pi/2 - atan(1/x), then below tan(15 deg) by atan(x) = pi/6 +
 * atan((x sqrt3 - 1) / (x + sqrt3)), where the Taylor series to the 15th
 * power errs by under 1e-10. Several times faster than the OpenCL and libm
 * arctangents, whose full accuracy at any argument the sweep does not need. */
SS_FN float ss_atan_nonneg(float x)
{
    int inverted = x > 1.0f;
    float a = inverted ? 1.0f / x : x;
    int shifted = a > 0.26794919f;
    float u = shifted ? (a * 1.7320508f - 1.0f) / (a + 1.7320508f) : a;
    float u2 = u * u;
    float series =
        u * (1.0f +
             u2 * (-1.0f / 3 +
                   u2 * (1.0f / 5 +
                         u2 * (-1.0f / 7 +
                               u2 * (1.0f / 9 +
                                     u2 * (-1.0f / 11 + u2 * (1.0f / 13 - u2 * (1.0f / 15))))))));
    float r = shifted ? 0.52359878f + series : series;
    return inverted ? 1.5707963f - r : r;
}

/* Elevation angle of a horizon vector (d >= 0), radians: atan(dz / d),
 * -pi/2 when nothing lies ahead (d = 0). */
SS_FN float ss_horizon_rad(float d, float dz)
{
    if (!(d > 0.0f))
        return dz >= 0.0f ? 0.5f * SS_PI_F : -0.5f * SS_PI_F;
    float a = ss_atan_nonneg(SS_FABS(dz) / d);
    return dz < 0.0f ? -a : a;
}

/* Horizon elevation in degrees; -90 when nothing lies ahead (d = 0). */
SS_FN float ss_horizon_deg(float d, float dz)
{
    return ss_horizon_rad(d, dz) * SS_DEG_PER_RAD_F;
}

/* sin of the horizon elevation clipped at 0: one direction's share of the
 * geometric (solid-angle) obstruction. */
SS_FN float ss_svf_geometric_term(float d, float dz)
{
    return dz > 0.0f ? dz / SS_SQRT(dz * dz + d * d) : 0.0f;
}

/* cos^2 of the horizon elevation clipped at 0: one direction's share of
 * the cosine-weighted sky seen by a horizontal surface. */
SS_FN float ss_svf_horizontal_term(float d, float dz)
{
    return dz > 0.0f ? d * d / (dz * dz + d * d) : 1.0f;
}

/* One direction's share of the sky seen by the tilted cell surface,
 * isotropic radiance, cosine-weighted (Dozier & Frew 1990 eq. 7b written
 * with elevations as in HORAYZON's topo_param.pyx):
 *     [cos^2 h - rise (pi/2 - h - sin h cos h)] / sqrt(1 + |grad z|^2).
 * The horizon is clipped at the horizontal (physics.md convention A, so an
 * open tilted plane gives (1 + cos S)/2) and at the cell's own tangent plane
 * (Dozier 2022), so no sky behind the surface is counted. With t = tan h
 * the terms are cos^2 h = 1/(1 + t^2), sin h cos h = t/(1 + t^2) and
 * pi/2 - h = atan2(1, t): one arctangent per direction, no sines.
 * dz_de, dz_dn: surface gradient. */
SS_FN float ss_svf_tilted_term(float d, float dz, float sin_az, float cos_az, float dz_de,
                               float dz_dn)
{
    float rise = dz_de * sin_az + dz_dn * cos_az; /* tan of the tangent plane's elevation */
    float t = SS_FMAX(rise, 0.0f);
    if (d > 0.0f && dz > t * d)
        t = dz / d;
    float inv = 1.0f / (1.0f + t * t);
    float t_term = inv - rise * (0.5f * SS_PI_F - ss_atan_nonneg(t) - t * inv);
    return t_term / SS_SQRT(1.0f + dz_de * dz_de + dz_dn * dz_dn);
}

/* One direction's term of a summed sky walk (SS_SVF_* or SS_TERM_ELEVATION)
 * for a cell whose horizon in it is the tangent (d, dz), d = 0 where no
 * terrain lies ahead; dz_de, dz_dn: the cell's surface gradient, which only
 * the radiative SVF of a tilted cell reads. */
SS_FN float ss_sky_walk_term(int definition, float d, float dz, float sin_az, float cos_az,
                             float dz_de, float dz_dn)
{
    if (definition == SS_SVF_GEOMETRIC)
        return ss_svf_geometric_term(d, dz);
    if (definition == SS_SVF_HORIZONTAL)
        return ss_svf_horizontal_term(d, dz);
    if (definition == SS_TERM_ELEVATION)
        return d > 0.0f ? ss_horizon_deg(d, dz) : 0.0f;
    return ss_svf_tilted_term(d, dz, sin_az, cos_az, dz_de, dz_dn);
}

/* Height of neighbour (col + dc, row + dr) of cell (col, row) for the
 * gradient, as gdaldem -compute_edges takes it (GDALGeneric3x3Processing),
 * so that a plane's slope is exact on the grid's edge too:
 *   - past the top or bottom edge, extrapolated along its column from the
 *     two cells inside, 2 z(edge row) - z(next row);
 *   - past a side edge, along its row, 2 z(edge column) - z(next column),
 *     except in the first and last rows, where gdaldem takes the edge
 *     column itself (so a corner's slope across the side is one-sided);
 *   - nodata, or a grid too thin to extrapolate: the centre's own height,
 *     as gdaldem takes a hole's neighbours. */
SS_FN float ss_z_or(SS_GLOBAL const float *z, int width, int height, int col, int row, int dc,
                    int dr, float centre)
{
    int r = row + dr, c = col + dc;
    int end_row = row == 0 || row == height - 1;
    float v = centre;
    if (r < 0 || r >= height) {
        int cc = c < 0 ? 0 : c >= width ? width - 1 : c;
        int r0 = r < 0 ? 0 : height - 1, r1 = r < 0 ? 1 : height - 2;
        if (height >= 2 && width >= 2)
            v = 2.0f * z[r0 * width + cc] - z[r1 * width + cc];
    } else if ((c < 0 || c >= width) && end_row) {
        v = z[r * width + (c < 0 ? 0 : width - 1)];
    } else if (c < 0 || c >= width) {
        int c0 = c < 0 ? 0 : width - 1, c1 = c < 0 ? 1 : width - 2;
        if (width >= 2)
            v = 2.0f * z[r * width + c0] - z[r * width + c1];
    } else {
        v = z[r * width + c];
    }
    return SS_ISFINITE(v) ? v : centre;
}

/* The same for a neighbour known to lie inside the grid: no bounds tests,
 * so that a loop over a row's inner cells vectorises. */
SS_FN float ss_z_inner_or(SS_GLOBAL const float *z, int width, int col, int row, float fallback)
{
    float v = z[row * width + col];
    return SS_ISFINITE(v) ? v : fallback;
}

/* Surface gradient by Horn's (1981) 3x3 formula, as gdaldem uses, from the
 * eight neighbours' heights; rows run north to south. */
SS_FN void ss_horn(float nw, float n, float ne, float w, float e, float sw, float s, float se,
                   float cell_x_m, float cell_y_m, float *dz_de, float *dz_dn)
{
    *dz_de = ((ne + 2.0f * e + se) - (nw + 2.0f * w + sw)) / (8.0f * cell_x_m);
    *dz_dn = ((nw + 2.0f * n + ne) - (sw + 2.0f * s + se)) / (8.0f * cell_y_m);
}

/* Horn's gradient of cell (col, row), edges and holes as gdaldem
 * -compute_edges takes them (ss_z_or). */
SS_FN void ss_gradient_horn(SS_GLOBAL const float *z, int width, int height, int col, int row,
                            float cell_x_m, float cell_y_m, float *dz_de, float *dz_dn)
{
    float c = z[row * width + col];
    ss_horn(ss_z_or(z, width, height, col, row, -1, -1, c),
            ss_z_or(z, width, height, col, row, 0, -1, c),
            ss_z_or(z, width, height, col, row, 1, -1, c),
            ss_z_or(z, width, height, col, row, -1, 0, c),
            ss_z_or(z, width, height, col, row, 1, 0, c),
            ss_z_or(z, width, height, col, row, -1, 1, c),
            ss_z_or(z, width, height, col, row, 0, 1, c),
            ss_z_or(z, width, height, col, row, 1, 1, c), cell_x_m, cell_y_m, dz_de, dz_dn);
}

/* The same for a cell whose eight neighbours all lie inside the grid (not
 * on its edge): the same values, and a loop over them vectorises. */
SS_FN void ss_gradient_horn_inner(SS_GLOBAL const float *z, int width, int col, int row,
                                  float cell_x_m, float cell_y_m, float *dz_de, float *dz_dn)
{
    float c = z[row * width + col];
    ss_horn(ss_z_inner_or(z, width, col - 1, row - 1, c), ss_z_inner_or(z, width, col, row - 1, c),
            ss_z_inner_or(z, width, col + 1, row - 1, c), ss_z_inner_or(z, width, col - 1, row, c),
            ss_z_inner_or(z, width, col + 1, row, c), ss_z_inner_or(z, width, col - 1, row + 1, c),
            ss_z_inner_or(z, width, col, row + 1, c), ss_z_inner_or(z, width, col + 1, row + 1, c),
            cell_x_m, cell_y_m, dz_de, dz_dn);
}

/* Surface gradient by Zevenbergen & Thorne's (1987) central differences,
 * gdaldem's -alg ZevenbergenThorne, from the four edge neighbours. */
SS_FN void ss_zevenbergen_thorne(float n, float w, float e, float s, float cell_x_m,
                                 float cell_y_m, float *dz_de, float *dz_dn)
{
    *dz_de = (e - w) / (2.0f * cell_x_m);
    *dz_dn = (n - s) / (2.0f * cell_y_m);
}

SS_FN void ss_gradient_zt(SS_GLOBAL const float *z, int width, int height, int col, int row,
                          float cell_x_m, float cell_y_m, float *dz_de, float *dz_dn)
{
    float c = z[row * width + col];
    ss_zevenbergen_thorne(ss_z_or(z, width, height, col, row, 0, -1, c),
                          ss_z_or(z, width, height, col, row, -1, 0, c),
                          ss_z_or(z, width, height, col, row, 1, 0, c),
                          ss_z_or(z, width, height, col, row, 0, 1, c), cell_x_m, cell_y_m, dz_de,
                          dz_dn);
}

SS_FN void ss_gradient_zt_inner(SS_GLOBAL const float *z, int width, int col, int row,
                                float cell_x_m, float cell_y_m, float *dz_de, float *dz_dn)
{
    float c = z[row * width + col];
    ss_zevenbergen_thorne(ss_z_inner_or(z, width, col, row - 1, c),
                          ss_z_inner_or(z, width, col - 1, row, c),
                          ss_z_inner_or(z, width, col + 1, row, c),
                          ss_z_inner_or(z, width, col, row + 1, c), cell_x_m, cell_y_m, dz_de,
                          dz_dn);
}

#endif
