/* What the parts of skysweep roofs share (cmd_roofs.c): its settings, the
 * window of rows it works in, its rows per plane and per building, and the
 * run that holds them; the insolation run and the skies
 * (roofs_insolation.c), the layers written (roofs_layers.c). */
#ifndef SKYSWEEP_CLI_ROOFS_H
#define SKYSWEEP_CLI_ROOFS_H

#include <limits.h>
#include <stddef.h>

#include "insolation_trees.h"
#include "options.h"
#include "roof_panels.h"
#include "roof_planes.h"
#include "roof_shade.h"
#include "roofs_io.h"
#include "run.h"
#include "weather.h"

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    ss_insolation_params ins;
    const char *weather, *weather_zone;
    int weather_far_ok;
    const char *buildings, *buildings_layer, *dtm, *csv, *id_field, *shade_masks, *cell_raster;
    double min_area_m2, max_angle_deg, tolerance_m, obstacle_m;
    double setback_m, min_irradiation, max_tilt_deg, max_off_equator_deg;
    const char *module_size;
    const char *horizon_dir;
    int horizon_format;
    int orientation, panels_layer, shade_table;
    double module_power_w, module_spacing_m, row_spacing_m, min_panel_area_m2;
    double flat_tilt_deg, rack_tilt_deg, rack_sun_elevation_deg;
    panel_options panel; /* from the above (settle_panel_options) */
    insolation_tree_settings trees; /* passed on to insolation */
} roofs_settings;

/* Bands of the insolation raster roofs reads (cmd_insolation.c's order). */
#define BAND_GLOBAL 1
#define BAND_MONTHS 6
#define BAND_PV_DC 18
#define BAND_PV_AC 19

/* A window of the grid's rows [row0, row0 + rows) that holds whole
 * footprints (doc/roofs.md, "Scale"): the DSM's heights, the ground's
 * (--dtm) and the insolation run's results per cell. The grid's cell c is
 * element c - base. */
typedef struct {
    int row0, rows;
    size_t base, n; /* row0 x width; rows x width */
    const float *z; /* the DSM's heights (relative to z_origin_m) */
    float *z_read;  /* where a banded job reads them, else NULL (the job's whole grid) */
    float *dtm;     /* absolute ground heights (--dtm), else NULL */
    float *global;  /* kWh/m2 for the records */
    float *monthly; /* 12 planes of kWh/m2 */
    float *pv_dc;   /* kWh/kWp DC (after the system losses) */
    float *pv_ac;   /* kWh/kWp AC */
} roof_window;

/* Bytes a window holds per cell (roof_window; the DTM's counted always). */
#define WINDOW_CELL_BYTES (sizeof(float) * 17)

/* The weather's records as insolation steps at the DSM's centre, in a
 * frame whose grid north is true north (the steps of the unshaded runs). */
typedef struct {
    ss_sun_step *steps;
    int n;
} sky_steps;

typedef struct {
    size_t building;
    int number; /* 1.. within the building */
    roof_plane fit;
    double tilt_deg, azimuth_deg; /* true azimuth of the downslope direction */
    double centre_col, centre_row; /* the plane's cell nearest its mean (--horizon-files) */
    double area_m2, usable_area_m2, inner_area_m2;
    double kwh_m2_year, unshaded_kwh_m2_year, shading_loss_pct;
    double kwp, kwh_ac_year, kwh_dc_year, kwh_per_kwp, kwh_ac_month[12];
    int n_panels, racked, landscape;
    int shade_on_usable; /* the shade table counts its usable cells (else all its cells) */
    double panel_tilt_deg, panel_azimuth_deg; /* the modules' (racks': toward the equator) */
    void *geometry;
} plane_row;

/* A module of the layer panels. */
typedef struct {
    size_t plane; /* index of its plane_row */
    int number;   /* 1.. within the plane */
    double kwh_ac_year;
    void *geometry;
} panel_row;

typedef struct {
    double roof_area_m2, usable_area_m2, obstacle_area_m2, footprint_area_m2;
    double kwp, kwh_ac_year, kwh_dc_year, kwh_ac_month[12];
    int n_panels;
    double inner_area_m2, inner_kwh, inner_unshaded_kwh; /* for the mean and the loss */
    double height_m;
    int n_planes;
} building_sums;

/* What a plane's panel layout reads. */
typedef struct {
    const sweep_job *job;
    const roofs_settings *set;
    const ss_footprint *fp;
    const roof_window *win;
} roofs_run_view;

typedef struct {
    roofs_settings set;
    sweep_job job;
    ss_footprints fps;
    ss_weather weather;
    char raster[PATH_MAX + 40]; /* the insolation run's, read back a window at a time */
    roof_window win;            /* the window of rows being worked on */
    int n_windows, most_rows;   /* windows worked in, and the rows of the largest */
    ss_dem dtm;                 /* --dtm, read a window at a time */
    ss_dem_source *dtm_src;
    sky_steps sky;
    plane_row *planes;
    size_t n_planes, cap_planes;
    building_sums *sums;
    panel_row *panels; /* with --panels */
    size_t n_panels, cap_panels;
    roof_shade shade;              /* planes in the order of planes */
    char clear_sky[PATH_MAX + 40]; /* without --weather: the clear sky's records ("": none) */
    char sky_note[400];            /* the sky the yield is summed under */
    double seconds_planes, seconds_panels, seconds_insolation, seconds_unshaded, seconds_shade;
    double seconds_write;
} roofs_run;

/* roofs_insolation.c */
int roofs_run_insolation(sweep_job *job, const opt_spec *const *tables, const opt_spec *own,
                         int argc, char **argv, const char *clear_sky, const char *kept,
                         char *raster, size_t size);
ss_status roofs_sky_steps(sweep_job *job, const roofs_settings *set, const ss_weather *w,
                          sky_steps *out);
ss_status roofs_sky_step_at(ss_ctx *ctx, int index, ss_sun_step *step, void *user);
ss_status roofs_write_clear_sky(sweep_job *job, const roofs_settings *set, char *path,
                                size_t size, char *note, size_t note_size);

/* roofs_layers.c */
void roofs_define_fields(void);
ss_status roofs_write_outputs(roofs_run *r);

#endif
