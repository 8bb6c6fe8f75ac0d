/* skysweep: the product registry. Every product the library makes from a
 * DEM is declared here once: its name and summary, its parameter tables
 * (skysweep_params.h), its outputs (name, unit, bands, optional or not),
 * what it asks the planner, what a cell of a band costs, the halo it
 * reads, and the call that runs it. The command line's product commands
 * and command list, `skysweep COMMAND --help-json` (its "outputs"), the
 * Python package and the QGIS provider derive each product from it
 * (doc/engine.md, "Product registry"). The built-in table is read-only;
 * ss_product_register adds to it. */
#ifndef SKYSWEEP_PRODUCTS_H
#define SKYSWEEP_PRODUCTS_H

#include "skysweep.h"
#include "skysweep_params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One output of a product: a raster the product writes. */
typedef struct {
    const char *name;       /* "svf", "distance": for a front end's parameter */
    const char *option;     /* NULL: the command's OUTPUT argument; else the option that names
                               the file, "distance" for --distance FILE */
    const char *unit;       /* "1", "deg", "m", "Wh/m2" (the bands' GDAL unit); "" where none */
    int bands;              /* its band count; 0: one band per direction or time step */
    const char *band_names; /* '|'-separated, the bands' GDAL descriptions where bands > 0;
                               with bands 0, the pattern of each band's ("azimuth DEG") */
    int optional;           /* written only when its option is given */
} ss_product_output;

/* What a product that needs a sun (group "Sun": shadow, insolation) runs
 * with besides its parameters; the others take NULL. */
typedef struct {
    int n_steps;             /* its time steps; shadow's one sun is step 0 */
    ss_sun_rows_fn sun_rows; /* each step's sun for the rows of a band */
    void *sun_user;
    int real_sky;               /* the steps are weather records: the months' sums besides */
    ss_shadow_mode shadow_mode; /* insolation's shadows: the plan's (ss_plan's shadow_mode) */
    const struct ss_insolation_trees_s *trees; /* insolation's trees (NULL: none) */
} ss_product_sun;

/* Runs a product on src into sink (output i of the product's outputs is
 * the sink's output i): params is the struct of the product's own
 * parameter table (NULL for a product without one), sun its steps' suns
 * (NULL for a product that needs none), outputs the bits (1 << i) of the
 * optional outputs asked for, share (may be NULL) deals out its
 * directions or time steps where the product shares (`shares`). */
typedef ss_status (*ss_product_run_fn)(ss_ctx *ctx, const ss_source *src,
                                       const ss_sweep_options *opt, const void *params,
                                       const ss_product_sun *sun, unsigned outputs,
                                       const ss_share *share, ss_rows_sink sink, void *user);

typedef struct {
    const char *name;        /* "svf": its command, scene key and Python function */
    const char *summary;     /* one line: the command list's, `skysweep --help` */
    const char *title;       /* "Sky-view factor": a front end's label for it */
    const char *group;       /* "Terrain" or "Sun" (it needs a sun): a front end's group */
    const char *description; /* what the command's --help says it makes ('\n' breaks lines) */
    /* Its parameter tables (skysweep_params.h): its own (NULL: none), whose struct is what
     * `run`, `cell_bytes`, `halo_m` and `request` take (NULL for a product without one),
     * and the shared ones it takes besides ("sweep", "sun"), NULL-ended. */
    const char *own_table;
    const char *const *tables;
    size_t params_size; /* bytes of the product's own table's struct; 0: it has none */
    const ss_product_output *outputs; /* NULL name ends them; output 0 is OUTPUT */
    ss_plan_kind plans_as;            /* what the planner weighs it as at the parameters' defaults */
    int shares;                       /* its directions or time steps can be dealt out (MPI) */
    /* Fills what the parameters add to a plan request, on cells of cell_size_m (NAN before
     * the DEM is read): the planner's kind of job, and where they set them the SVF
     * definition, the radius and the shadow mode. */
    void (*request)(const void *params, double cell_size_m, ss_plan_request *req);
    /* Bytes the product holds per cell of a band, halo rows included, for the optional
     * outputs asked for (bits as `run`'s): the least, at a sweep's own needs; a run that
     * stores horizons between its walks (insolation's interpolated shadows and cumulative
     * sky) adds ss_insolation_band_cell_bytes' share for them. */
    double (*cell_bytes)(const void *params, unsigned outputs);
    /* Metres of terrain beyond a band it reads (its radius), on cells of cell_size_m (NAN
     * before the DEM is read: a radius in metres does not need it); 0: the sweep's own halo. */
    double (*halo_m)(const void *params, double cell_size_m);
    /* Runs it (every built-in product has one; a registered one without it has no
     * command of its own). */
    ss_product_run_fn run;
} ss_product_info;

/* What a run of a product takes besides its own parameters, for
 * ss_product_prepare. */
typedef struct {
    const ss_sweep_params *sweep; /* the "sweep" table's parameters */
    const ss_sun_params *sun;     /* the "sun" table's (its sun per cell); NULL: one sun */
    /* Where the grid lies (the CLI's frame); NULL: a grid without a place (an array):
     * grid azimuths, the grid's diagonal, the earth's mean radius unless sweep gives one. */
    const ss_place *place;
    int n_steps;                /* time steps (shadow, insolation) ... */
    const double *step_unix_s;  /* ... and the instants they are evaluated at */
    ss_plan_weather weather;    /* insolation from weather records; zeros: the clear sky */
} ss_product_job;

/* The one translation of a product's parameters into a run: asks the
 * planner (ss_plan_make) what the parameters, the sweep's and the job's
 * ask for on this grid, fills *opt with the sweep options that obey the
 * plan (ss_sweep_params_options, then ss_plan_sweep_options) and checks
 * them, and opens the device the plan chose on an "auto" context
 * (ss_ctx_apply_plan). params is the struct of the product's own table
 * (NULL for a product without one). The CLI's commands and the Python
 * package both call it. */
SS_API ss_status ss_product_prepare(ss_ctx *ctx, const ss_product_info *product,
                                    const void *params, const ss_grid *grid,
                                    const ss_product_job *job, ss_sweep_options *opt,
                                    ss_plan *plan);

/* How many products the registry holds. */
SS_API int ss_product_count(void);
/* Product i (0 <= i < ss_product_count()), or NULL. */
SS_API const ss_product_info *ss_product_at(int i);
/* The product named `name`, or NULL. */
SS_API const ss_product_info *ss_product_named(const char *name);
/* Adds a product declared outside the library (a plug-in, a test's
 * product) after the built-in ones: every front end then
 * finds it as it finds them (the CLI runs one with a run call as a
 * command of its own). The entry must live as long as the process. Call
 * it before the registry is read from another thread (a plug-in's
 * constructor). SS_ERR_ARGUMENT for an entry without a name, outputs,
 * request, cell cost or halo, or whose name is taken; SS_ERR_MEMORY when
 * the room for 8 is full. */
SS_API ss_status ss_product_register(const ss_product_info *product);

#ifdef __cplusplus
}
#endif
#endif
