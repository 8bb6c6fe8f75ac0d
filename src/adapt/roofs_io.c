/* skysweep roofs' GDAL/OGR side (roofs_io.h). */
#include "config.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gdal.h>
#include <gdal_alg.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "gdal_errors.h"
#include "roofs_io.h"
#include "temporaries.h"
#include "temporary_name.h"

/* ---- footprints ---------------------------------------------------------- */

static void note(ss_footprints *f, const char *fmt, ...)
{
    char line[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    char **grown = realloc(f->notes, sizeof *grown * (f->n_notes + 1));
    if (!grown)
        return;
    f->notes = grown;
    if ((f->notes[f->n_notes] = strdup(line)))
        f->n_notes++;
}

/* The polygons of g (a polygon, a multipolygon, or a collection such as
 * MakeValid returns, whose lines and points are dropped) as a MultiPolygon;
 * NULL where it has none. Takes g. */
static OGRGeometryH polygons_of(OGRGeometryH g)
{
    OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
    if (t == wkbPolygon || t == wkbMultiPolygon)
        return OGR_G_ForceToMultiPolygon(g);
    OGRGeometryH multi = OGR_G_CreateGeometry(wkbMultiPolygon);
    for (int i = 0; t == wkbGeometryCollection && i < OGR_G_GetGeometryCount(g); ++i) {
        OGRGeometryH part = OGR_G_GetGeometryRef(g, i);
        OGRwkbGeometryType pt = wkbFlatten(OGR_G_GetGeometryType(part));
        if (pt == wkbPolygon)
            OGR_G_AddGeometry(multi, part);
        else if (pt == wkbMultiPolygon)
            for (int k = 0; k < OGR_G_GetGeometryCount(part); ++k)
                OGR_G_AddGeometry(multi, OGR_G_GetGeometryRef(part, k));
    }
    OGR_G_DestroyGeometry(g);
    if (OGR_G_GetGeometryCount(multi) == 0) {
        OGR_G_DestroyGeometry(multi);
        return NULL;
    }
    return multi;
}

/* The DEM's extent as a polygon in its CRS. */
static OGRGeometryH dem_extent(const ss_dem *dem)
{
    const double *gt = dem->geotransform;
    OGRGeometryH ring = OGR_G_CreateGeometry(wkbLinearRing);
    const int corner[5][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}};
    for (int i = 0; i < 5; ++i) {
        double c = corner[i][0] * dem->grid.width, r = corner[i][1] * dem->grid.height;
        OGR_G_AddPoint_2D(ring, gt[0] + c * gt[1] + r * gt[2], gt[3] + c * gt[4] + r * gt[5]);
    }
    OGRGeometryH poly = OGR_G_CreateGeometry(wkbPolygon);
    OGR_G_AddGeometryDirectly(poly, ring);
    return poly;
}

/* The cells of fp's geometry whose centres lie inside it (GDAL's
 * rasterizer without ALL_TOUCHED), in its envelope's window of the grid. */
static ss_status rasterize(ss_ctx *ctx, const ss_dem *dem, ss_footprint *fp)
{
    const double *gt = dem->geotransform;
    OGREnvelope env;
    OGR_G_GetEnvelope(fp->geometry, &env);
    /* north-up grids (the DEM reader refuses rotated ones) */
    double c0 = (env.MinX - gt[0]) / gt[1], c1 = (env.MaxX - gt[0]) / gt[1];
    double r0 = (env.MaxY - gt[3]) / gt[5], r1 = (env.MinY - gt[3]) / gt[5];
    int col0 = (int)fmax(0, floor(fmin(c0, c1))), row0 = (int)fmax(0, floor(fmin(r0, r1)));
    int col1 = (int)fmin(dem->grid.width, ceil(fmax(c0, c1)));
    int row1 = (int)fmin(dem->grid.height, ceil(fmax(r0, r1)));
    fp->col0 = col0, fp->row0 = row0, fp->cols = col1 - col0, fp->rows = row1 - row0;
    if (fp->cols <= 0 || fp->rows <= 0)
        return SS_OK;
    GDALDriverH mem = GDALGetDriverByName("MEM");
    GDALDatasetH ds = mem ? GDALCreate(mem, "", fp->cols, fp->rows, 1, GDT_Byte, NULL) : NULL;
    unsigned char *burnt = malloc((size_t)fp->cols * (size_t)fp->rows);
    fp->cells = malloc(sizeof(int) * (size_t)fp->cols * (size_t)fp->rows);
    if (!ds || !burnt || !fp->cells) {
        if (ds)
            GDALClose(ds);
        free(burnt);
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory rasterizing footprints");
    }
    double wgt[6] = {gt[0] + col0 * gt[1], gt[1], 0, gt[3] + row0 * gt[5], 0, gt[5]};
    GDALSetGeoTransform(ds, wgt);
    int band = 1;
    double burn = 1;
    OGRGeometryH geom = fp->geometry;
    CPLErr err = GDALRasterizeGeometries(ds, 1, &band, 1, &geom, NULL, NULL, &burn, NULL, NULL,
                                         NULL);
    if (err == CE_None)
        err = GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, fp->cols, fp->rows, burnt,
                           fp->cols, fp->rows, GDT_Byte, 0, 0);
    GDALClose(ds);
    for (int r = 0; err == CE_None && r < fp->rows; ++r)
        for (int c = 0; c < fp->cols; ++c)
            if (burnt[(size_t)r * fp->cols + c])
                fp->cells[fp->n_cells++] = (row0 + r) * dem->grid.width + col0 + c;
    free(burnt);
    return err == CE_None ? SS_OK
                          : ss_ctx_error(ctx, SS_ERR_INTERNAL, "cannot rasterize a footprint: %s",
                                         ss_gdal_message());
}

/* The field ids come from: the one asked for, else building_id or id. */
static int id_field_index(OGRFeatureDefnH defn, const char *asked)
{
    if (asked)
        return OGR_FD_GetFieldIndex(defn, asked);
    const char *names[] = {"building_id", "id"};
    for (int i = 0; i < 2; ++i)
        for (int k = 0; k < OGR_FD_GetFieldCount(defn); ++k)
            if (strcasecmp(OGR_Fld_GetNameRef(OGR_FD_GetFieldDefn(defn, k)), names[i]) == 0)
                return k;
    return -1;
}

/* One feature's geometry made ready: reprojected, valid (repaired where
 * not), polygons only. NULL with why in reason where it is skipped. */
static OGRGeometryH footprint_geometry(OGRFeatureH feat, OGRCoordinateTransformationH to_dem,
                                       ss_footprints *f, const char *id, int *repaired)
{
    OGRGeometryH g = OGR_F_GetGeometryRef(feat);
    *repaired = 0;
    if (!g || OGR_G_IsEmpty(g)) {
        f->empty++;
        note(f, "footprint %s skipped: empty geometry", id);
        return NULL;
    }
    OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
    if (t != wkbPolygon && t != wkbMultiPolygon && t != wkbGeometryCollection) {
        f->invalid++;
        note(f, "footprint %s skipped: a %s is not a polygon", id, OGRGeometryTypeToName(t));
        return NULL;
    }
    g = OGR_G_Clone(g);
    if (to_dem && OGR_G_Transform(g, to_dem) != OGRERR_NONE) {
        OGR_G_DestroyGeometry(g);
        f->invalid++;
        note(f, "footprint %s skipped: cannot be reprojected to the DSM's CRS", id);
        return NULL;
    }
    if (!OGR_G_IsValid(g)) {
        OGRGeometryH valid = OGR_G_MakeValid(g);
        OGR_G_DestroyGeometry(g);
        g = valid ? polygons_of(valid) : NULL;
        if (!g) {
            f->invalid++;
            note(f, "footprint %s skipped: invalid geometry that MakeValid could not repair into "
                    "a polygon",
                 id);
            return NULL;
        }
        *repaired = 1;
        f->repaired++;
        note(f, "footprint %s repaired: invalid geometry made valid (OGR_G_MakeValid)", id);
        return g;
    }
    g = polygons_of(g);
    if (!g) {
        f->empty++;
        note(f, "footprint %s skipped: no polygon in it", id);
    }
    return g;
}

static OGRCoordinateTransformationH transform_to_dem(OGRLayerH layer, const ss_dem *dem)
{
    OGRSpatialReferenceH from = OGR_L_GetSpatialRef(layer);
    if (!from || !dem->crs_wkt || !*dem->crs_wkt)
        return NULL;
    OGRSpatialReferenceH to = OSRNewSpatialReference(dem->crs_wkt);
    OGRSpatialReferenceH src = OSRClone(from);
    OSRSetAxisMappingStrategy(to, OAMS_TRADITIONAL_GIS_ORDER);
    OSRSetAxisMappingStrategy(src, OAMS_TRADITIONAL_GIS_ORDER);
    OGRCoordinateTransformationH ct = OSRIsSame(src, to) ? NULL : OCTNewCoordinateTransformation(src, to);
    OSRDestroySpatialReference(src);
    OSRDestroySpatialReference(to);
    return ct;
}

/* Keeps fp (its geometry in the DEM's CRS) unless it lies outside the
 * DEM or covers no cell centre; flags it when part of it lies outside. */
static ss_status place_footprint(ss_ctx *ctx, const ss_dem *dem, OGRGeometryH extent,
                                 ss_footprints *f, ss_footprint *fp)
{
    if (!OGR_G_Intersects(fp->geometry, extent)) {
        f->outside++;
        note(f, "footprint %s skipped: outside the DSM", fp->id);
        return SS_OK;
    }
    fp->partly_outside = !OGR_G_Within(fp->geometry, extent);
    ss_status st = rasterize(ctx, dem, fp);
    if (st != SS_OK)
        return st;
    if (fp->n_cells == 0) {
        f->no_cell++;
        note(f, "footprint %s skipped: covers no cell centre of the DSM", fp->id);
        return SS_OK;
    }
    f->partly_outside += fp->partly_outside;
    if (fp->partly_outside)
        note(f, "footprint %s lies partly outside the DSM: flagged (partly_outside 1), its "
                "cells inside kept",
             fp->id);
    f->items[f->n++] = *fp;
    fp->geometry = NULL;
    fp->cells = NULL;
    return SS_OK;
}

static int is_polygon_layer(OGRLayerH layer)
{
    OGRwkbGeometryType t = wkbFlatten(OGR_L_GetGeomType(layer));
    return t == wkbPolygon || t == wkbMultiPolygon || t == wkbCurvePolygon ||
           t == wkbMultiSurface;
}

/* The layer of footprints: the one named; else an OpenStreetMap file's
 * areas tagged building (GDAL's OSM driver puts closed ways and
 * multipolygon relations in its layer "multipolygons", with the building
 * tag as a field); else the first layer of polygons; else the first
 * layer. */
static ss_status footprint_layer(ss_ctx *ctx, GDALDatasetH ds, const char *path,
                                 const char *name, OGRLayerH *layer)
{
    if (name) {
        *layer = GDALDatasetGetLayerByName(ds, name);
        return *layer ? SS_OK
                      : ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                                     "--buildings-layer: '%s' has no layer '%s'", path, name);
    }
    if (strcmp(GDALGetDriverShortName(GDALGetDatasetDriver(ds)), "OSM") == 0) {
        *layer = GDALDatasetGetLayerByName(ds, "multipolygons");
        if (!*layer || OGR_L_SetAttributeFilter(*layer, "building IS NOT NULL") != OGRERR_NONE)
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                                "'%s' is an OpenStreetMap file whose areas carry no building "
                                "tag (GDAL's osmconf.ini must list 'building' for "
                                "multipolygons)",
                                path);
        return SS_OK;
    }
    int n = GDALDatasetGetLayerCount(ds);
    *layer = n > 0 ? GDALDatasetGetLayer(ds, 0) : NULL;
    for (int i = n - 1; i >= 0; --i) /* the first of polygons wins */
        if (is_polygon_layer(GDALDatasetGetLayer(ds, i)))
            *layer = GDALDatasetGetLayer(ds, i);
    return *layer ? SS_OK
                  : ss_ctx_error(ctx, SS_ERR_INPUT, "'%s' holds no layer of footprints", path);
}

ss_status ss_footprints_read(ss_ctx *ctx, const char *path, const char *layer_name,
                             const char *id_field, const ss_dem *dem, ss_footprints *out)
{
    memset(out, 0, sizeof *out);
    ss_gdal_errors_reset();
    GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_VECTOR | GDAL_OF_READONLY, NULL, NULL, NULL);
    if (!ds)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot open '%s' as a vector source: %s", path,
                            ss_gdal_message());
    OGRLayerH layer = NULL;
    ss_status found = footprint_layer(ctx, ds, path, layer_name, &layer);
    if (found != SS_OK) {
        GDALClose(ds);
        return found;
    }
    OGRFeatureDefnH defn = OGR_L_GetLayerDefn(layer);
    int id_index = id_field_index(defn, id_field);
    if (id_field && id_index < 0) {
        GDALClose(ds);
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "--id-field: '%s' has no field '%s'", path,
                            id_field);
    }
    if (id_index >= 0)
        snprintf(out->id_field, sizeof out->id_field, "%s",
                 OGR_Fld_GetNameRef(OGR_FD_GetFieldDefn(defn, id_index)));
    GIntBig count = OGR_L_GetFeatureCount(layer, 1);
    out->items = calloc(count > 0 ? (size_t)count : 1, sizeof *out->items);
    OGRCoordinateTransformationH to_dem = transform_to_dem(layer, dem);
    OGRGeometryH extent = dem_extent(dem);
    ss_status st = out->items ? SS_OK
                              : ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for footprints");
    OGR_L_ResetReading(layer);
    OGRFeatureH feat;
    while (st == SS_OK && out->n < (size_t)count && (feat = OGR_L_GetNextFeature(layer))) {
        ss_footprint fp = {0};
        out->read++;
        if (id_index >= 0 && OGR_F_IsFieldSetAndNotNull(feat, id_index))
            snprintf(fp.id, sizeof fp.id, "%s", OGR_F_GetFieldAsString(feat, id_index));
        else
            snprintf(fp.id, sizeof fp.id, "%lld", (long long)OGR_F_GetFID(feat));
        fp.geometry = footprint_geometry(feat, to_dem, out, fp.id, &fp.repaired);
        OGR_F_Destroy(feat);
        if (fp.geometry)
            st = place_footprint(ctx, dem, extent, out, &fp);
        OGR_G_DestroyGeometry(fp.geometry);
        free(fp.cells);
    }
    OGR_G_DestroyGeometry(extent);
    if (to_dem)
        OCTDestroyCoordinateTransformation(to_dem);
    GDALClose(ds);
    return st;
}

void ss_footprints_free(ss_footprints *f)
{
    for (size_t i = 0; i < f->n; ++i) {
        free(f->items[i].cells);
        OGR_G_DestroyGeometry(f->items[i].geometry);
    }
    for (size_t i = 0; i < f->n_notes; ++i)
        free(f->notes[i]);
    free(f->notes);
    free(f->items);
    memset(f, 0, sizeof *f);
}

/* ---- rasters and polygons ----------------------------------------------- */

ss_status ss_raster_read_rows(ss_ctx *ctx, const char *path, int first, int n, int width,
                              int height, int row0, int n_rows, float *out)
{
    ss_gdal_errors_reset();
    GDALDatasetH ds = GDALOpen(path, GA_ReadOnly);
    if (!ds || GDALGetRasterXSize(ds) != width || GDALGetRasterYSize(ds) != height ||
        GDALGetRasterCount(ds) < first + n - 1 || row0 < 0 || n_rows < 0 ||
        row0 + n_rows > height) {
        if (ds)
            GDALClose(ds);
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "cannot read back '%s': %s", path,
                            ss_gdal_message());
    }
    CPLErr err = CE_None;
    for (int b = 0; err == CE_None && b < n; ++b)
        err = GDALRasterIO(GDALGetRasterBand(ds, first + b), GF_Read, 0, row0, width, n_rows,
                           out + (size_t)b * width * n_rows, width, n_rows, GDT_Float32, 0, 0);
    GDALClose(ds);
    return err == CE_None ? SS_OK
                          : ss_ctx_error(ctx, SS_ERR_INTERNAL, "cannot read back '%s': %s", path,
                                         ss_gdal_message());
}

ss_status ss_polygons_of_labels(ss_ctx *ctx, const ss_dem *dem, const int *ids, int col0,
                                int row0, int cols, int rows, int n_ids, void **geoms)
{
    for (int i = 0; i < n_ids; ++i)
        geoms[i] = NULL;
    const double *gt = dem->geotransform;
    GDALDriverH mem = GDALGetDriverByName("MEM");
    GDALDatasetH ds = GDALCreate(mem, "", cols, rows, 1, GDT_Int32, NULL);
    GDALDriverH vmem = GDALGetDriverByName("Memory");
    GDALDatasetH vds = vmem ? GDALCreate(vmem, "", 0, 0, 0, GDT_Unknown, NULL) : NULL;
    OGRLayerH layer = vds ? GDALDatasetCreateLayer(vds, "planes", NULL, wkbPolygon, NULL) : NULL;
    if (!ds || !layer) {
        if (ds)
            GDALClose(ds);
        if (vds)
            GDALClose(vds);
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "cannot polygonize roof planes: %s",
                            ss_gdal_message());
    }
    double wgt[6] = {gt[0] + col0 * gt[1], gt[1], 0, gt[3] + row0 * gt[5], 0, gt[5]};
    GDALSetGeoTransform(ds, wgt);
    OGRFieldDefnH id_field = OGR_Fld_Create("id", OFTInteger);
    OGR_L_CreateField(layer, id_field, 1);
    OGR_Fld_Destroy(id_field);
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    CPLErr err = GDALRasterIO(band, GF_Write, 0, 0, cols, rows, (void *)ids, cols, rows,
                              GDT_Int32, 0, 0);
    /* the band masks itself: label 0 is no plane */
    if (err == CE_None)
        err = GDALPolygonize(band, band, layer, 0, NULL, NULL, NULL);
    OGR_L_ResetReading(layer);
    OGRFeatureH f;
    while (err == CE_None && (f = OGR_L_GetNextFeature(layer))) {
        int id = OGR_F_GetFieldAsInteger(f, 0);
        if (id >= 1 && id <= n_ids) {
            if (!geoms[id - 1])
                geoms[id - 1] = OGR_G_CreateGeometry(wkbMultiPolygon);
            OGR_G_AddGeometry(geoms[id - 1], OGR_F_GetGeometryRef(f));
        }
        OGR_F_Destroy(f);
    }
    GDALClose(ds);
    GDALClose(vds);
    return err == CE_None ? SS_OK
                          : ss_ctx_error(ctx, SS_ERR_INTERNAL, "cannot polygonize roof planes: %s",
                                         ss_gdal_message());
}

void ss_geometry_free(void *geometry)
{
    if (geometry)
        OGR_G_DestroyGeometry(geometry);
}

/* ---- the GeoPackage ------------------------------------------------------ */

#define MAX_LAYERS 8
struct ss_vector_writer {
    ss_ctx *ctx;
    char *path, *tmp_path;
    GDALDatasetH ds;
    OGRSpatialReferenceH srs;
    OGRLayerH layers[MAX_LAYERS];
    int n_layers;
    const ss_field *fields[MAX_LAYERS];
    int n_fields[MAX_LAYERS];
};

static ss_status vector_failed(ss_vector_writer *w, const char *what)
{
    char cause[600];
    return ss_ctx_error(w->ctx, SS_ERR_OUTPUT, "cannot %s '%s': %s", what, w->path,
                        ss_gdal_failure(cause, sizeof cause));
}

ss_status ss_vector_open(ss_ctx *ctx, const char *path, const ss_dem *dem,
                         ss_vector_writer **out)
{
    *out = NULL;
    ss_status st = ss_output_check(ctx, path);
    if (st != SS_OK)
        return st;
    ss_vector_writer *w = calloc(1, sizeof *w);
    if (!w || !(w->path = strdup(path)) || !(w->tmp_path = ss_temporary_name(path, "tmp"))) {
        if (w)
            free(w->path);
        free(w);
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    }
    w->ctx = ctx;
    ss_temporaries_track(path);
    ss_gdal_errors_reset();
    GDALDriverH gpkg = GDALGetDriverByName("GPKG");
    w->ds = gpkg ? GDALCreate(gpkg, w->tmp_path, 0, 0, 0, GDT_Unknown, NULL) : NULL;
    if (!w->ds) {
        st = vector_failed(w, "create the GeoPackage");
        ss_vector_abort(w);
        return st;
    }
    /* One transaction for the whole file: features are written fast and
     * nothing reaches the file until the commit. */
    if (GDALDatasetStartTransaction(w->ds, FALSE) != OGRERR_NONE) {
        st = vector_failed(w, "start writing");
        ss_vector_abort(w);
        return st;
    }
    if (dem->crs_wkt && *dem->crs_wkt) {
        w->srs = OSRNewSpatialReference(dem->crs_wkt);
        OSRSetAxisMappingStrategy(w->srs, OAMS_TRADITIONAL_GIS_ORDER);
    }
    *out = w;
    return SS_OK;
}

static OGRFieldType field_type(ss_field_type t)
{
    return t == SS_FIELD_INT ? OFTInteger64 : t == SS_FIELD_REAL ? OFTReal : OFTString;
}

/* A layer of geometry type `type` (wkbNone: a table of attributes). */
static ss_status create_layer(ss_vector_writer *w, const char *name, const char *description,
                              OGRwkbGeometryType type, const ss_field *fields, int n_fields,
                              int *layer)
{
    /* The description whole: it names the sky, the trees and the crown
     * light, longer than any fixed buffer would be sure to hold. */
    size_t size = strlen("DESCRIPTION=") + strlen(description) + 1;
    char *desc = malloc(size);
    if (!desc)
        return vector_failed(w, "create a layer in");
    snprintf(desc, size, "DESCRIPTION=%s", description);
    char *opts[] = {desc, NULL};
    OGRLayerH l = w->n_layers < MAX_LAYERS
                      ? GDALDatasetCreateLayer(w->ds, name, type == wkbNone ? NULL : w->srs,
                                               type, opts)
                      : NULL;
    free(desc);
    if (!l)
        return vector_failed(w, "create a layer in");
    /* The units and meanings, in the layer's metadata (gpkg_metadata). */
    for (int k = 0; k < n_fields; ++k) {
        OGRFieldDefnH fd = OGR_Fld_Create(fields[k].name, field_type(fields[k].type));
        OGRErr e = OGR_L_CreateField(l, fd, 1);
        OGR_Fld_Destroy(fd);
        if (e != OGRERR_NONE)
            return vector_failed(w, "create a field in");
        char key[80], value[400];
        snprintf(key, sizeof key, "FIELD_%s", fields[k].name);
        snprintf(value, sizeof value, "%s%s%s%s", fields[k].meaning, *fields[k].unit ? " (" : "",
                 fields[k].unit, *fields[k].unit ? ")" : "");
        GDALSetMetadataItem(l, key, value, NULL);
    }
    w->layers[w->n_layers] = l;
    w->fields[w->n_layers] = fields;
    w->n_fields[w->n_layers] = n_fields;
    *layer = w->n_layers++;
    return SS_OK;
}

ss_status ss_vector_layer(ss_vector_writer *w, const char *name, const char *description,
                          const ss_field *fields, int n_fields, int *layer)
{
    return create_layer(w, name, description, wkbMultiPolygon, fields, n_fields, layer);
}

ss_status ss_vector_table(ss_vector_writer *w, const char *name, const char *description,
                          const ss_field *fields, int n_fields, int *layer)
{
    return create_layer(w, name, description, wkbNone, fields, n_fields, layer);
}

ss_status ss_vector_add(ss_vector_writer *w, int layer, const void *geometry,
                        const ss_value *values)
{
    OGRLayerH l = w->layers[layer];
    OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(l));
    for (int k = 0; k < w->n_fields[layer]; ++k) {
        if (w->fields[layer][k].type == SS_FIELD_TEXT)
            OGR_F_SetFieldString(f, k, values[k].text ? values[k].text : "");
        else if (isfinite(values[k].num) && w->fields[layer][k].type == SS_FIELD_INT)
            OGR_F_SetFieldInteger64(f, k, (GIntBig)llround(values[k].num));
        else if (isfinite(values[k].num))
            OGR_F_SetFieldDouble(f, k, values[k].num);
        else
            OGR_F_SetFieldNull(f, k);
    }
    if (geometry)
        OGR_F_SetGeometry(f, (OGRGeometryH)geometry);
    OGRErr e = OGR_L_CreateFeature(l, f);
    OGR_F_Destroy(f);
    return e == OGRERR_NONE ? SS_OK : vector_failed(w, "write a feature to");
}

ss_status ss_vector_commit(ss_vector_writer *w)
{
    ss_status st = SS_OK;
    if (GDALDatasetCommitTransaction(w->ds) != OGRERR_NONE)
        st = vector_failed(w, "finish writing");
    if (st == SS_OK) {
        GDALClose(w->ds);
        w->ds = NULL;
        if (ss_gdal_failed())
            st = vector_failed(w, "close");
    }
    if (st == SS_OK) {
        if (!ss_temporaries_hold())
            st = ss_ctx_error(w->ctx, SS_ERR_CANCELLED, "stopped before '%s' was renamed", w->path);
        else {
            if (rename(w->tmp_path, w->path) != 0)
                st = ss_ctx_error(w->ctx, SS_ERR_OUTPUT, "cannot rename '%s' to '%s'",
                                  w->tmp_path, w->path);
            ss_temporaries_release();
        }
    }
    if (st != SS_OK) {
        ss_vector_abort(w);
        return st;
    }
    ss_temporaries_forget(w->path);
    if (w->srs)
        OSRDestroySpatialReference(w->srs);
    free(w->path);
    free(w->tmp_path);
    free(w);
    return SS_OK;
}

void ss_vector_abort(ss_vector_writer *w)
{
    if (!w)
        return;
    if (w->ds)
        ss_gdal_close_discarding(w->ds);
    remove(w->tmp_path);
    ss_temporaries_forget(w->path);
    if (w->srs)
        OSRDestroySpatialReference(w->srs);
    free(w->path);
    free(w->tmp_path);
    free(w);
}

void *ss_polygon_of_grid_points(const ss_dem *dem, const double (*col_row)[2], int n)
{
    const double *gt = dem->geotransform;
    OGRGeometryH ring = OGR_G_CreateGeometry(wkbLinearRing);
    for (int k = 0; k <= n; ++k) {
        const double *p = col_row[k % n];
        OGR_G_AddPoint_2D(ring, gt[0] + p[0] * gt[1] + p[1] * gt[2],
                          gt[3] + p[0] * gt[4] + p[1] * gt[5]);
    }
    OGRGeometryH poly = OGR_G_CreateGeometry(wkbPolygon);
    OGRGeometryH multi = OGR_G_CreateGeometry(wkbMultiPolygon);
    OGR_G_AddGeometryDirectly(poly, ring);
    OGR_G_AddGeometryDirectly(multi, poly);
    return multi;
}

/* ---- rasters of bit masks ------------------------------------------------- */

ss_status ss_masks_write(ss_ctx *ctx, const char *path, const ss_dem *dem, int bands,
                         const uint32_t *masks, const char *const *descriptions,
                         char **tmp_path)
{
    *tmp_path = NULL;
    ss_gdal_init();
    ss_status st = ss_output_check(ctx, path);
    if (st != SS_OK)
        return st;
    char *tmp = ss_temporary_name(path, "tmp");
    if (!tmp)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    ss_temporaries_track(path);
    const ss_grid *g = &dem->grid;
    char *opts[] = {"TILED=YES", "COMPRESS=DEFLATE", "INTERLEAVE=BAND", "BIGTIFF=IF_SAFER",
                    NULL};
    ss_gdal_errors_reset();
    GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), tmp, g->width, g->height, bands,
                                 GDT_UInt32, opts);
    CPLErr err = ds ? CE_None : CE_Failure;
    if (ds) {
        GDALSetGeoTransform(ds, (double *)dem->geotransform);
        if (dem->crs_wkt)
            GDALSetProjection(ds, dem->crs_wkt);
    }
    size_t cells = (size_t)g->width * (size_t)g->height;
    for (int b = 0; err == CE_None && b < bands; ++b) {
        GDALRasterBandH band = GDALGetRasterBand(ds, b + 1);
        GDALSetDescription(band, descriptions[b]);
        err = GDALRasterIO(band, GF_Write, 0, 0, g->width, g->height,
                           (void *)(masks + (size_t)b * cells), g->width, g->height, GDT_UInt32,
                           0, 0);
    }
    if (ds)
        GDALClose(ds);
    if (err != CE_None || ss_gdal_failed()) {
        char why[1200];
        st = ss_ctx_error(ctx, ss_gdal_out_of_memory() ? SS_ERR_MEMORY : SS_ERR_OUTPUT,
                          "cannot write '%s': %s", path, ss_gdal_failure(why, sizeof why));
        remove(tmp);
        ss_temporaries_forget(path);
        free(tmp);
        return st;
    }
    *tmp_path = tmp;
    return SS_OK;
}

ss_status ss_masks_commit(ss_ctx *ctx, const char *path, char *tmp_path)
{
    ss_status st = SS_OK;
    if (!ss_temporaries_hold())
        st = ss_ctx_error(ctx, SS_ERR_CANCELLED, "stopped before '%s' was renamed", path);
    else {
        if (rename(tmp_path, path) != 0)
            st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename '%s' to '%s'", tmp_path, path);
        ss_temporaries_release();
    }
    if (st != SS_OK)
        remove(tmp_path);
    ss_temporaries_forget(path);
    free(tmp_path);
    return st;
}

void ss_masks_abort(const char *path, char *tmp_path)
{
    if (!tmp_path)
        return;
    remove(tmp_path);
    ss_temporaries_forget(path);
    free(tmp_path);
}
