/* The sweep backends: the C twin (backend_ref.c) and OpenCL
 * (backend_ocl.c) walk a band's lines for a batch of directions, from the
 * same kernel headers (kernels/ss_passes.h, ss_band.h). The driver
 * (engine.c) decides bands, passes and batches; a backend holds the band's
 * buffers and the hulls handed on between bands. */
#ifndef SS_BACKEND_H
#define SS_BACKEND_H

#include "ctx_internal.h"
#include "ss_band.h"
#include "ss_insolation_cells.h"

/* A run without a walk: the driver only visits the bands (per-cell
 * products, and products finished from what earlier runs stored). */
#define SS_TERM_NONE (-1)

/* What every sample of a run's walk hands over (one enum for the
 * per-sample terms, kernels/ss_terms.h): a summed term (SS_SVF_*,
 * SS_TERM_ELEVATION; radius_m > 0 for the highest terrain within it), added
 * over the directions into one grid of sums, or SS_TERM_HORIZON, one grid
 * of angles (with want's distances and casting heights) per direction. */
typedef struct {
    int term;
    int want;       /* SS_TERM_HORIZON: SS_HORIZON_WANT_* bits */
    float none_deg; /* SS_TERM_HORIZON: where no terrain lies ahead */
    double radius_m;
    int negate;     /* heights read as -z (negative openness) */
    /* SS_TERM_HORIZON for shadows alone: each cell's bound
     * level per sector of azimuth (lit_levels.h), so that the walks stop past the last cell a
     * direction's sun may not clear (ss_engine_dir.lit_level), on every
     * backend; NULL: whole walks. The C twin counts the samples it leaves
     * (ss_counters.shadow_steps_skipped). */
    const unsigned char *lit_levels;
    /* The same in bands (lit_levels.h): the driver reads each band's into
     * lit_levels before its walks, and a device's load takes them with the
     * band's heights. */
    struct ss_lit_bands *lit_bands;
} ss_walk;

/* Output planes per direction of a horizon walk: angle sums, weights, and
 * distances and casting heights where wanted (ss_horizon_steps). */
int ss_walk_planes(const ss_walk *walk);

typedef struct ss_backend ss_backend;

typedef struct {
    /* Makes a band current: its held rows' heights (NaN at nodata) and,
     * for the radiative SVF, their gradients (2 floats a cell), which the
     * caller keeps unchanged until the next load (the C twin reads them in
     * place; a device copies them). */
    ss_status (*load)(ss_backend *b, const ss_band_run *run, const float *z, const float *grad);
    /* Starts a pass over the bands for directions with n_lines lines in
     * all: every line's hull is empty, every row carried between bands 0. */
    ss_status (*pass_begin)(ss_backend *b, int n_lines);
    /* Summed walks: the band's sums start at 0, with the rows carried in
     * from the band before (pass: the visit's). */
    ss_status (*sums_begin)(ss_backend *b, const ss_band_run *run, int pass);
    /* Walks the n directions of a batch (their slots 0..n-1) over the
     * band's lines, both rounds, handing hulls on; horizon walks end with
     * every slot's angles finished over the band's own rows. */
    ss_status (*walk)(ss_backend *b, const ss_band_run *run, const ss_band_dir *dirs, int n);
    /* Summed walks: carries the fed row on and gives the band's own rows
     * of sums (readable and writable until the next call). */
    ss_status (*sums_end)(ss_backend *b, const ss_band_run *run, int pass, float **own);
    /* Horizon walks: plane p of slot's own rows (as sums_end's). */
    ss_status (*view)(ss_backend *b, const ss_band_run *run, int slot, int plane, float **own);
    /* Ends a band visit: what it handed on becomes the next band's input;
     * the handoffs are added to stats. */
    ss_status (*hulls_swap)(ss_backend *b, ss_band_stats *stats);
    /* The bare pass (whole grid, one direction): out[c] += weighted heights. */
    ss_status (*bare)(ss_backend *b, const ss_band_run *run, const ss_band_dir *dir,
                      float **out);
    void (*close)(ss_backend *b);
    /* Insolation's steps on the device, where the backend has them (NULL:
     * the C twin, whose consumer computes them in place). cells_begin
     * takes the band's own cells' terms and zeroes `planes` planes over
     * them, and takes interpolated shadows' stored horizons where given
     * (stored_planes planes of the own cells, stored_stride cells apart on
     * the host); cells_step adds a step (kernels/ss_insolation_cells.h)
     * with batch slot `slot`'s horizons (or -1), its suns from the lattice
     * where given, and reads the step's own global back to step_out where
     * given; cells_end adds the planes into the host's. */
    ss_status (*cells_begin)(ss_backend *b, const ss_band_run *run, const ss_cell_terms *terms,
                             int planes, const int16_t *stored, int stored_planes,
                             size_t stored_stride);
    ss_status (*cells_step)(ss_backend *b, const ss_band_run *run, int slot,
                            const ss_cells_step *step, const ss_sun_lattice *lattice,
                            float *step_out);
    ss_status (*cells_end)(ss_backend *b, const ss_band_run *run, float *planes);
} ss_backend_ops;

struct ss_backend {
    ss_ctx *ctx;
    const ss_backend_ops *ops;
    ss_walk walk;
    int width, max_held_rows; /* the largest band's buffers */
    int stack_per_cell;       /* stack grid slots per held cell (ss_band_run's: box lines
                                 and radius walks with hulls take more than one) */
    int batch;                /* directions per batch: asked for, lowered by open to fit */
    int carried;              /* rows of sums kept between bands (0: the whole grid) */
    const float *whole_z;     /* the whole grid, used in place (NULL in bands) */
    int device_cells;         /* runs insolation's steps itself (cells_*, ss_ctx_set_cells) ... */
    size_t cells_max_bytes;   /* ... where a band's cell buffers together fit in this */
    void *impl;
};

/* Opens the context's device for b (its fields above set): the C twin or
 * OpenCL. */
ss_status ss_backend_open(ss_backend *b);
ss_status ss_backend_ref_open(ss_backend *b);
ss_status ss_backend_ocl_open(ss_backend *b);
/* The floats of the rows kept between bands: a row per plane and
 * direction carried. */
size_t ss_backend_carry_floats(const ss_backend *b);

/* The surface gradient of every cell for the radiative SVF: out[2c] =
 * dz/de, out[2c + 1] = dz/dn by Horn's formula (ss_gradient_horn), 0 at
 * nodata cells; 2 * width * height floats. */
void ss_gradient_grid(const ss_grid *g, float *out);

#endif
