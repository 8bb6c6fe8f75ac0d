/* Panel layouts on roof planes (doc/roofs.md, "Panels"): rows of modules
 * laid on a plane's usable cells, in the plane's own frame (along the eave
 * and up the slope), a module placed only where every cell it overlaps is
 * usable; on flat roofs, racks tilted toward the equator in rows spaced
 * clear of each other's shadow. */
#ifndef SS_ROOF_PANELS_H
#define SS_ROOF_PANELS_H

#include <stddef.h>

typedef enum { PANELS_PORTRAIT, PANELS_LANDSCAPE, PANELS_BEST } panel_orientation;

typedef struct {
    double length_m, width_m;        /* the module's long and short sides */
    double power_w;                  /* its nameplate (STC) */
    panel_orientation orientation;   /* portrait: the long side up the slope */
    double module_spacing_m;         /* between modules of a row */
    double row_spacing_m;            /* between rows, on the plane (racks: least gap) */
    double flat_tilt_deg;            /* planes tilted less are racked */
    double rack_tilt_deg;            /* the racks' tilt, facing the equator */
    double rack_sun_elevation_deg;   /* racked rows clear each other's shadow with the
                                        sun this high toward the equator */
    double min_panel_area_m2;        /* a plane whose modules cover less gets none */
} panel_options;

/* How modules lie on one plane, on the ground (metres): a module's
 * footprint along the rows and across them, and the pitch of both. */
typedef struct {
    int racked, landscape;
    double facing_grid_deg;  /* the way the modules face (descend), grid azimuth */
    double tilt_deg;         /* the modules' tilt */
    double along_m, depth_m; /* footprint along the rows, across them */
    double pitch_along_m, pitch_depth_m;
} panel_geometry;

/* The geometry on a plane of tilt and grid aspect (the way it descends);
 * equator_grid_deg: the grid azimuth of the equator (racks face it). */
panel_geometry panel_geometry_on(const panel_options *o, int landscape, double plane_tilt_deg,
                                 double plane_aspect_grid_deg, double equator_grid_deg);

/* Modules laid: ground corners in window metres (x east of the window's
 * west edge, y north of its north edge, so y <= 0), and the window cells
 * (row * cols + col) each overlaps, cells[first .. first + n_cells). */
typedef struct {
    double corner[4][2];
    size_t first;
    int n_cells;
    double kwh_ac_year; /* set by the caller */
} panel_place;

typedef struct {
    panel_place *items;
    size_t n, cap;
    int *cells;
    size_t n_cells, cap_cells;
} panel_layout;

/* Lays rows of modules of geometry g over the usable cells (nonzero in
 * usable, cols x rows cells of cx x cy metres), from the lower left
 * corner (looking up the slope) of the usable cells' bounding rectangle in
 * the plane's frame, rows up the slope, modules to the right.
 * The layout is emptied first. Returns 0, or -1 out of memory. */
int panels_lay(const panel_geometry *g, const unsigned char *usable, int cols, int rows,
               double cx, double cy, panel_layout *out);
void panel_layout_free(panel_layout *l);

#endif
