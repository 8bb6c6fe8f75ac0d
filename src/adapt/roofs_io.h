/* GDAL/OGR adapter of skysweep roofs: building footprints in (any OGR
 * vector source, reprojected to the DSM's CRS, repaired or skipped one by
 * one, rasterized onto the DSM's grid), a product's bands read back, the
 * roof planes' cells as polygons, and the GeoPackage out (written to a
 * temporary name and renamed into place when complete). */
#ifndef SS_ROOFS_IO_H
#define SS_ROOFS_IO_H

#include <stddef.h>
#include <stdint.h>

#include "dem_io.h"

typedef struct {
    char id[64];        /* the id field's value, or the feature id */
    int partly_outside; /* part of the footprint lies outside the DSM */
    int repaired;       /* invalid geometry made valid (OGR_G_MakeValid) */
    int col0, row0, cols, rows; /* the window of the grid its cells lie in */
    size_t n_cells;
    int *cells;         /* row * width + col of the cells whose centres lie inside */
    void *geometry;     /* OGRGeometryH, a MultiPolygon in the DSM's CRS */
} ss_footprint;

typedef struct {
    ss_footprint *items;
    size_t n;
    size_t read, repaired, invalid, empty, outside, no_cell, partly_outside;
    char id_field[64]; /* the field ids came from; "" for feature ids */
    char **notes;      /* one line per footprint skipped or repaired, and why */
    size_t n_notes;
} ss_footprints;

/* Reads every feature of path's layer of footprints: layer_name, else an
 * OpenStreetMap file's areas tagged building, else its first layer of
 * polygons, else its first layer (id_field NULL: a field named building_id
 * or id where the layer has one). */
ss_status ss_footprints_read(ss_ctx *ctx, const char *path, const char *layer_name,
                             const char *id_field, const ss_dem *dem, ss_footprints *out);
void ss_footprints_free(ss_footprints *f);

/* Reads rows [row0, row0 + n_rows) of bands [first, first + n) (1-based)
 * of a raster of width x height cells into out (band after band, n_rows *
 * width floats each). */
ss_status ss_raster_read_rows(ss_ctx *ctx, const char *path, int first, int n, int width,
                              int height, int row0, int n_rows, float *out);

/* The cells labelled 1..n_ids in ids (cols x rows, the grid's window at
 * col0, row0; 0: none) as one MultiPolygon per label (OGRGeometryH, NULL
 * where a label has no cell), into geoms[0..n_ids). */
ss_status ss_polygons_of_labels(ss_ctx *ctx, const ss_dem *dem, const int *ids, int col0,
                                int row0, int cols, int rows, int n_ids, void **geoms);
/* A MultiPolygon of one ring through n points given in grid columns and
 * rows (fractional, from the grid's north-west corner). */
void *ss_polygon_of_grid_points(const ss_dem *dem, const double (*col_row)[2], int n);
void ss_geometry_free(void *geometry);

/* A field of a layer: its name, type, unit and meaning (the layer's
 * metadata lists the units and meanings). */
typedef enum { SS_FIELD_INT, SS_FIELD_REAL, SS_FIELD_TEXT } ss_field_type;
typedef struct {
    const char *name;
    ss_field_type type;
    const char *unit; /* "" where none */
    const char *meaning;
} ss_field;
/* A value: num for numbers (NAN: null), text for text. */
typedef struct {
    double num;
    const char *text;
} ss_value;

typedef struct ss_vector_writer ss_vector_writer;
/* Creates OUTPUT's temporary GeoPackage in the DEM's CRS. */
ss_status ss_vector_open(ss_ctx *ctx, const char *path, const ss_dem *dem,
                         ss_vector_writer **out);
/* Adds a MultiPolygon layer; returns its index in *layer. */
ss_status ss_vector_layer(ss_vector_writer *w, const char *name, const char *description,
                          const ss_field *fields, int n_fields, int *layer);
/* Adds a table of attributes, no geometry (GeoPackage's "attributes"). */
ss_status ss_vector_table(ss_vector_writer *w, const char *name, const char *description,
                          const ss_field *fields, int n_fields, int *layer);
/* Adds a feature (the geometry is copied; NULL: none). */
ss_status ss_vector_add(ss_vector_writer *w, int layer, const void *geometry,
                        const ss_value *values);
/* Closes the file and renames it into place. */
ss_status ss_vector_commit(ss_vector_writer *w);
/* Removes the temporary; the output is left as it was. */
void ss_vector_abort(ss_vector_writer *w);

/* Bands of 32-bit masks on the DEM's grid (masks: band after band, width *
 * height each) as a GeoTIFF of UInt32 written to a temporary beside path,
 * whose name goes to *tmp_path; ss_masks_commit renames it into place,
 * ss_masks_abort removes it (both free the name). */
ss_status ss_masks_write(ss_ctx *ctx, const char *path, const ss_dem *dem, int bands,
                         const uint32_t *masks, const char *const *descriptions,
                         char **tmp_path);
ss_status ss_masks_commit(ss_ctx *ctx, const char *path, char *tmp_path);
void ss_masks_abort(const char *path, char *tmp_path);

#endif
