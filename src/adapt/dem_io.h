/* GDAL adapter: DEMs in (any single-band raster GDAL reads, tiles mosaicked
 * in memory) and georeferenced rasters out (written to a temporary name and
 * renamed into place when complete). The only files that include GDAL. */
#ifndef SS_DEM_IO_H
#define SS_DEM_IO_H

#include "skysweep.h"

/* Which height a cell takes where tiles overlap and disagree: refuse the
 * mosaic (tiles that agree are fine), the first or last tile given with a
 * height there, or their mean. */
typedef enum { SS_OVERLAP_REFUSE, SS_OVERLAP_FIRST, SS_OVERLAP_LAST, SS_OVERLAP_MEAN } ss_overlap_rule;

/* A DEM read from files. For a geographic CRS the grid's cell sizes are NAN
 * until ss_dem_frame (frame.h) sets them from geodesy. */
typedef struct {
    ss_grid grid;
    double geotransform[6];
    char *crs_wkt;         /* NULL for a plain heightmap */
    size_t nodata_cells;   /* cells without a height: nodata value or NaN */
    size_t rejected_cells; /* heights beyond +-1e7 m, taken as nodata */
    /* Cells where overlapping tiles disagree, decided by the overlap rule
     * (counted once per pair of tiles); 0 for one file. */
    size_t overlap_cells;
    ss_overlap_rule overlap_rule; /* the rule that decided them */
    char description[600]; /* what was read, for summaries */
    /* Metres per unit of the heights as stored (they are converted to
     * metres on reading), and where that came from, for the metadata; NAN
     * where tiles of a mosaic differ (each is read in its own). */
    double z_unit_m;
    char z_unit_source[200];
    /* The part of the grid outputs cover (-projwin): columns [col0, col0 +
     * cols) and rows [row0, row0 + rows); cols == 0: the whole grid. The
     * sweep still sees the whole DEM, so horizons reach beyond it. */
    int window_col0, window_row0, window_cols, window_rows;
} ss_dem;

typedef struct {
    /* > 0: accept a raster without georeferencing as a heightmap whose cells
     * are this many metres wide. */
    double heightmap_cell_m;
    /* > 0: metres per unit of the stored heights, overriding the band's
     * unit type and the CRS's vertical axis (--z-units). */
    double z_unit_m;
    ss_overlap_rule overlap;
} ss_dem_read_options;

/* Registers GDAL's drivers once. */
void ss_gdal_init(void);
/* What the command line asks of GDAL, so that it includes no GDAL header:
 * its release name; its progress bar on the terminal (returns 1: go on);
 * a bound on its block cache. */
const char *ss_gdal_version(void);
int ss_gdal_term_progress(double complete);
void ss_gdal_limit_cache(size_t bytes);

ss_status ss_dem_read(ss_ctx *ctx, const char *const *paths, int n_paths,
                      const ss_dem_read_options *opt, ss_dem *dem);
void ss_dem_free(ss_dem *dem);

/* The same in two steps, for DEMs read in pieces (the banded sweep):
 * ss_dem_open fills dem's metadata (size, cell sizes, CRS; grid.z stays
 * NULL) and keeps the files open; ss_dem_source_read reads rows [row0,
 * row0 + n_rows) into z as ss_dem_read would (heights relative to
 * dem->grid.z_origin_m, set by the first plausible height read; nodata and
 * rejected cells counted into dem). Reads run on the opening thread. */
typedef struct ss_dem_source ss_dem_source;
ss_status ss_dem_open(ss_ctx *ctx, const char *const *paths, int n_paths,
                      const ss_dem_read_options *opt, ss_dem *dem, ss_dem_source **source);
ss_status ss_dem_source_read(ss_ctx *ctx, ss_dem_source *src, ss_dem *dem, int row0, int n_rows,
                             float *z);
void ss_dem_source_close(ss_dem_source *src);

typedef struct ss_raster_writer ss_raster_writer;

/* Sets dem's output window from -projwin's ULX ULY LRX LRY (the DEM's CRS,
 * cell edges rounded as gdal_translate -projwin does); fails if it is
 * empty or not inside the DEM. */
ss_status ss_dem_set_window(ss_ctx *ctx, ss_dem *dem, const double projwin[4]);

/* Creates OUTPUT's temporary twin with the DEM's size (or its window), CRS
 * and geotransform.
 * format NULL means GTiff; creation_options are KEY=VALUE strings (NULL-ended)
 * that override the defaults (tiled, DEFLATE, floating-point predictor). */
ss_status ss_writer_open(ss_ctx *ctx, const char *path, const ss_dem *like, int bands,
                         const char *format, const char *const *creation_options,
                         ss_raster_writer **writer);
/* The same with Byte bands (gdaldem's style for shaded reliefs): values
 * are rounded and clamped to 1..255, SS_NODATA becomes nodata 0. */
ss_status ss_writer_open_byte(ss_ctx *ctx, const char *path, const ss_dem *like, int bands,
                              const char *format, const char *const *creation_options,
                              ss_raster_writer **writer);
/* Writes band (1-based), the whole grid's values (only the window's are
 * stored): SS_NODATA marks nodata; NaN or Inf is refused. */
ss_status ss_writer_band(ss_raster_writer *w, int band, const float *data,
                         const char *description, const char *unit);
/* Writes rows [row0, row0 + n_rows) of a band, full grid rows, in any
 * order (a banded run); what falls outside the window is dropped. */
ss_status ss_writer_rows(ss_raster_writer *w, int band, int row0, int n_rows, const float *data);
void ss_writer_describe(ss_raster_writer *w, int band, const char *description, const char *unit);
ss_status ss_writer_metadata(ss_raster_writer *w, const char *key, const char *value);
/* Flushes, closes and renames the file into place. */
ss_status ss_writer_commit(ss_raster_writer *w, ss_progress_fn progress, void *user);
/* Removes the temporary file; the output path is left as it was. */
void ss_writer_abort(ss_raster_writer *w);

/* Whether an output may be written at path: a non-empty name in a folder
 * that exists and is writable, and nothing there yet but a file to
 * replace (not a folder, device, pipe or socket) that may be replaced: one
 * the user may write and that has a write bit for someone (root too is
 * refused a file of mode 444). A link is checked, and written, at its
 * target (ss_output_target). ss_writer_open checks it; a command checks
 * each of its outputs before any work. */
ss_status ss_output_check(ss_ctx *ctx, const char *path);

/* Nonzero when two paths name the same existing file. */
int ss_same_file(const char *a, const char *b);
/* Nonzero when two output paths, which need not exist yet, name the same
 * file: equal names in the same folder (links and dots resolved), or the
 * same existing file. */
int ss_same_output(const char *a, const char *b);

#endif
