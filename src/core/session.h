/* A sweep session: one grid on one device (OpenCL or the C twin), a hull
 * stack grid, and up to three float output grids that passes write into.
 * Products queue passes direction by direction and read outputs back. */
#ifndef SS_SESSION_H
#define SS_SESSION_H

#include "ctx_internal.h"
#include "ss_lines.h"

#define SS_SESSION_MAX_OUTPUTS 3

typedef struct ss_session ss_session;

typedef struct {
    ss_status (*clear)(ss_session *s, int output);
    ss_status (*svf)(ss_session *s, const ss_line_set *ls, int definition, float curv_k,
                     float sin_az, float cos_az);
    ss_status (*horizon)(ss_session *s, const ss_line_set *ls, float curv_k, float none_deg,
                         int want);
    ss_status (*bare)(ss_session *s, const ss_line_set *ls);
    ss_status (*radius_terms)(ss_session *s, const ss_line_set *ls, int definition,
                              float radius_m, float curv_k);
    ss_status (*view)(ss_session *s, int output, float **host);
    void (*close)(ss_session *s);
} ss_backend;

struct ss_session {
    ss_ctx *ctx;
    const ss_grid *grid;
    int n_outputs;
    const ss_backend *backend;
    void *impl;
};

ss_status ss_session_open(ss_ctx *ctx, const ss_grid *grid, int n_outputs, ss_session **out);
void ss_session_close(ss_session *s);
ss_status ss_session_clear(ss_session *s, int output);
/* Adds one direction's SVF term into output 0. */
ss_status ss_session_svf(ss_session *s, const ss_line_set *ls, int definition, float curv_k,
                         double azimuth_rad);
/* Sets output 0 to horizon angles (degrees): each cell's weighted mean over
 * the samples feeding it that have terrain ahead, weights renormalised, and
 * exactly none_deg where none has (ss_pass_horizon_walk). With
 * SS_HORIZON_WANT_DIST in want, sets output 1 to distances, from the nearer
 * such sample, 0 where none has; with SS_HORIZON_WANT_CAST too, output 2 to
 * the heights of those samples' casting points (grid origin). Clear the
 * outputs first. The backend keeps one more float grid, of weights. */
ss_status ss_session_horizon(ss_session *s, const ss_line_set *ls, float curv_k, float none_deg,
                             int want);
/* Adds a term (SS_TERM_ELEVATION, SS_SVF_GEOMETRIC or SS_SVF_HORIZONTAL)
 * of the horizon within radius_m into output 0. */
ss_status ss_session_radius_terms(ss_session *s, const ss_line_set *ls, int definition,
                                  float radius_m, float curv_k);
/* out0[c] += z[c] along the lines. */
ss_status ss_session_bare(ss_session *s, const ss_line_set *ls);
/* Waits for queued passes; *host (readable and writable) stays valid until
 * the next call. */
ss_status ss_session_view(ss_session *s, int output, float **host);

/* The surface gradient of every cell for the radiative SVF: out[2c] =
 * dz/de, out[2c + 1] = dz/dn by Horn's formula (ss_gradient_horn), 0 at
 * nodata cells; 2 * width * height floats. Computed once per session
 * instead of for both cells of every sample of every direction. */
void ss_gradient_grid(const ss_grid *g, float *out);

/* Backends. */
ss_status ss_backend_ref_open(ss_session *s);
ss_status ss_backend_ocl_open(ss_session *s);

#endif
