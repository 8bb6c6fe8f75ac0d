/* Writes georeferenced float rasters through GDAL. The file is built under a
 * hidden temporary name next to the output and renamed over it only when
 * complete, so a failed or interrupted run never leaves a half-written file
 * and never replaces an existing one. */
#include "config.h"

#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>

#include "skysweep.h"
#include "dem_io.h"
#include "gdal_errors.h"
#include "temporaries.h"
#include "temporary_name.h"

struct ss_raster_writer {
    ss_ctx *ctx;
    int grid_width;       /* rows handed in are this long ... */
    int col0, row0;       /* ... and the file holds the window from here */
    int byte_pixels;      /* 1: Byte bands, values rounded, nodata 0 (gdaldem's style) */
    GDALDatasetH ds;      /* the temporary file, or a MEM copy for CreateCopy-only drivers */
    GDALDriverH driver;   /* the output format */
    char **create_opts;
    char *path, *tmp_path;
    int bands;
    void *reserve;        /* room to close the file in (release_reserve) */
};

int ss_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

int ss_same_output(const char *a, const char *b)
{
    char *a_dir = strdup(a), *a_base = strdup(a), *b_dir = strdup(b), *b_base = strdup(b);
    int same = strcmp(a, b) == 0;
    if (!same && a_dir && a_base && b_dir && b_base &&
        strcmp(basename(a_base), basename(b_base)) == 0) {
        char *ra = realpath(dirname(a_dir), NULL), *rb = realpath(dirname(b_dir), NULL);
        same = ra && rb && strcmp(ra, rb) == 0;
        free(ra);
        free(rb);
    }
    free(a_dir);
    free(a_base);
    free(b_dir);
    free(b_base);
    return same || ss_same_file(a, b);
}

/* Removes the files "dir/.base.<pid>.*" that a writer of OUTPUT dir/base
 * made: the temporary, its side-cars (.aux.xml, an ENVI .hdr, a .prj) and a
 * format probe. pid 0: those of processes that no longer run, which a
 * SIGKILL or a crash left behind; else those of that process. */
static void remove_temporaries(const char *dir, const char *base, long pid)
{
    char **names = VSIReadDir(dir); /* GDAL's file system: /vsimem/ and the like too */
    size_t n_base = strlen(base);
    for (int i = 0; names && names[i]; ++i) {
        const char *name = names[i];
        if (name[0] != '.' || strncmp(name + 1, base, n_base) != 0 || name[1 + n_base] != '.')
            continue;
        char *end;
        long owner = strtol(name + 2 + n_base, &end, 10);
        if (owner <= 0 || end == name + 2 + n_base || *end != '.')
            continue;
        if (pid ? owner != pid : kill((pid_t)owner, 0) == 0 || errno != ESRCH)
            continue; /* another's, or alive (or not ours to judge) */
        char full[PATH_MAX];
        VSIStatBufL st;
        if (snprintf(full, sizeof full, "%s/%s", dir, name) >= (int)sizeof full ||
            VSIStatL(full, &st) != 0)
            continue;
        if (VSI_ISDIR(st.st_mode))
            VSIRmdirRecursive(full); /* a format that is a folder (Zarr) */
        else
            VSIUnlink(full);
    }
    CSLDestroy(names);
}

/* Splits path into a folder and a name (both to be freed). */
static int split_path(const char *path, char **dir, char **base)
{
    char *dir_copy = strdup(path), *base_copy = strdup(path);
    *dir = dir_copy ? strdup(dirname(dir_copy)) : NULL;
    *base = base_copy ? strdup(basename(base_copy)) : NULL;
    free(dir_copy);
    free(base_copy);
    if (*dir && *base)
        return 0;
    free(*dir);
    free(*base);
    return -1;
}

/* Whether path's file name has an extension: a dot after its first
 * character (".hs" is a hidden name, not an extension), the one rule of the
 * temporary's name, its stem and the rename. */
static int has_extension(const char *path)
{
    const char *slash = strrchr(path, '/'), *name = slash ? slash + 1 : path;
    const char *dot = strrchr(name, '.');
    return dot && dot > name;
}

/* The file name of path without its folder and last extension. */
static char *stem_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *name = slash ? slash + 1 : path;
    const char *dot = strrchr(name, '.');
    return strndup(name, dot && dot > name ? (size_t)(dot - name) : strlen(name));
}

/* The files of the dataset at path that are its own: named from its stem.
 * GDAL's file list may name unrelated files of the folder (a GeoTIFF's
 * lists any ./NAME.txt it takes for satellite metadata), which neither a
 * rename nor a clean-up may touch. NULL-ended, CSLDestroy it. */
static char **own_files(GDALDatasetH ds, const char *path)
{
    char **all = GDALGetFileList(ds), **own = NULL, *stem = stem_of(path);
    for (int i = 0; stem && all && all[i]; ++i) {
        const char *slash = strrchr(all[i], '/'), *name = slash ? slash + 1 : all[i];
        size_t n = strlen(stem);
        if (strncmp(name, stem, n) == 0 && (name[n] == '\0' || name[n] == '.'))
            own = CSLAddString(own, all[i]);
    }
    CSLDestroy(all);
    free(stem);
    /* A world file (-co TFW=YES, WORLDFILE=YES) is left out of the list
     * where the georeferencing is inside the file too. */
    static const char *const world_extensions[] = {"tfw", "wld"};
    for (size_t i = 0; i < sizeof world_extensions / sizeof world_extensions[0]; ++i) {
        const char *world = CPLResetExtension(path, world_extensions[i]);
        VSIStatBufL st;
        if (CSLFindString(own, world) < 0 && VSIStatL(world, &st) == 0)
            own = CSLAddString(own, world);
    }
    return own;
}

/* Renames from[i] to to[i] in turn, under the renames' lock
 * (temporaries.h), which only these renames hold: a stop guard then waits
 * for no GDAL call. 0 when all moved, -1 when one failed, 1 when none
 * moved because the process is stopping. */
static int move_files(char **from, char **to)
{
    if (!ss_temporaries_hold())
        return 1;
    int failed = 0;
    for (int i = 0; !failed && from[i]; ++i) {
        failed = VSIRename(from[i], to[i]) != 0;
        if (failed) /* for ss_gdal_failure, as GDAL reports its own failures */
            CPLError(CE_Failure, CPLE_FileIO, "cannot rename '%s' to '%s': %s", from[i], to[i],
                     strerror(errno));
    }
    ss_temporaries_release();
    return failed ? -1 : 0;
}

/* Moves the temporary's own files (own_files) to the output's names: the
 * temporary's stem in each replaced by the output's; the file itself (the
 * list's first) last, so that until it moves the output stays whole.
 * Returns as move_files. */
static int rename_own_files(const char *tmp_path, const char *path)
{
    GDALDatasetH ds = GDALOpen(tmp_path, GA_ReadOnly);
    char **files = ds ? own_files(ds, tmp_path) : NULL;
    if (!files && ds)
        CPLError(CE_Failure, CPLE_FileIO, "cannot list the files of '%s'", tmp_path);
    if (ds)
        GDALClose(ds);
    char *from_stem = stem_of(tmp_path), *to_stem = stem_of(path), *dir = NULL, *base = NULL;
    int failed = !files || !from_stem || !to_stem || split_path(path, &dir, &base) != 0;
    int n = 0;
    while (!failed && files[n])
        ++n;
    char **from = NULL, **to = NULL;
    for (int k = 1; !failed && k <= n; ++k) {
        int i = k % n; /* 1, 2, ..., n - 1, then 0 */
        const char *slash = strrchr(files[i], '/'), *name = slash ? slash + 1 : files[i];
        char target[PATH_MAX];
        snprintf(target, sizeof target, "%s/%s%s", dir, to_stem, name + strlen(from_stem));
        from = CSLAddString(from, files[i]);
        to = CSLAddString(to, target);
    }
    int result = failed || !from ? -1 : move_files(from, to);
    CSLDestroy(from);
    CSLDestroy(to);
    CSLDestroy(files);
    free(from_stem);
    free(to_stem);
    free(dir);
    free(base);
    return result;
}

/* OUTPUT's temporary of this kind (ss_temporary_name), once the
 * temporaries of dead processes beside it are gone. */
static char *temporary_name(const char *path, const char *kind)
{
    char *dir, *base;
    if (split_path(path, &dir, &base) != 0)
        return NULL;
    remove_temporaries(dir, base, 0);
    free(dir);
    free(base);
    return ss_temporary_name(path, kind);
}

/* Whether an existing file may be replaced: the user may write it, and,
 * for root too (whom access() lets write anything), someone may: a file
 * without a write bit for anyone was made read-only on purpose, and is
 * refused as rm -i and cp ask first. Renaming over a file needs only the
 * folder's permission, so neither would be checked otherwise. */
static int may_replace(const char *path, mode_t mode)
{
    return (mode & 0222) != 0 && access(path, W_OK) == 0;
}

ss_status ss_output_check(ss_ctx *ctx, const char *path)
{
    if (!path[0])
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "an output's name is empty");
    char target[PATH_MAX]; /* a link's target: written through (ss_output_target) */
    if (!ss_output_target(path, target))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "the output '%s' names a path too long", path);
    char *copy = strdup(target);
    if (!copy)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    const char *dir = dirname(copy);
    VSIStatBufL st;
    struct stat file;
    ss_status status = SS_OK;
    if (VSIStatL(dir, &st) != 0 || !VSI_ISDIR(st.st_mode))
        status = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s': folder '%s' does not exist",
                         path, dir);
    else if (strncmp(dir, "/vsi", 4) != 0 && access(dir, W_OK | X_OK) != 0)
        status = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s': folder '%s' is not writable",
                         path, dir);
    else if (VSIStatL(target, &st) == 0 && !VSI_ISREG(st.st_mode))
        status = ss_ctx_error(ctx, SS_ERR_OUTPUT,
                              "cannot write '%s': it is a %s, which an output may not replace",
                              path, VSI_ISDIR(st.st_mode) ? "folder" : "device, pipe or socket");
    else if (strncmp(target, "/vsi", 4) != 0 && stat(target, &file) == 0 &&
             !may_replace(target, file.st_mode))
        status = ss_ctx_error(ctx, SS_ERR_OUTPUT,
                              "cannot replace '%s': %s (mode %03o); make it writable or choose "
                              "another name",
                              path, file.st_mode & 0222 ? "this user may not write it"
                                                        : "it is read-only",
                              (unsigned)(file.st_mode & 0777));
    free(copy);
    return status;
}

static char **default_options(GDALDriverH driver, int bands, int byte_pixels,
                              const char *const *user)
{
    char **opts = NULL;
    if (strcmp(GDALGetDriverShortName(driver), "GTiff") == 0) {
        opts = CSLSetNameValue(opts, "TILED", "YES");
        opts = CSLSetNameValue(opts, "COMPRESS", "DEFLATE");
        /* Level 1 on every core (GDAL_NUM_THREADS: as many as the process
         * can start, src/cli/run.c): measured on the Kilauea DEM (doc/performance.md),
         * horizon --directions 16 writes in 0.75 s instead of 1.32 s for a file
         * 1.2 % larger; every DEFLATE reader (QGIS, GDAL, libtiff) reads it. */
        opts = CSLSetNameValue(opts, "ZLEVEL", "1");
        opts = CSLSetNameValue(opts, "NUM_THREADS",
                               CPLGetConfigOption("GDAL_NUM_THREADS", "ALL_CPUS"));
        /* Floating-point prediction for floats, horizontal differencing for bytes. */
        opts = CSLSetNameValue(opts, "PREDICTOR", byte_pixels ? "2" : "3");
        opts = CSLSetNameValue(opts, "BIGTIFF", "IF_SAFER");
        /* Every tile of a finished output is written anyway; without it
         * GDAL fills the missing ones of an abandoned file at close, which
         * kept an interrupted run of many bands busy for seconds. */
        opts = CSLSetNameValue(opts, "SPARSE_OK", "TRUE");
        if (bands > 1)
            opts = CSLSetNameValue(opts, "INTERLEAVE", "BAND");
    }
    for (int i = 0; user && user[i]; ++i) {
        char *key = NULL;
        const char *value = CPLParseNameValue(user[i], &key);
        if (key && value)
            opts = CSLSetNameValue(opts, key, value);
        CPLFree(key);
    }
    return opts;
}

/* Formats known to hold every product (Float32 or Byte, any band count,
 * nodata), for the message that refuses another. */
#define SS_FORMATS_THAT_HOLD "GTiff, COG, HFA or ENVI"

/* Whether the probe read back as written; where not, says why as GDAL
 * reports a failure (for ss_gdal_failure). */
static int probe_holds(GDALDatasetH ds, int bands, const double *values)
{
    if (!ds)
        return 0;
    if (GDALGetRasterCount(ds) != bands) {
        CPLError(CE_Failure, CPLE_AppDefined, "it reads back as %d bands",
                 GDALGetRasterCount(ds));
        return 0;
    }
    for (int b = 1; b <= bands; ++b) {
        GDALRasterBandH band = GDALGetRasterBand(ds, b);
        int has_nodata = 0;
        double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
        double back[4];
        if (!has_nodata || nodata != values[0]) {
            CPLError(CE_Failure, CPLE_AppDefined, "it reads back without its nodata value");
            return 0;
        }
        if (GDALRasterIO(band, GF_Read, 0, 0, 2, 2, back, 2, 2, GDT_Float64, 0, 0) != CE_None)
            return 0;
        for (int i = 0; i < 4; ++i)
            if (back[i] != values[i]) {
                CPLError(CE_Failure, CPLE_AppDefined, "it reads %g back as %g", values[i],
                         back[i]);
                return 0;
            }
    }
    return 1;
}

/* Georeferences the probe and writes its values and nodata into each band,
 * as the writer does its output; whether all went in. */
static int fill_probe(GDALDatasetH ds, int bands, const double *values)
{
    /* Formats that need georeferencing (GPKG) would refuse a probe
     * without, and a world file (-co TFW=YES) is written only with it. */
    double gt[6] = {0, 1, 0, 2, 0, -1};
    /* Nodata first: GPKG takes it only before its tables exist, which
     * the georeferencing creates. */
    for (int b = 1; b <= bands; ++b)
        GDALSetRasterNoDataValue(GDALGetRasterBand(ds, b), values[0]); /* read back below */
    if (GDALSetGeoTransform(ds, gt) != CE_None)
        return 0;
    for (int b = 1; b <= bands; ++b)
        if (GDALRasterIO(GDALGetRasterBand(ds, b), GF_Write, 0, 0, 2, 2, (void *)values, 2, 2,
                         GDT_Float64, 0, 0) != CE_None)
            return 0;
    return 1;
}

/* Writes a 2 x 2 probe with the values that would be lost (nodata,
 * fractions, values above 255) to probe_path with the format, the way the
 * writer will (GDALCreate where the driver can, else a copy of a MEM
 * dataset: a GPKG of bytes made one way reads back as 4 bands, the other
 * as 1), reads it back and deletes it. Returns whether the values came
 * back unchanged; *side_cars counts the files besides it (other than
 * .aux.xml). */
static int probe_format(GDALDriverH driver, const char *probe_path, int bands, GDALDataType type,
                        char **create_opts, const double *values, int *side_cars)
{
    *side_cars = 0;
    int can_create = CSLFetchBoolean(GDALGetMetadata(driver, NULL), GDAL_DCAP_CREATE, FALSE);
    GDALDatasetH ds = can_create
                          ? GDALCreate(driver, probe_path, 2, 2, bands, type, create_opts)
                          : GDALCreate(GDALGetDriverByName("MEM"), "", 2, 2, bands, type, NULL);
    int filled = ds && fill_probe(ds, bands, values);
    int written = can_create && ds != NULL; /* something may be on disk */
    if (!can_create && filled) {
        GDALDatasetH copy = GDALCreateCopy(driver, probe_path, ds, FALSE, create_opts, NULL, NULL);
        written = copy != NULL;
        if (copy)
            GDALClose(copy);
    }
    if (ds)
        GDALClose(ds);
    GDALDatasetH back = written && filled ? GDALOpen(probe_path, GA_ReadOnly) : NULL;
    int holds = probe_holds(back, bands, values);
    char **files = back ? own_files(back, probe_path) : NULL;
    for (int i = 0; files && files[i]; ++i)
        *side_cars += i > 0 && !strstr(files[i], ".aux.xml");
    if (back)
        GDALClose(back);
    for (int i = 0; files && files[i]; ++i)
        VSIUnlink(files[i]);
    if (written && !back) /* written, but it does not open: its name is all we know */
        VSIUnlink(probe_path);
    CSLDestroy(files);
    return holds;
}

/* Whether the format can hold the product's values: its data type, its
 * bands and its nodata value, probed before any work (probe_format), so
 * that no format casts or drops them silently (a PNG of an SVF would hold
 * only 0 and 1). The probe goes to memory first, where the driver can write
 * there, so that a full disk is not taken for what the format holds; then
 * beside the output (what a failed probe leaves, ss_writer_abort removes). */
static ss_status check_format_holds(ss_ctx *ctx, GDALDriverH driver, const char *format,
                                    const char *path, int bands, GDALDataType type,
                                    char **create_opts)
{
    char why[1200] = ""; /* GDAL's words, where a probe failed */
    const char *types = GDALGetMetadataItem(driver, GDAL_DMD_CREATIONDATATYPES, NULL);
    const char *type_name = GDALGetDataTypeName(type);
    if (types && !strstr(types, type_name))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "the %s format cannot hold this product's %s values (it writes %s); use "
                       "-of %s, or convert afterwards with gdal_translate -ot -scale",
                       format, type_name, types, SS_FORMATS_THAT_HOLD);
    const double float_values[4] = {SS_NODATA, 0.8125, -12.5, 1234.5};
    const double byte_values[4] = {0, 1, 128, 255};
    const double *values = type == GDT_Byte ? byte_values : float_values;
    int has_ext = has_extension(path), holds = 0, side_cars = 0;
    if (CSLFetchBoolean(GDALGetMetadata(driver, NULL), GDAL_DCAP_VIRTUALIO, FALSE)) {
        char probe[128];
        snprintf(probe, sizeof probe, "/vsimem/skysweep-probe-%ld%.16s", (long)getpid(),
                 has_ext ? strrchr(path, '.') : "");
        holds = probe_format(driver, probe, bands, type, create_opts, values, &side_cars);
        ss_gdal_errors_reset();
    }
    if (!holds) {
        char *probe = temporary_name(path, "probe");
        if (!probe)
            return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
        holds = probe_format(driver, probe, bands, type, create_opts, values, &side_cars);
        free(probe);
        if (!holds && ss_gdal_io_cause()) /* the folder, not the format, failed it */
            return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s': %s", path,
                           ss_gdal_failure(why, sizeof why));
        if (!holds)
            ss_gdal_failure(why, sizeof why);
        ss_gdal_errors_reset();
    }
    if (holds && side_cars && !has_ext)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "the %s format keeps side-car files named after the output's extension, "
                       "and '%s' has none: add one (e.g. %s.bin)",
                       format, path, path);
    /* The user's -co may be what failed it (PREDICTOR=9): say so, with GDAL's words. */
    if (!holds && create_opts && create_opts[0])
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "the %s format with the -co options given cannot hold this product (%d "
                       "%s band%s with nodata %g, read back unchanged): %s",
                       format, bands, type_name, bands == 1 ? "" : "s", values[0],
                       why[0] ? why : "no reason given");
    if (!holds)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "the %s format cannot hold this product (%d %s band%s with nodata %g, "
                       "read back unchanged%s%s); use -of %s",
                       format, bands, type_name, bands == 1 ? "" : "s", values[0],
                       why[0] ? ": " : "", why, SS_FORMATS_THAT_HOLD);
    return SS_OK;
}

/* What closing a file may allocate, at most: GDAL's compression of the
 * last tiles and the format's own structures. */
#define SS_ROOM_TO_CLOSE (16u << 20)

/* Not every library under GDAL survives a failed allocation: libgeotiff's
 * GTIFKeySet crashed writing a GeoTIFF's keys at close, finished or thrown
 * away, once a run under ulimit -v had taken all the room. A writer keeps
 * room for its close from the open (address space only: never touched)
 * and gives it back just before. */
static void release_reserve(ss_raster_writer *w)
{
    free(w->reserve);
    w->reserve = NULL;
}

/* The status of a GDAL call that failed while writing: out of memory
 * (ulimit -v) is the run's, not the output's. */
static ss_status write_failure(void)
{
    return ss_gdal_out_of_memory() ? SS_ERR_MEMORY : SS_ERR_OUTPUT;
}

static ss_status writer_open(ss_ctx *ctx, const char *path, const ss_dem *like, int bands,
                             const char *format, const char *const *creation_options,
                             int byte_pixels, ss_raster_writer **writer)
{
    *writer = NULL;
    ss_gdal_init();
    for (int i = 0; creation_options && creation_options[i]; ++i)
        if (!strchr(creation_options[i], '=') || creation_options[i][0] == '=')
            return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "-co expects KEY=VALUE, not '%s'",
                           creation_options[i]);
    GDALDriverH driver = GDALGetDriverByName(format ? format : "GTiff");
    if (!driver)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "unknown output format '%s' (-of)", format);
    char **meta = GDALGetMetadata(driver, NULL);
    int can_create = CSLFetchBoolean(meta, GDAL_DCAP_CREATE, FALSE);
    int can_copy = CSLFetchBoolean(meta, GDAL_DCAP_CREATECOPY, FALSE);
    if (!can_create && !can_copy)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "GDAL cannot write the '%s' format", format);
    /* An unknown key or a value the format does not take: GDAL would only
     * warn, and write the file without it. */
    CPLErrorReset();
    if (creation_options && creation_options[0] &&
        !GDALValidateCreationOptions(driver, (CSLConstList)creation_options))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "-co: %s",
                            CPLGetLastErrorMsg()[0] ? CPLGetLastErrorMsg()
                                                    : "not a creation option of this format");
    ss_status st = ss_output_check(ctx, path);
    if (st != SS_OK)
        return st;

    ss_raster_writer *w = calloc(1, sizeof *w);
    if (!w)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    w->ctx = ctx;
    w->byte_pixels = byte_pixels;
    w->driver = driver;
    w->bands = bands;
    char target[PATH_MAX]; /* fits: ss_output_check has resolved it */
    ss_output_target(path, target);
    w->path = strdup(target);
    if (w->path)
        ss_temporaries_track(w->path);
    w->tmp_path = temporary_name(path, "tmp");
    w->create_opts = default_options(driver, bands, byte_pixels, creation_options);
    w->reserve = malloc(SS_ROOM_TO_CLOSE);
    if (!w->path || !w->tmp_path || !w->reserve) {
        ss_writer_abort(w);
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    }
    GDALDataType type = byte_pixels ? GDT_Byte : GDT_Float32;
    ss_gdal_errors_reset();
    /* The user's creation options (NBITS=8 would lose values), not the
     * defaults: tiles of 256 x 256 made a probe of 2000 bands 0.5 GB. */
    st = check_format_holds(ctx, driver, format ? format : "GTiff", w->path, bands, type,
                            (char **)creation_options);
    if (st != SS_OK) {
        ss_writer_abort(w);
        return st;
    }
    const ss_grid *g = &like->grid;
    int windowed = like->window_cols > 0;
    int cols = windowed ? like->window_cols : g->width, rows = windowed ? like->window_rows : g->height;
    w->grid_width = g->width;
    w->col0 = windowed ? like->window_col0 : 0;
    w->row0 = windowed ? like->window_row0 : 0;
    if (can_create)
        w->ds = GDALCreate(driver, w->tmp_path, cols, rows, bands, type, w->create_opts);
    else
        w->ds = GDALCreate(GDALGetDriverByName("MEM"), "", cols, rows, bands, type, NULL);
    if (!w->ds) {
        char why[1200];
        /* Where the folder is not the cause, the -co options are: the probe
         * took them without the defaults they may clash with (BLOCKXSIZE=7
         * with TILED=YES), and this is still before any work. */
        if (creation_options && creation_options[0] && !ss_gdal_io_cause())
            st = ss_ctx_error(ctx, SS_ERR_ARGUMENT, "-co: the %s format cannot be written with "
                              "the options given: %s", format ? format : "GTiff",
                              ss_gdal_failure(why, sizeof why));
        else
            st = ss_ctx_error(ctx, write_failure(), "cannot create '%s': %s", path,
                              ss_gdal_failure(why, sizeof why));
        ss_writer_abort(w);
        return st;
    }
    /* Nodata before the georeferencing, as the probe (fill_probe). */
    for (int b = 1; b <= bands; ++b)
        GDALSetRasterNoDataValue(GDALGetRasterBand(w->ds, b), byte_pixels ? 0 : SS_NODATA);
    double gt[6];
    memcpy(gt, like->geotransform, sizeof gt);
    gt[0] += w->col0 * gt[1];
    gt[3] += w->row0 * gt[5];
    GDALSetGeoTransform(w->ds, gt);
    if (like->crs_wkt)
        GDALSetProjection(w->ds, like->crs_wkt);
    *writer = w;
    return SS_OK;
}

ss_status ss_writer_open(ss_ctx *ctx, const char *path, const ss_dem *like, int bands,
                         const char *format, const char *const *creation_options,
                         ss_raster_writer **writer)
{
    return writer_open(ctx, path, like, bands, format, creation_options, 0, writer);
}

ss_status ss_writer_open_byte(ss_ctx *ctx, const char *path, const ss_dem *like, int bands,
                              const char *format, const char *const *creation_options,
                              ss_raster_writer **writer)
{
    return writer_open(ctx, path, like, bands, format, creation_options, 1, writer);
}

/* v held in 1..255 (NaN taken as 1, as fmax takes it) and rounded half to
 * even, as nearbyint rounds: adding and taking away 2^23 leaves a float of
 * 0..2^23 rounded to an integer (the sum is stored first, so that it is
 * rounded to float even where the compiler keeps more precision). No libm
 * call, so the loop over a band's cells is a few instructions. */
static unsigned char byte_of(float v)
{
    float held = v > 1.0f ? (v < 255.0f ? v : 255.0f) : 1.0f;
    float shifted = held + 0x1p23f;
    return (unsigned char)(shifted - 0x1p23f);
}

ss_status ss_writer_rows(ss_raster_writer *w, int band, int row0, int n_rows,
                         const float *data)
{
    /* The rows handed in that fall in the file's window, its columns only. */
    int width = GDALGetRasterXSize(w->ds), height = GDALGetRasterYSize(w->ds);
    int lo = row0 > w->row0 ? row0 : w->row0;
    int hi = row0 + n_rows < w->row0 + height ? row0 + n_rows : w->row0 + height;
    if (lo >= hi)
        return SS_OK;
    data += (size_t)(lo - row0) * (size_t)w->grid_width + (size_t)w->col0;
    n_rows = hi - lo;
    row0 = lo - w->row0;
    size_t n = (size_t)width * (size_t)n_rows;
    for (int r = 0; r < n_rows; ++r)
        for (int c = 0; c < width; ++c)
            if (!isfinite(data[(size_t)r * w->grid_width + c]))
                return ss_ctx_error(w->ctx, SS_ERR_INTERNAL,
                               "refusing to write a non-finite value into band %d of '%s' "
                               "(a bug: please report it)",
                               band, w->path);
    GDALRasterBandH b = GDALGetRasterBand(w->ds, band);
    unsigned char *bytes = NULL;
    if (w->byte_pixels) {
        /* Values 1..255 round to the nearest byte; nodata becomes 0. */
        bytes = malloc(n);
        if (!bytes)
            return ss_ctx_error(w->ctx, SS_ERR_MEMORY, "out of memory writing '%s'", w->path);
        for (int r = 0; r < n_rows; ++r)
            for (int c = 0; c < width; ++c) {
                float v = data[(size_t)r * w->grid_width + c];
                bytes[(size_t)r * width + c] = v == SS_NODATA ? 0 : byte_of(v);
            }
    }
    ss_gdal_errors_reset();
    CPLErr err = bytes ? GDALRasterIO(b, GF_Write, 0, row0, width, n_rows, bytes, width, n_rows,
                                      GDT_Byte, 0, 0)
                       : GDALRasterIO(b, GF_Write, 0, row0, width, n_rows, (void *)data, width,
                                      n_rows, GDT_Float32, (int)sizeof(float),
                                      w->grid_width * (int)sizeof(float));
    free(bytes);
    char why[1200];
    if (err != CE_None || ss_gdal_failed())
        return ss_ctx_error(w->ctx, write_failure(), "cannot write band %d of '%s': %s", band, w->path,
                       ss_gdal_failure(why, sizeof why));
    return SS_OK;
}

void ss_writer_describe(ss_raster_writer *w, int band, const char *description, const char *unit)
{
    GDALRasterBandH b = GDALGetRasterBand(w->ds, band);
    if (description)
        GDALSetDescription(b, description);
    if (unit)
        GDALSetRasterUnitType(b, unit);
}

ss_status ss_writer_band(ss_raster_writer *w, int band, const float *data,
                         const char *description, const char *unit)
{
    ss_status st = ss_writer_rows(w, band, 0, w->row0 + GDALGetRasterYSize(w->ds), data);
    if (st == SS_OK)
        ss_writer_describe(w, band, description, unit);
    return st;
}

ss_status ss_writer_metadata(ss_raster_writer *w, const char *key, const char *value)
{
    GDALSetMetadataItem(w->ds, key, value, NULL);
    return SS_OK;
}

/* Moves a file and its .aux.xml, if it has one, the file last; returns as
 * move_files. */
static int rename_with_aux(const char *from, const char *to)
{
    char aux_from[PATH_MAX], aux_to[PATH_MAX];
    snprintf(aux_from, sizeof aux_from, "%s.aux.xml", from);
    snprintf(aux_to, sizeof aux_to, "%s.aux.xml", to);
    VSIStatBufL st;
    int aux = VSIStatL(aux_from, &st) == 0;
    char *froms[] = {aux_from, (char *)from, NULL}, *tos[] = {aux_to, (char *)to, NULL};
    return aux ? move_files(froms, tos) : move_files(froms + 1, tos + 1);
}

static int reads_back_as(const char *path, int cols, int rows, int bands)
{
    int err = errno; /* for ss_gdal_failure's cause, should this fail */
    GDALDatasetH ds = GDALOpen(path, GA_ReadOnly);
    int whole = ds && GDALGetRasterXSize(ds) == cols && GDALGetRasterYSize(ds) == rows &&
                GDALGetRasterCount(ds) == bands;
    if (ds)
        GDALClose(ds);
    errno = err;
    return whole;
}

ss_status ss_writer_commit(ss_raster_writer *w, ss_progress_fn progress, void *user)
{
    ss_ctx *ctx = w->ctx;
    ss_status st = SS_OK;
    char why[1200];
    release_reserve(w);
    ss_gdal_errors_reset();
    if (!CSLFetchBoolean(GDALGetMetadata(w->driver, NULL), GDAL_DCAP_CREATE, FALSE)) {
        GDALDatasetH copy = GDALCreateCopy(w->driver, w->tmp_path, w->ds, FALSE, w->create_opts,
                                           progress, user);
        if (copy)
            GDALClose(copy);
        if (!copy || ss_gdal_failed())
            st = ss_ctx_error(ctx, write_failure(), "cannot write '%s': %s", w->path,
                         ss_gdal_failure(why, sizeof why));
    }
    /* GDALClose flushes the file; an error here (disk full) loses the output. */
    int cols = GDALGetRasterXSize(w->ds), rows = GDALGetRasterYSize(w->ds);
    GDALClose(w->ds);
    w->ds = NULL;
    if (st == SS_OK && ss_gdal_failed())
        st = ss_ctx_error(ctx, write_failure(), "cannot finish writing '%s': %s", w->path,
                     ss_gdal_failure(why, sizeof why));
    /* Some drivers lose a failed write without a word (ENVI's header at
     * close): what was written must open as what was meant. */
    if (st == SS_OK && !reads_back_as(w->tmp_path, cols, rows, w->bands))
        st = ss_ctx_error(ctx, write_failure(), "cannot finish writing '%s': the file written does not "
                     "read back whole: %s", w->path, ss_gdal_failure(why, sizeof why));
    if (st == SS_OK && progress && !progress(1.0, "", user))
        st = ss_ctx_error(ctx, SS_ERR_CANCELLED, "cancelled while writing '%s'", w->path);
    if (st == SS_OK)
        ss_output_keep_mode(w->tmp_path, w->path);
    /* The side-cars a format keeps beside the file (.aux.xml, an ENVI .hdr,
     * a .prj) move along, named as the format expects. The names of an
     * output without an extension cannot be paired so; such an output is
     * one file (formats with side-cars refuse it at open) and perhaps its
     * .aux.xml, moved one by one. */
    int move = st == SS_OK ? has_extension(w->path) ? rename_own_files(w->tmp_path, w->path)
                                                     : rename_with_aux(w->tmp_path, w->path)
                            : 0;
    if (move > 0) /* a signal came as the file was finished */
        st = ss_ctx_error(ctx, SS_ERR_CANCELLED, "cancelled before moving '%s' into place", w->path);
    else if (move < 0)
        st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot move the finished output to '%s': %s", w->path,
                     ss_gdal_failure(why, sizeof why));
    ss_writer_abort(w);
    return st;
}

void ss_writer_abort(ss_raster_writer *w)
{
    if (!w)
        return;
    release_reserve(w);
    if (w->ds)
        ss_gdal_close_discarding(w->ds);
    char *dir, *base;
    if (w->path && split_path(w->path, &dir, &base) == 0) {
        remove_temporaries(dir, base, (long)getpid());
        free(dir);
        free(base);
    }
    if (w->path)
        ss_temporaries_forget(w->path);
    CSLDestroy(w->create_opts);
    free(w->path);
    free(w->tmp_path);
    free(w);
}
