/* Roof planes of one building from a DSM (doc/roofs.md, "Roof planes"):
 * each cell's normal from a plane fitted over its 3 x 3 neighbours in the
 * footprint, regions grown from the flattest cells over neighbours whose
 * normals agree and whose heights lie on the region's plane, a robust
 * least-squares plane per region, regions smaller than a minimum area
 * dropped, and the cells left over joined to a neighbouring plane they lie
 * on. Cells standing above an adjacent plane by more than a threshold are
 * obstacles (chimneys, dormers, vents). */
#ifndef SS_ROOF_PLANES_H
#define SS_ROOF_PLANES_H

#include <stddef.h>

typedef struct {
    double min_area_m2;   /* planes with less true (3D) area are not roof planes */
    double max_angle_deg; /* normals within this of the region's join it */
    double tolerance_m;   /* heights within this of the region's plane join it */
    double obstacle_m;    /* cells higher than an adjacent plane by more are obstacles */
} roof_plane_options;

typedef struct {
    /* z = a e + b n + c, e east and n north (grid axes) in metres from the
     * window's first cell centre */
    double a, b, c;
    double tilt_deg;
    double aspect_grid_deg; /* downslope direction, clockwise from grid north */
    double rms_m;           /* of the cells fitted */
    size_t n_cells;
} roof_plane;

#define ROOF_NONE (-1)
#define ROOF_OBSTACLE (-2)

/* The planes of a building whose cells (row * width + col) lie in the
 * window of cols x rows cells at col0, row0 of a grid of cells cell_x_m
 * by cell_y_m; z holds the grid's heights (NAN: none). label[i] gets the
 * plane (0-based) of cells[i], ROOF_OBSTACLE or ROOF_NONE. Returns the
 * number of planes (*planes malloc'ed), or -1 when memory is out. */
int roof_planes_find(const float *z, int width, double cell_x_m, double cell_y_m, int col0,
                     int row0, int cols, int rows, const int *cells, size_t n_cells,
                     const roof_plane_options *o, roof_plane **planes, int *label);

#endif
