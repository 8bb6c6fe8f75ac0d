/* The product registry (skysweep_products.h): each product declared once,
 * pointing at the parameter tables (params.c), the band costs
 * (band_memory.c) and the rows calls that exist for it. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "skysweep_products.h"

/* ---- what each product's parameters become ---------------------------------- */

static void svf_request(const void *params, double cell_size_m, ss_plan_request *req)
{
    (void)cell_size_m;
    const ss_svf_params *p = params;
    req->kind = SS_PLAN_SKY_VIEW;
    req->svf_definition = (ss_svf_definition)ss_svf_params_term(p);
    req->radius_m = p->radius_m;
    req->sky_walk = 1;
}

static double svf_cell_bytes(const void *params, unsigned outputs)
{
    (void)outputs;
    return ss_sky_band_cell_bytes(ss_svf_params_term(params));
}

static double svf_halo_m(const void *params, double cell_size_m)
{
    (void)cell_size_m;
    return ((const ss_svf_params *)params)->radius_m;
}

static ss_status svf_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                         const void *params, const ss_product_sun *sun, unsigned outputs,
                         const ss_share *share, ss_rows_sink sink, void *user)
{
    (void)sun, (void)outputs;
    const ss_svf_params *p = params;
    return ss_sky_rows(ctx, src, opt, ss_svf_params_term(p), p->radius_m, share, sink, user);
}

/* Openness reads horizons, not an SVF: the planner's horizon product. */
static void openness_request(const void *params, double cell_size_m, ss_plan_request *req)
{
    (void)cell_size_m;
    req->kind = SS_PLAN_HORIZONS;
    req->radius_m = ((const ss_openness_params *)params)->radius_m;
    req->sky_walk = 1;
}

static double openness_cell_bytes(const void *params, unsigned outputs)
{
    (void)params, (void)outputs;
    return ss_sky_band_cell_bytes(SS_SKY_OPENNESS_POSITIVE); /* either kind's */
}

static double openness_halo_m(const void *params, double cell_size_m)
{
    (void)cell_size_m;
    return ((const ss_openness_params *)params)->radius_m;
}

static ss_status openness_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                              const void *params, const ss_product_sun *sun, unsigned outputs,
                              const ss_share *share, ss_rows_sink sink, void *user)
{
    (void)sun, (void)outputs;
    const ss_openness_params *p = params;
    return ss_sky_rows(ctx, src, opt, ss_openness_params_term(p), p->radius_m, share, sink, user);
}

static void horizon_request(const void *params, double cell_size_m, ss_plan_request *req)
{
    (void)params, (void)cell_size_m;
    req->kind = SS_PLAN_HORIZONS;
    req->sky_walk = 1; /* a horizon walk (horizon_walk.c) */
}

/* The optional outputs' bits (1 << SS_OUT_HORIZON_DISTANCE, ...) are
 * ss_horizon_rows' want shifted by one. */
static double horizon_cell_bytes(const void *params, unsigned outputs)
{
    (void)params;
    return ss_horizon_band_cell_bytes((int)(outputs >> 1));
}

static ss_status horizon_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                             const void *params, const ss_product_sun *sun, unsigned outputs,
                             const ss_share *share, ss_rows_sink sink, void *user)
{
    (void)params, (void)sun, (void)share; /* it does not share */
    return ss_horizon_rows(ctx, src, opt, (int)(outputs >> 1), sink, user);
}

/* A blend's horizons are radius-limited, which the plan's choice of lines weighs. */
static void hillshade_request(const void *params, double cell_size_m, ss_plan_request *req)
{
    const ss_hillshade_params *p = params;
    req->kind = ss_hillshade_params_plan_kind(p);
    if (p->blend != SS_HILLSHADE_BLEND_NONE)
        req->radius_m = p->blend_radius_cells * cell_size_m;
    req->sky_walk = p->sky_view > 0 || p->blend == SS_HILLSHADE_BLEND_VAT;
}

static int hillshade_sweeps(const ss_hillshade_params *p)
{
    return p->blend || p->cast_shadows || p->sky_view > 0;
}

/* Its heights and a row of shades, SVF and openness; sweeps add a horizon's band. */
static double hillshade_cell_bytes(const void *params, unsigned outputs)
{
    (void)outputs;
    return 16.0 + (hillshade_sweeps(params) ? ss_horizon_band_cell_bytes(0) : 4.0);
}

static double hillshade_halo_m(const void *params, double cell_size_m)
{
    const ss_hillshade_params *p = params;
    return p->blend ? p->blend_radius_cells * cell_size_m : 0.0;
}

static ss_status hillshade_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                               const void *params, const ss_product_sun *sun, unsigned outputs,
                               const ss_share *share, ss_rows_sink sink, void *user)
{
    (void)sun, (void)outputs, (void)share; /* it does not share */
    ss_hillshade_options ho;
    ss_hillshade_params_options(params, sqrt(src->cell_x_m * src->cell_y_m), &ho);
    return ss_hillshade_rows(ctx, src, opt, &ho, sink, user);
}

static void shadow_request(const void *params, double cell_size_m, ss_plan_request *req)
{
    (void)params, (void)cell_size_m;
    req->kind = SS_PLAN_SHADOW;
}

/* A horizon's band and the lit and facing rows. */
static double shadow_cell_bytes(const void *params, unsigned outputs)
{
    (void)params, (void)outputs;
    return ss_horizon_band_cell_bytes(0) + 2.0 * sizeof(float);
}

/* Where a rows call's outputs go as the entry declares them. */
typedef struct {
    ss_rows_sink sink;
    void *user;
} entry_sink;

/* ss_shadow_rows' three outputs are the bands of the entry's one. */
static ss_status shadow_bands(void *user, int output, int index, int row0, int n_rows,
                              const float *values)
{
    (void)index;
    const entry_sink *to = user;
    return to->sink(to->user, 0, output, row0, n_rows, values);
}

/* The sun's step 0, along whose azimuth it sweeps. */
static ss_status shadow_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                            const void *params, const ss_product_sun *sun, unsigned outputs,
                            const ss_share *share, ss_rows_sink sink, void *user)
{
    (void)params, (void)outputs, (void)share; /* it does not share */
    if (!sun)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "shadow needs a sun");
    entry_sink to = {sink, user};
    return ss_shadow_rows(ctx, src, opt, sun->sun_rows, sun->sun_user, shadow_bands, &to);
}

static void insolation_request(const void *params, double cell_size_m, ss_plan_request *req)
{
    (void)cell_size_m;
    req->kind = SS_PLAN_INSOLATION;
    req->shadow_mode = ss_insolation_params_shadow(params);
    req->sky_walk = 1; /* a cell's own surface's sky view, in every shadow mode */
}

/* Output 1 is the steps' (SS_INSOLATION_STEPS); weather's monthly sums and
 * stored horizons add to it (ss_insolation_band_cell_bytes). */
static double insolation_cell_bytes(const void *params, unsigned outputs)
{
    const ss_insolation_params *p = params;
    int want = (p->pv ? SS_INSOLATION_PV : 0) | (outputs & 2u ? SS_INSOLATION_STEPS : 0);
    return ss_horizon_band_cell_bytes(0) + ss_insolation_band_cell_bytes(want, 0);
}

/* ss_insolation_rows' sums are the bands of the entry's output 0 in its
 * order: the five (SS_OUT_GLOBAL .. SS_OUT_SUN_HOURS), the global of each
 * month, the PV yields DC and AC; each step's global is output 1. */
static ss_status insolation_bands(void *user, int output, int index, int row0, int n_rows,
                                  const float *values)
{
    const entry_sink *to = user;
    if (output == SS_OUT_STEP)
        return to->sink(to->user, 1, index, row0, n_rows, values);
    int band = output == SS_OUT_MONTHLY ? SS_OUT_MONTHLY + index
               : output == SS_OUT_PV    ? SS_OUT_MONTHLY + 12
               : output == SS_OUT_PV_AC ? SS_OUT_MONTHLY + 13
                                        : output;
    return to->sink(to->user, 0, band, row0, n_rows, values);
}

/* Its library options from its parameters and the run's shadows and trees;
 * weather records add the months' sums, --pv its yields, the optional
 * output 1 each step's global. */
static ss_status insolation_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                                const void *params, const ss_product_sun *sun, unsigned outputs,
                                const ss_share *share, ss_rows_sink sink, void *user)
{
    const ss_insolation_params *p = params;
    if (!sun)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "insolation needs the suns of its steps");
    ss_insolation_options io;
    ss_status st = ss_insolation_params_options(ctx, p, sun->shadow_mode, &io);
    if (st != SS_OK)
        return st;
    io.trees = sun->trees;
    int want = (sun->real_sky ? SS_INSOLATION_MONTHLY : 0) | (p->pv ? SS_INSOLATION_PV : 0) |
               (outputs & 2u ? SS_INSOLATION_STEPS : 0);
    entry_sink to = {sink, user};
    return ss_insolation_rows(ctx, src, opt, &io, sun->n_steps, sun->sun_rows, sun->sun_user, want,
                              share, insolation_bands, &to);
}

static double no_halo(const void *params, double cell_size_m)
{
    (void)params, (void)cell_size_m;
    return 0.0;
}

/* ---- the registry ------------------------------------------------------------- */

static const char *const sweep_only[] = {"sweep", NULL};
static const char *const sweep_and_sun[] = {"sweep", "sun", NULL};

/* Each list ends with an entry without a name ({0}). */
static const ss_product_output horizon_outputs[] = {
    {"horizon", NULL, "deg", 0, "azimuth DEG", 0},
    {"distance", "distance", "m", 0, "azimuth DEG", 1},
    {"cast-height", "cast-height", "m", 0, "azimuth DEG", 1},
    {0}};
static const ss_product_output svf_outputs[] = {{"svf", NULL, "1", 1, "sky-view factor", 0}, {0}};
static const ss_product_output openness_outputs[] = {
    {"openness", NULL, "deg", 1, "KIND openness", 0}, {0}};
static const ss_product_output hillshade_outputs[] = {{"hillshade", NULL, "", 1, "hillshade", 0},
                                                      {0}};
/* With --canopy two bands follow: the shadow class and the beam's fraction. */
static const ss_product_output shadow_outputs[] = {
    {"shadow", NULL, "1", 3,
     "sunlit (1) or in a cast shadow (0)|facing the sun (1) or away from it (0)|"
     "illumination cos(incidence), 0 in shadow",
     0},
    {0}};
/* sun_hours is in hours. A weather run writes 17 bands in kWh/m2 (the five
 * for the year, the global of each month) and, with --pv, two of PV yield
 * (kWh/kWp); the run's sink gets them as output 0's bands 0..18 all the
 * same, in Wh/m2 (insolation_bands). */
static const ss_product_output insolation_outputs[] = {
    {"insolation", NULL, "Wh/m2", 5, "global|beam|diffuse|reflected|sun_hours", 0},
    {"steps", "steps", "Wh/m2", 0, "the step's instant (ISO 8601)", 1},
    {0}};

static const ss_product_info products[] = {
    {"horizon", "horizon elevation angle per azimuth (one band each)", "Horizon angles", "Terrain",
     "Horizon elevation angle (degrees above the horizontal; -90 where no terrain lies ahead,\n"
     "0 on box lines, whose cells see their own flat tops)\n"
     "of every cell, one band per azimuth, exact at unlimited distance; or the horizon "
     "profiles of sites.",
     NULL, sweep_only, 0, horizon_outputs, SS_PLAN_HORIZONS, 0, horizon_request,
     horizon_cell_bytes, no_halo, horizon_run},
    {"svf", "sky-view factor (geometric, radiative or horizontal)", "Sky-view factor", "Terrain",
     "Sky-view factor of every cell (0..1), from exact horizons in evenly spaced azimuths.\n"
     "Several DEM tiles are mosaicked first. With --canopy, bands 2 svfveg (1 less the sky\n"
     "that crowns hide) and 3 svfbuveg (svf - (1 - svfveg)(1 - transmissivity)).",
     "svf", sweep_only, sizeof(ss_svf_params), svf_outputs, SS_PLAN_SKY_VIEW, 1, svf_request,
     svf_cell_bytes, svf_halo_m, svf_run},
    {"openness", "positive or negative topographic openness (degrees)", "Openness", "Terrain",
     "Topographic openness in degrees (Yokoyama et al. 2002), from horizons in evenly spaced "
     "azimuths.\nSeveral DEM tiles are mosaicked first.",
     "openness", sweep_only, sizeof(ss_openness_params), openness_outputs, SS_PLAN_HORIZONS, 1,
     openness_request, openness_cell_bytes, openness_halo_m, openness_run},
    {"hillshade", "gdaldem-compatible hillshade, with cast shadows and sky view", "Hillshade",
     "Terrain",
     "Shaded relief as gdaldem hillshade computes it (Byte 1..255, 0 = nodata), optionally with"
     "\nexact cast shadows and sky-view shading.",
     "hillshade", sweep_only, sizeof(ss_hillshade_params), hillshade_outputs, SS_PLAN_NO_SWEEP,
     0, hillshade_request, hillshade_cell_bytes, hillshade_halo_m, hillshade_run},
    {"insolation", "clear-sky beam, diffuse, reflected irradiation, hours of sun",
     "Insolation and PV yield", "Sun",
     "Irradiation on each cell's slope with exact cast shadows. Clear sky over a time range "
     "(ESRA,\nLinke turbidity): bands 1 global, 2 beam, 3 diffuse, 4 reflected (Wh/m2), 5 "
     "hours of direct\nsun. Real sky from a weather file: the same five (kWh/m2, hours) for "
     "the year, then the\nglobal of each month.",
     "insolation", sweep_and_sun, sizeof(ss_insolation_params), insolation_outputs,
     SS_PLAN_INSOLATION, 1, insolation_request, insolation_cell_bytes, no_halo, insolation_run},
    {"shadow", "cast shadows and self-shadow for one sun (exact sweep)", "Cast shadows", "Sun",
     "Cast shadows for one sun, by an exact sweep along its azimuth. Bands: 1 sunlit (1) or in "
     "a cast\nshadow (0); 2 facing the sun (1) or away (self-shadow, 0); 3 illumination cos(i) "
     "on sunlit cells facing\nthe sun, else 0 (shaded relief with cast shadows). With "
     "--canopy: 4 lit (0), solid\nshadow (1) or vegetation shadow (2); 5 fraction of the beam "
     "that arrives.",
     NULL, sweep_and_sun, 0, shadow_outputs, SS_PLAN_SHADOW, 0, shadow_request,
     shadow_cell_bytes, no_halo, shadow_run},
};

/* Products registered at run time (ss_product_register), after the table's. */
enum { REGISTERED_MAX = 8 };
static const ss_product_info *registered[REGISTERED_MAX];
static int n_registered;

static int built_in(void)
{
    return (int)(sizeof products / sizeof products[0]);
}

int ss_product_count(void)
{
    return built_in() + n_registered;
}

const ss_product_info *ss_product_at(int i)
{
    return i < 0 || i >= ss_product_count() ? NULL
           : i < built_in()                 ? &products[i]
                                            : registered[i - built_in()];
}

const ss_product_info *ss_product_named(const char *name)
{
    for (int i = 0; name && i < ss_product_count(); ++i)
        if (strcmp(ss_product_at(i)->name, name) == 0)
            return ss_product_at(i);
    return NULL;
}

ss_status ss_product_register(const ss_product_info *product)
{
    if (!product || !product->name || !product->outputs || !product->request ||
        !product->cell_bytes || !product->halo_m || ss_product_named(product->name))
        return SS_ERR_ARGUMENT;
    if (n_registered == REGISTERED_MAX)
        return SS_ERR_MEMORY;
    registered[n_registered++] = product;
    return SS_OK;
}
