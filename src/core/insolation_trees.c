/* Trees in insolation's steps (insolation_trees.h). */
#include "config.h"

#include <math.h>

#include "insolation_trees.h"

ss_status ss_insolation_trees_check(ss_ctx *ctx, const ss_insolation_options *io,
                                    const ss_source *src)
{
    const ss_insolation_trees *t = io->trees;
    if (!t->ground || !t->canopy || t->ground->width != src->width ||
        t->ground->height != src->height)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "insolation's trees need the DSM and a canopy on the run's grid");
    if (!(t->transmissivity_leaf_off >= 0 && t->transmissivity_leaf_off <= 1))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "the leaf-off transmissivity %g is outside 0..1",
                       t->transmissivity_leaf_off);
    return ss_canopy_check(ctx, t->ground, t->canopy);
}

float ss_insolation_trees_transmissivity(const ss_insolation_trees *t, int k)
{
    return (float)(t->leaf_off && t->leaf_off[k] ? t->transmissivity_leaf_off
                                                 : t->canopy->transmissivity);
}

void ss_insolation_trees_terms(const ss_insolation_trees *t, const ss_band_view *band, float T,
                               const ss_cell_terms *in, ss_cell_terms *out)
{
    size_t n = (size_t)band->n_rows * band->width, at = (size_t)band->row0 * band->width;
    for (size_t c = 0; c < n; ++c) {
        out[c] = in[c];
        float hidden = t->sky_hidden ? t->sky_hidden[at + c] : 0.0f;
        if (hidden > 0.0f && hidden != SS_NODATA)
            out[c].sky_view = fmaxf(in[c].sky_view - hidden * (1.0f - T), 0.0f);
    }
}

ss_status ss_insolation_trees_crossed(ss_ctx *ctx, const ss_insolation_trees *t,
                                      const ss_sweep_options *opt, const ss_sun_step *sun,
                                      unsigned char *crossed)
{
    return ss_insolation_trees_crossed_at(ctx, t, opt, sun->grid_azimuth_deg,
                                          sun->apparent_elevation_deg, crossed);
}

ss_status ss_insolation_trees_crossed_at(ss_ctx *ctx, const ss_insolation_trees *t,
                                         const ss_sweep_options *opt, double grid_azimuth_deg,
                                         double apparent_elevation_deg, unsigned char *crossed)
{
    ss_sweep_options lines = *opt;
    if (t->digital_lines)
        lines.lines = SS_LINES_DIGITAL;
    return ss_canopy_crossed(ctx, t->ground, t->canopy, &lines, grid_azimuth_deg,
                             apparent_elevation_deg, crossed);
}
