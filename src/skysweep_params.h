/* skysweep: the parameter table. Every product's parameters as the library
 * takes them, each with its name, type, default, range, choices and help,
 * and the calls that turn them into the products' options. Front ends
 * derive their options from it: the command line's options, --help,
 * doc/cli.md, the man pages and scene keys, and through them the Python
 * package and the QGIS provider (skysweep COMMAND --help-json). */
#ifndef SKYSWEEP_PARAMS_H
#define SKYSWEEP_PARAMS_H

#include "skysweep.h"
#include "skysweep_sun.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    SS_PARAM_INT,    /* int, within [min, max] */
    SS_PARAM_DOUBLE, /* double, finite, within [min, max] */
    SS_PARAM_TEXT,   /* const char *, read by the product (a time, a list of values) */
    SS_PARAM_CHOICE, /* int: the index of the word given among the '|'-separated choices */
    SS_PARAM_FLAG    /* int: 1 when given */
} ss_param_type;

typedef struct {
    const char *name;         /* "definition": the command line's --definition */
    ss_param_type type;
    size_t offset;            /* of the value in the table's parameter struct */
    const char *metavar;      /* what a value is, e.g. METRES */
    const char *default_text; /* the default as text; NULL: none */
    double min, max;
    const char *choices;
    const char *help;
} ss_param;

/* A table: its name ("svf", or "sweep" and "sun" for what every sweeping
 * product takes), what it is, and its parameters, ending with a NULL
 * name. */
typedef struct {
    const char *name;
    const char *summary;
    const ss_param *params;
} ss_param_table;

/* The table named `name`, or NULL. */
SS_API const ss_param_table *ss_param_table_named(const char *name);
/* The word of choice `index` of parameter `param` of table `table` into
 * buf ("" where there is none); returns buf. */
SS_API const char *ss_param_choice(const char *table, const char *param, int index, char *buf,
                                   size_t size);

/* ---- what every sweeping product takes ("sweep") ---------------------------- */

typedef struct {
    int directions;               /* 0: the planner chooses from svf_tolerance */
    double offset_deg;
    int north;                    /* "auto|true|grid" */
    int curvature;                /* "auto|on|off" */
    double refraction_k;
    double earth_radius_m;        /* 0: the ellipsoid's at the DEM's centre */
    double horizon_tolerance_deg, svf_tolerance, sun_tolerance_deg;
    int lines;                    /* "auto|interpolated|digital|box" (ss_line_model + 1) */
    int box_lines;                /* box lines per cell across; 0: the planner chooses */
    int box_shadows;              /* "march|lines" (ss_box_shadows) */
    int box_sky;                  /* "march|lines" (ss_box_sky) */
} ss_sweep_params;
#define SS_NORTH_AUTO 0
#define SS_NORTH_TRUE 1
#define SS_NORTH_GRID 2
/* The indices of every "auto|on|off" choice (curvature, sun_per_cell). */
#define SS_CHOICE_AUTO 0
#define SS_CHOICE_ON 1
#define SS_CHOICE_OFF 2

/* ---- the sun of a shadow, a hillshade's light, a render ("sun") -------------- */

typedef struct {
    const char *time;             /* ISO 8601 instant, or NULL */
    double sun_azimuth_deg, sun_elevation_deg; /* given instead of a time; NAN if not */
    int sun_per_cell;             /* "auto|on|off" */
    double delta_t_s;             /* NAN: the model */
    double pressure_hpa, temperature_c;
} ss_sun_params;
/* Marks the sun's optional numbers as not given (NAN): before parsing. */
SS_API void ss_sun_params_init(ss_sun_params *p);
/* Checks that the sun is given one way: as an instant (*unix_s gets it)
 * or as an azimuth and an elevation (*unix_s gets NAN). SS_ERR_ARGUMENT,
 * naming what is missing or doubled, otherwise. */
SS_API ss_status ss_sun_params_check(ss_ctx *ctx, const ss_sun_params *p, double *unix_s);
/* SPA's parameters from the sun's. */
SS_API void ss_sun_params_spa(const ss_sun_params *p, ss_spa_params *spa);
/* The line model asked for (SS_LINES_AUTO: the planner's choice). */
SS_API ss_line_model ss_sweep_params_lines(const ss_sweep_params *p);
/* What the planner is asked for a sweeping product: the sweep's tolerances,
 * curvature, true north, refraction, directions and lines, and the sun per
 * cell from sun (NULL: one sun for the grid), as the parameters give them.
 * The caller adds the product and what the job adds (its SVF definition,
 * radius, steps, weather). */
SS_API void ss_sweep_params_request(const ss_sweep_params *p, const ss_sun_params *sun,
                                    ss_plan_request *req);
/* The sweep options the parameters ask for before a plan decides (the
 * front ends' provisional options; ss_product_prepare then obeys the plan):
 * the directions asked (32 where the planner chooses), offset, lines
 * (interpolated for auto), box lines (SS_BOX_LINES_DEFAULT where the
 * planner chooses), curvature only where turned on
 * (the parameters' earth radius, else the place's, with their refraction)
 * and the place's grid north unless north is the grid's. place NULL: a
 * grid without a place (an array): the earth's mean radius, grid north. */
SS_API void ss_sweep_params_options(const ss_sweep_params *p, const ss_place *place,
                                    ss_sweep_options *opt);
/* The most box lines per cell a plan of these parameters can take, for
 * sizing memory before the plan is made: those given, else the larger of
 * SS_BOX_LINES_DEFAULT and the sky view's choice from svf_tolerance. */
SS_API int ss_sweep_params_box_lines_most(const ss_sweep_params *p);
/* The box lines per cell insolation's sky view takes where its exact
 * shadows are each cell's own ray (the plan's sky_box_lines, else its box
 * lines): those given, else the fewer of SS_BOX_LINES_DEFAULT and the
 * count the SVF table gives svf_tolerance. */
SS_API int ss_sweep_params_sky_box_lines(const ss_sweep_params *p);

/* ---- sky-view factor ("svf") and openness ("openness") ------------------------ */

typedef struct {
    int definition;  /* "geometric|radiative|horizontal" */
    double radius_m; /* 0: unlimited */
} ss_svf_params;
SS_API ss_sky_term ss_svf_params_term(const ss_svf_params *p);

typedef struct {
    int kind;        /* "positive|negative" */
    double radius_m; /* 0: unlimited */
} ss_openness_params;
SS_API ss_sky_term ss_openness_params_term(const ss_openness_params *p);

/* ---- hillshade ("hillshade") --------------------------------------------------- */

typedef struct {
    double azimuth_deg, altitude_deg, z_factor;
    int alg;                  /* "Horn|ZevenbergenThorne" */
    int multidirectional, cast_shadows;
    double sky_view;
    int blend;                /* "none|vat" */
    double blend_radius_cells;
} ss_hillshade_params;
/* The indices of alg's and blend's choices. */
#define SS_HILLSHADE_ALG_HORN 0
#define SS_HILLSHADE_ALG_ZEVENBERGEN_THORNE 1
#define SS_HILLSHADE_BLEND_NONE 0
#define SS_HILLSHADE_BLEND_VAT 1
/* The shading's options, the blend's radius from cells to metres. */
SS_API void ss_hillshade_params_options(const ss_hillshade_params *p, double cell_size_m,
                                        ss_hillshade_options *out);
/* What the planner is asked to plan: plain shading reads no horizons
 * (SS_PLAN_NO_SWEEP); cast shadows sweep along the light
 * (SS_PLAN_SHADOW); sky view and the VAT blend sweep around the sky
 * (SS_PLAN_SKY_VIEW). */
SS_API ss_plan_kind ss_hillshade_params_plan_kind(const ss_hillshade_params *p);

/* ---- insolation ("insolation") ------------------------------------------------- */

typedef struct {
    const char *step;           /* ISO 8601 duration of a clear-sky step */
    const char *linke;          /* one turbidity, or twelve for January..December */
    double albedo;
    int shadow;                 /* "auto|exact|interpolated|cumulative" */
    double tolerance_percent;   /* the cumulative sky's error allowed (p95) */
    double elevation_step_deg;
    double solar_constant;      /* W/m^2 at 1 AU */
    int sky_model;              /* "perez|haydavies|isotropic" */
    const char *surface;        /* cell|horizontal|TILT,AZIMUTH */
    int pv;
    double gamma_pdc;
    int temperature_model;      /* "faiman|sapm" */
    double losses_percent, temp_air_c, wind_speed_m_s;
    double inverter_efficiency_percent, dc_ac_ratio;
} ss_insolation_params;
/* The shadow mode asked for (SS_SHADOW_AUTO: the planner's choice). */
SS_API ss_shadow_mode ss_insolation_params_shadow(const ss_insolation_params *p);
/* The run's options, with the shadow mode the plan chose; the surface is
 * read from its text (one line naming the parameter where it cannot be). */
SS_API ss_status ss_insolation_params_options(ss_ctx *ctx, const ss_insolation_params *p,
                                              ss_shadow_mode shadow, ss_insolation_options *out);
/* The Linke turbidity of each month from the text. */
SS_API ss_status ss_insolation_params_linke(ss_ctx *ctx, const ss_insolation_params *p,
                                            double linke[12]);
/* The names the run's metadata and summary give its choices. */
SS_API const char *ss_sky_model_name(ss_sky_model model);
SS_API const char *ss_shadow_mode_name(ss_shadow_mode mode);

#ifdef __cplusplus
}
#endif
#endif
