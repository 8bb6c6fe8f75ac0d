/* The one sweep driver. Every product runs through ss_engine_run, on every
 * DEM size and every device: the DEM is walked in bands of rows (the whole
 * grid is the case of one band), a band's lines for a batch of directions
 * at a time on the context's backend, each line's hull handed on exactly
 * from band to band (kernels/ss_band.h). What a product makes of the walk
 * is its consumer: what it takes from each sample (the walk, backend.h),
 * what it keeps per cell (planes), and what it does with each direction's
 * rows and with each band once complete. */
#ifndef SS_ENGINE_H
#define SS_ENGINE_H

#include "backend.h"

/* Where a consumer's steps run on the device (ss_engine_cells_*). */
typedef struct ss_engine_device ss_engine_device;

/* A band as a consumer sees it. */
typedef struct {
    int row0, n_rows;   /* the band's own rows */
    int lo, held_rows;  /* the rows held in z, from row lo */
    int width, height;  /* the grid's */
    const float *z;     /* the held rows' heights: NaN at nodata, relative to the source's
                           origin, negated for negate walks */
    const float *own_z; /* z at row0 */
    /* A consumer with device_cells whose backend can run its steps: where
     * they run (ss_engine_cells_*); NULL: on the host. */
    ss_engine_device *device;
} ss_band_view;

/* One direction's horizon over the band's own rows (finished: degrees,
 * the walk's none_deg where no terrain lies ahead, garbage at nodata), its
 * distances and casting heights where the walk wants them, else NULL. A
 * consumer may overwrite them. */
typedef struct {
    float *angle, *dist, *cast;
    int slot; /* the direction's place in its batch, for ss_engine_cells_step */
} ss_dir_rows;

typedef struct {
    /* Per-cell float planes over the band's own rows that the driver keeps
     * for the consumer: zero at each visit of a band, what earlier visits
     * (passes, groups of directions) left added in at the end of each, and
     * complete at the band's last. A summed walk's sums are its one plane. */
    int planes;
    /* A visit of a band begins (may be NULL). */
    ss_status (*visit)(void *user, const ss_band_view *band);
    /* A direction in its turn (horizon walks, and directions without a walk,
     * whose rows are NULL); may be NULL for summed walks. */
    ss_status (*direction)(void *user, int index, const ss_band_view *band,
                           const ss_dir_rows *rows, float *planes);
    /* The band's last visit has ended: its planes are complete. */
    ss_status (*finish)(void *user, const ss_band_view *band, float *planes);
    /* Insolation's steps can run on the device: where the backend can, a
     * band's view has a device and its directions come with their rows
     * left there (NULL), for the consumer to add there or read back ... */
    int device_cells;
    /* ... with this many int16 planes per own cell held there too
     * (interpolated shadows' stored horizons, ss_engine_cells_begin). */
    int device_stored;
} ss_consumer;

typedef struct {
    double azimuth_deg; /* the options' frame */
    int walk;           /* 0: the consumer sees it in its turn without a walk */
    int index;          /* what the consumer is told */
    /* With the walk's lit_levels or lit_bands: cells of this bound level or below have
     * every horizon below the direction's sun, so their angles may be any
     * such horizon (-1: none). */
    int lit_level;
} ss_engine_dir;

typedef struct {
    ss_walk walk;
    const ss_engine_dir *dirs;
    int n_dirs;
    /* In bands, every line's hull of a direction is held from band to band:
     * directions go in groups of at most this many (0: all at once). */
    int group;
    const ss_consumer *consumer;
    void *user;
    const char *what; /* names the run in progress reports */
} ss_engine_job;

/* A visit's steps on the device (backend.h's cells_*): the band's own
 * cells' terms, `planes` planes set to zero there, and the consumer's
 * device_stored planes of interpolated shadows' stored horizons (own
 * cells, stored_stride cells apart; NULL where it has none); a step added
 * there with the direction's horizons (rows) or none (NULL), its own
 * global read back to step_out where given (NULL: not read); what was
 * added there joins the consumer's planes when the visit's directions are
 * done. ss_engine_device_rows reads a direction's rows to the host
 * instead, for a step the consumer computes itself. */
ss_status ss_engine_cells_begin(ss_engine_device *d, const ss_cell_terms *terms, int planes,
                                const int16_t *stored, size_t stored_stride);
ss_status ss_engine_cells_step(ss_engine_device *d, const ss_dir_rows *rows,
                               const ss_cells_step *step, const ss_sun_lattice *lattice,
                               float *step_out);
ss_status ss_engine_device_rows(ss_engine_device *d, ss_dir_rows *rows);

/* Checks a source: sizes, cell sizes, heights or a reader. */
ss_status ss_source_check(ss_ctx *ctx, const ss_source *src);

/* Runs a job over the source; src and opt as checked by the product's
 * public call (ss_rows_begin, or the whole-grid calls' own checks). */
ss_status ss_engine_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                        const ss_engine_job *job);

/* The rows of a source's bands: band_rows, or its height for one band. */
int ss_source_band_rows(const ss_source *src);
/* Rows [lo, lo + n) of a source's heights into out (NaN at nodata), held
 * or read; a reader that fails without a message of its own gets one. */
ss_status ss_source_read_rows(ss_ctx *ctx, const ss_source *src, int lo, int n, float *out);
/* The height of a source's stored zero, metres. */
double ss_source_origin(const ss_source *src);

/* A source for a grid held whole. */
ss_source ss_source_of_grid(const ss_grid *grid);

#endif
