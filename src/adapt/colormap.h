/* Named colour maps for quicklooks and 3D drapes: small tables of control
 * points, linearly interpolated in sRGB. */
#ifndef SS_COLORMAP_H
#define SS_COLORMAP_H

#ifdef __cplusplus
extern "C" {
#endif

/* The known names, comma-separated, for help texts and error messages. */
#define SS_COLORMAP_NAMES "grey, viridis, magma, terrain, svf"

/* Colour of t01 in [0, 1] (clamped; NaN counts as 0) in the named map. A name
 * that is not known (see ss_colormap_known) gives the grey map, so callers
 * check names where they are parsed, not per cell. */
void ss_colormap_rgb(const char *name, double t01, unsigned char rgb[3]);

/* Nonzero when name is one of SS_COLORMAP_NAMES (case-sensitive). */
int ss_colormap_known(const char *name);

#ifdef __cplusplus
}
#endif
#endif
