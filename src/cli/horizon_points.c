/* Point mode of skysweep horizon (horizon_points.h): sites from --point or
 * a CSV file, placed on the DEM, their profiles computed by
 * ss_point_horizons and written as they finish. Output files are written
 * under a hidden temporary name and renamed when complete. */
#include "config.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "commands.h"
#include "horizon_crowns.h"
#include "horizon_far.h"
#include "horizon_formats.h"
#include "horizon_points.h"
#include "temporaries.h"
#include "text_input.h"
#include "temporary_name.h"

/* A million sites is far beyond a PV portfolio and keeps a typo'd file
 * from running for days. */
#define POINTS_MAX 1000000
/* A million sites of up to 256 bytes a line: a larger file is not a sites
 * file (and /dev/zero, one endless line, would be read for ever). */
#define POINTS_MAX_BYTES (256LL << 20)

typedef struct {
    const horizon_point_settings *pts;
    const char *dem_name;
    const ss_sweep_options *opt;
    ss_site_frame *sf;
    site_rec *sites;
    int n_sites;
    FILE *out;          /* NULL in folder mode */
    const char *folder; /* folder mode (--points with a PV file format): one file per site */
    const horizon_file_format *file_format; /* NULL for csv and json */
    horizon_far *far;   /* --far, or NULL */
    char sources[1300]; /* the DEM, and the far DEM, as the outputs name them */
    ss_status status;
    ss_ctx *ctx;
    int quiet;
    int true_north;
    double *cast_col, *cast_row, *cast_lon, *cast_lat; /* one profile's worth */
    ss_point_horizon_result *merged; /* with --far: one profile, near and far merged */
    /* --canopy: the trees, the placed sites, the highest crown top, one
     * profile's crown elevations and (--horizon-of canopy) its canopy
     * profile for the PV file. */
    const trees *trees;
    ss_grid ground; /* the DSM the crowns stand on */
    const ss_point_site *psites;
    double max_top_m;
    double *crown_deg;
    ss_point_horizon_result *canopy;
} writer;

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

/* A field without its blanks and the quotes a spreadsheet may add. */
static char *unquote(char *s)
{
    s = trim(s);
    size_t n = strlen(s);
    if (n >= 2 && s[0] == '"' && s[n - 1] == '"') {
        s[n - 1] = '\0';
        s++;
    }
    return s;
}

static int parse_number(const char *text, double *v)
{
    char *end;
    *v = strtod(text, &end);
    return end != text && *end == '\0' && isfinite(*v);
}

/* Ids go into CSV fields (where '#' would start a pandas comment), JSON
 * strings and (pvgis folders) file names, so they keep to printable
 * characters that need no quoting. */
static const char *id_problem(const char *id, int as_file_name)
{
    if (!*id)
        return "is empty";
    if (strlen(id) > ID_MAX)
        return "is longer than 200 characters";
    for (const char *p = id; *p; ++p) {
        unsigned char c = (unsigned char)*p;
        if (c < 0x20 || c == 0x7f || c == '"' || c == '#' || c == '\\' || c == ',')
            return "holds a control character, a quote, '#', '\\' or ','";
        if (as_file_name && !(isalnum(c) || c == '-' || c == '_' || c == '.'))
            return "must keep to letters, digits, '-', '_' and '.' to name a file";
    }
    if (as_file_name && id[0] == '.')
        return "must not start with '.' to name a file";
    return NULL;
}

static int column_of(char **names, int n, const char *a, const char *b)
{
    for (int i = 0; i < n; ++i)
        if (strcasecmp(names[i], a) == 0 || (b && strcasecmp(names[i], b) == 0))
            return i;
    return -1;
}

static int split(char *line, char **fields, int max)
{
    int n = 0;
    for (char *p = line; n < max;) {
        char *comma = strchr(p, ',');
        if (comma)
            *comma = '\0';
        fields[n++] = unquote(p);
        if (!comma)
            break;
        p = comma + 1;
    }
    return n;
}

static int compare_ids(const void *a, const void *b)
{
    return strcmp(((const site_rec *)a)->id, ((const site_rec *)b)->id);
}

ss_status horizon_sites_read(ss_ctx *ctx, const char *path, double default_height_m,
                             int ids_as_files, site_rec **out, int *n_out)
{
    char why[512];
    if (!ss_text_input_ok(path, "sites file", POINTS_MAX_BYTES, why, sizeof why))
        return ss_ctx_error(ctx, SS_ERR_INPUT, "%s", why);
    FILE *f = fopen(path, "r");
    if (!f)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot open the sites file '%s'", path);
    char *line = NULL;
    size_t cap = 0;
    int col_id = -1, col_x = -1, col_y = -1, col_h = -1, n_cols = 0, n = 0, lineno = 0;
    site_rec *sites = NULL;
    ss_status st = SS_OK;
    while (st == SS_OK && getline(&line, &cap, f) >= 0) {
        lineno++;
        char *fields[64];
        /* A spreadsheet's UTF-8 byte order mark would hide the first name. */
        char *s = trim(lineno == 1 && strncmp(line, "\xEF\xBB\xBF", 3) == 0 ? line + 3 : line);
        if (!*s || *s == '#')
            continue;
        int nf = split(s, fields, 64);
        if (n_cols == 0) {
            n_cols = nf;
            col_id = column_of(fields, nf, "id", NULL);
            col_x = column_of(fields, nf, "lon", "x");
            col_y = column_of(fields, nf, "lat", "y");
            col_h = column_of(fields, nf, "height", NULL);
            if (col_id < 0 || col_x < 0 || col_y < 0)
                st = ss_ctx_error(ctx, SS_ERR_INPUT,
                         "%s line %d: the header must name the columns id, lon, lat "
                         "(or id, x, y) and optionally height",
                         path, lineno);
            continue;
        }
        if (nf != n_cols) {
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "%s line %d: %d fields, the header has %d", path, lineno,
                     nf, n_cols);
            break;
        }
        if (n >= POINTS_MAX) {
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "%s: more than %d sites", path, POINTS_MAX);
            break;
        }
        if (n % 1024 == 0) {
            site_rec *grown = realloc(sites, sizeof *sites * (size_t)(n + 1024));
            if (!grown) {
                st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", path);
                break;
            }
            sites = grown;
        }
        site_rec *r = &sites[n];
        memset(r, 0, sizeof *r);
        const char *bad_id = id_problem(fields[col_id], ids_as_files);
        r->height_m = default_height_m;
        if (bad_id)
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "%s line %d: id '%.40s' %s", path, lineno, fields[col_id],
                     bad_id);
        else if (!parse_number(fields[col_x], &r->x) || !parse_number(fields[col_y], &r->y))
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "%s line %d: '%s,%s' are not two numbers", path, lineno,
                     fields[col_x], fields[col_y]);
        else if (col_h >= 0 && *fields[col_h] &&
                 (!parse_number(fields[col_h], &r->height_m) || r->height_m < 0 ||
                  r->height_m > 1e6))
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "%s line %d: height '%s' is not 0 to 1e6 m", path, lineno,
                     fields[col_h]);
        else
            snprintf(r->id, sizeof r->id, "%s", fields[col_id]);
        n++;
    }
    free(line);
    fclose(f);
    if (st == SS_OK && n == 0)
        st = ss_ctx_error(ctx, SS_ERR_INPUT, "%s holds no sites", path);
    if (st == SS_OK) {
        /* Duplicate ids would make the output ambiguous (and overwrite
         * pvgis files): sorted copy, neighbours compared. */
        site_rec *sorted = malloc(sizeof *sorted * (size_t)n);
        if (!sorted)
            st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory checking ids");
        else {
            memcpy(sorted, sites, sizeof *sorted * (size_t)n);
            qsort(sorted, (size_t)n, sizeof *sorted, compare_ids);
            for (int i = 1; i < n && st == SS_OK; ++i)
                if (strcmp(sorted[i].id, sorted[i - 1].id) == 0)
                    st = ss_ctx_error(ctx, SS_ERR_INPUT, "%s: the id '%s' is given twice", path,
                             sorted[i].id);
            free(sorted);
        }
    }
    if (st != SS_OK) {
        free(sites);
        return st;
    }
    *out = sites;
    *n_out = n;
    return SS_OK;
}

/* Creates path's temporary (*tmp, to be freed), known to the stop guard
 * until commit_file. */
static FILE *open_temporary(const char *path, char **tmp)
{
    ss_temporaries_track(path);
    *tmp = ss_temporary_name(path, "tmp");
    FILE *f = *tmp ? fopen(*tmp, "w") : NULL;
    if (!f)
        ss_temporaries_forget(path);
    return f;
}

static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; ++s) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static void model_text(const ss_sweep_options *opt, char *buf, size_t n)
{
    int used =
        snprintf(buf, n, "%s lines, ", ss_line_model_name(opt->lines));
    if (opt->earth_radius_m > 0)
        snprintf(buf + used, n - used,
                 "earth curvature on (R = %.0f m, refraction k = %.3f, R_eff = %.0f m)",
                 opt->earth_radius_m, opt->refraction_k,
                 opt->earth_radius_m / (1.0 - opt->refraction_k));
    else
        snprintf(buf + used, n - used, "earth curvature and refraction off");
}

/* %s: how azimuths are reckoned. */
static const char *const conventions =
    "azimuth_deg clockwise from %s; elevation_deg above the horizontal at the observer, "
    "negative below it, -90 where no terrain lies ahead inside the DEM; distance_m horizontal "
    "from the site to the horizon-casting point; cast_lon, cast_lat WGS84 degrees; heights in "
    "the DEM's vertical datum";

/* With --canopy: the two more columns. */
static const char *const canopy_conventions =
    "canopy_elevation_deg: the higher of elevation_deg and crown_elevation_deg; "
    "crown_elevation_deg: the highest crown top ahead (ground + canopy height), each cell the "
    "ray crosses taken where the ray enters it, the site's own cell left out; -90 where no crown "
    "lies ahead";

static const char *north_text(const writer *w)
{
    return w->true_north ? "true north (the meridian convergence at each site taken out)"
                         : "grid north (--north grid)";
}

static void write_head(writer *w)
{
    const horizon_point_settings *pts = w->pts;
    char model[200];
    model_text(w->opt, model, sizeof model);
    if (pts->format == POINT_FORMAT_CSV) {
        fprintf(w->out, "# skysweep %s horizon profiles of %s\n# ", ss_version(), w->sources);
        fprintf(w->out, conventions, north_text(w));
        fprintf(w->out, "\n# model: %s; step %.10g deg\n", model, 360.0 / w->opt->directions);
        if (w->trees)
            fprintf(w->out, "# %s\n", canopy_conventions);
        fprintf(w->out, "id,azimuth_deg,elevation_deg,distance_m,cast_lon,cast_lat,cast_height_m%s\n",
                w->trees ? ",canopy_elevation_deg,crown_elevation_deg" : "");
    } else if (pts->format == POINT_FORMAT_JSON) {
        fprintf(w->out, "{\n  \"skysweep\": \"%s\",\n  \"dem\": ", ss_version());
        json_string(w->out, w->dem_name);
        if (w->far) {
            fprintf(w->out, ",\n  \"far_dem\": ");
            json_string(w->out, horizon_far_name(w->far));
        }
        if (w->trees) {
            fprintf(w->out, ",\n  \"canopy\": ");
            json_string(w->out, w->pts->trees->canopy);
        }
        fprintf(w->out, ",\n  \"conventions\": \"");
        fprintf(w->out, conventions, north_text(w));
        if (w->trees)
            fprintf(w->out, "; %s", canopy_conventions);
        fprintf(w->out, "\",\n  \"model\": \"%s\",\n", model);
        fprintf(w->out,
                "  \"line_model\": \"%s\", \"earth_radius_m\": %.0f, \"refraction_k\": %.3f, "
                "\"step_deg\": %.10g,\n  \"sites\": [",
                ss_line_model_name(w->opt->lines),
                w->opt->earth_radius_m, w->opt->refraction_k, 360.0 / w->opt->directions);
    }
}

static void write_site_csv(writer *w, const site_rec *s, const ss_point_horizon_result *p)
{
    fprintf(w->out, "# site id=%s lon=%.8f lat=%.8f ground_height_m=%.3f observer_height_m=%.3f",
            s->id, s->lon_deg, s->lat_deg, s->ground_m, s->height_m);
    if (w->far) {
        double ground, eye;
        horizon_far_site(w->far, (int)(s - w->sites), &ground, &eye);
        fprintf(w->out, " far_ground_height_m=%.3f far_observer_height_m=%.3f", ground, eye);
    }
    fputc('\n', w->out);
    for (int i = 0; i < w->opt->directions; ++i) {
        fprintf(w->out, "%s,%.10g,%.6f,%.1f,", s->id, p[i].azimuth_deg, p[i].elevation_deg,
                p[i].distance_m);
        if (isfinite(w->cast_lon[i]))
            fprintf(w->out, "%.8f,%.8f,%.2f", w->cast_lon[i], w->cast_lat[i], p[i].cast_height_m);
        else
            fprintf(w->out, ",,");
        if (w->trees)
            fprintf(w->out, ",%.6f,%.6f", fmax(p[i].elevation_deg, w->crown_deg[i]),
                    w->crown_deg[i]);
        fputc('\n', w->out);
    }
}

/* decimals < 0: up to 10 significant digits. */
static void json_array(FILE *f, const char *name, const double *v, int n, int decimals, int last)
{
    fprintf(f, "      \"%s\": [", name);
    for (int i = 0; i < n; ++i) {
        if (i)
            fputc(',', f);
        if (isfinite(v[i]) && decimals < 0)
            fprintf(f, "%.10g", v[i]);
        else if (isfinite(v[i]))
            fprintf(f, "%.*f", decimals, v[i]);
        else
            fputs("null", f);
    }
    fprintf(f, "]%s\n", last ? "" : ",");
}

static void write_site_json(writer *w, int index, const site_rec *s,
                            const ss_point_horizon_result *p)
{
    int n = w->opt->directions;
    fprintf(w->out, "%s\n    {\"id\": ", index ? "," : "");
    json_string(w->out, s->id);
    fprintf(w->out,
            ", \"lon\": %.8f, \"lat\": %.8f, \"ground_height_m\": %.3f, "
            "\"observer_height_m\": %.3f,\n",
            s->lon_deg, s->lat_deg, s->ground_m, s->height_m);
    /* The per-direction columns, gathered into the cast_* buffers' space. */
    double *col = malloc(sizeof *col * (size_t)n);
    if (!col) {
        w->status = ss_ctx_error(w->ctx, SS_ERR_MEMORY, "out of memory writing JSON");
        return;
    }
    const char *names[] = {"azimuth_deg", "elevation_deg", "distance_m", "cast_height_m"};
    const int decimals[] = {-1, 6, 1, 2};
    for (int k = 0; k < 4; ++k) {
        for (int i = 0; i < n; ++i)
            col[i] = k == 0   ? p[i].azimuth_deg
                     : k == 1 ? p[i].elevation_deg
                     : k == 2 ? p[i].distance_m
                              : p[i].cast_height_m;
        json_array(w->out, names[k], col, n, decimals[k], 0);
    }
    json_array(w->out, "cast_lon", w->cast_lon, n, 8, 0);
    json_array(w->out, "cast_lat", w->cast_lat, n, 8, !w->trees);
    if (w->trees) {
        for (int i = 0; i < n; ++i)
            col[i] = fmax(p[i].elevation_deg, w->crown_deg[i]);
        json_array(w->out, "canopy_elevation_deg", col, n, 6, 0);
        json_array(w->out, "crown_elevation_deg", w->crown_deg, n, 6, 1);
    }
    fprintf(w->out, "    }");
    free(col);
}

/* Finishes a temporary file: close, and rename over path when all went well. */
static ss_status commit_file(ss_ctx *ctx, FILE *f, const char *tmp, const char *path, ss_status st)
{
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (st == SS_OK && bad)
        st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s'", path);
    if (st == SS_OK && !ss_temporaries_hold()) /* a signal came as the file was finished */
        st = ss_ctx_error(ctx, SS_ERR_CANCELLED, "cancelled before moving '%s' into place", path);
    else if (st == SS_OK) {
        int moved = ss_output_rename(tmp, path) == 0;
        ss_temporaries_release();
        if (!moved)
            st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename the finished output to '%s'", path);
    }
    if (st != SS_OK)
        remove(tmp);
    ss_temporaries_forget(path);
    return st;
}

static void write_pv_file(const writer *w, FILE *f, const site_rec *s,
                          const ss_point_horizon_result *p)
{
    horizon_file_site site = {s->id, s->lon_deg, s->lat_deg, w->sources};
    w->file_format->write(f, &site, p, w->opt->directions);
}

ss_status horizon_file_write(ss_ctx *ctx, const horizon_file_format *format, const char *path,
                             const horizon_file_site *site, const ss_point_horizon_result *p,
                             int n)
{
    char *tmp;
    FILE *f = open_temporary(path, &tmp);
    if (!f) {
        free(tmp);
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot create '%s'", path);
    }
    format->write(f, site, p, n);
    ss_status st = commit_file(ctx, f, tmp, path, SS_OK);
    free(tmp);
    return st;
}

/* Folder mode: the site's file, ID plus the format's extension. */
static ss_status write_site_file(writer *w, const site_rec *s, const ss_point_horizon_result *p)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s%s", w->folder, s->id, w->file_format->extension);
    horizon_file_site site = {s->id, s->lon_deg, s->lat_deg, w->sources};
    return horizon_file_write(w->ctx, w->file_format, path, &site, p, w->opt->directions);
}

/* The site's crown elevations into w->crown_deg; returns the profile the
 * site's PV file holds: the solid one, or with --horizon-of canopy the
 * higher of it (far terrain merged) and the crowns per azimuth. */
static const ss_point_horizon_result *crowns_of_site(writer *w, int index,
                                                     const ss_point_horizon_result *p)
{
    const site_rec *s = &w->sites[index];
    crowns_profile(&w->ground, &w->trees->canopy, &w->psites[index], s->ground_m + s->height_m,
                   w->max_top_m, w->opt, w->crown_deg);
    if (!w->canopy)
        return p;
    for (int i = 0; i < w->opt->directions; ++i) {
        w->canopy[i] = p[i];
        w->canopy[i].elevation_deg = fmax(p[i].elevation_deg, w->crown_deg[i]);
    }
    return w->canopy;
}

static int store_site(int index, const ss_point_horizon_result *p, void *user)
{
    writer *w = user;
    const site_rec *s = &w->sites[index];
    int n = w->opt->directions, none = 0;
    for (int i = 0; i < n; ++i) {
        w->cast_col[i] = p[i].cast_col;
        w->cast_row[i] = p[i].cast_row;
    }
    w->status = ss_site_lonlat(w->sf, n, w->cast_col, w->cast_row, w->cast_lon, w->cast_lat);
    if (w->status == SS_OK && w->far) {
        int far_wins;
        memcpy(w->merged, p, sizeof *p * (size_t)n);
        p = w->merged;
        w->status = horizon_far_merge(w->far, index, w->opt, w->merged, w->cast_lon, w->cast_lat,
                                      &far_wins);
    }
    if (w->status != SS_OK)
        return 0;
    if (w->trees)
        p = crowns_of_site(w, index, p);
    for (int i = 0; i < n; ++i)
        none += p[i].distance_m == 0.0;
    if (none && !w->quiet)
        fprintf(stderr,
                "skysweep horizon: warning: site '%s': at %d of %d azimuths no terrain lies "
                "ahead inside the DEM%s (the site is at its edge); their elevation is -90\n",
                s->id, none, n, w->far ? "s" : "");
    if (w->pts->format == POINT_FORMAT_CSV)
        write_site_csv(w, s, p);
    else if (w->pts->format == POINT_FORMAT_JSON)
        write_site_json(w, index, s, p);
    else if (w->folder)
        w->status = write_site_file(w, s, p);
    else
        write_pv_file(w, w->out, s, p);
    return w->status == SS_OK;
}

static int parse_pair(const char *text, double *x, double *y)
{
    char *end;
    *x = strtod(text, &end);
    if (end == text || *end != ',')
        return 0;
    const char *second = end + 1;
    *y = strtod(second, &end);
    return end != second && *end == '\0' && isfinite(*x) && isfinite(*y);
}

static int is_folder(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 && S_ISDIR(sb.st_mode);
}

/* Places every site on the DEM (refusing any outside it or on nodata) and
 * fills the point sites: position, observer height, grid north. */
static ss_status place_sites(run_state *run, const common_settings *common,
                             ss_dem_frame *frame, ss_site_frame *sf, const ss_point_grid *pg,
                             site_rec *sites, int n, ss_point_site *out)
{
    for (int i = 0; i < n; ++i) {
        site_rec *s = &sites[i];
        ss_point_site *p = &out[i];
        ss_status st = ss_site_locate(sf, s->x, s->y, &p->col, &p->row);
        if (st == SS_OK)
            st = ss_site_lonlat(sf, 1, &p->col, &p->row, &s->lon_deg, &s->lat_deg);
        if (st == SS_OK)
            st = ss_point_ground_height(run->ctx, pg, p->col, p->row, &s->ground_m);
        p->observer_height_m = s->height_m;
        p->grid_north_deg = 0.0;
        if (st == SS_OK && common->sweep.north != SS_NORTH_GRID)
            st = ss_geo_grid_north(frame->geo, p->col, p->row, &p->grid_north_deg);
        if (st != SS_OK)
            return n > 1 ? ss_ctx_error(run->ctx, st, "id '%s': %s", s->id, ss_ctx_message(run->ctx)) : st;
    }
    return SS_OK;
}

static const char *format_name(const horizon_point_settings *pts)
{
    static const char *const names[] = {"csv", "json", "pvgis", "pvsyst", "pvsol", "helioscope",
                                        "sam"};
    return names[pts->format];
}

/* Checks the settings; returns 0 or the usage error's exit code. */
static int check_settings(const horizon_point_settings *pts, int north_grid, const char *output,
                          int *directions)
{
    double x, y;
    if ((pts->point != NULL) == (pts->points != NULL))
        return run_usage_error("horizon", "give one of --point X,Y and --points FILE");
    if (pts->point && !parse_pair(pts->point, &x, &y))
        return run_usage_error("horizon", "--point expects X,Y (longitude,latitude in degrees "
                                          "unless --point-crs), e.g. -155.25,19.4");
    double n = 360.0 / pts->step_deg;
    if (!(pts->step_deg > 0) || fabs(n - nearbyint(n)) > 1e-9 * n || nearbyint(n) > 1e6)
        return run_usage_error("horizon", "--step must divide 360 degrees into a whole number "
                                          "of steps (at most a million), e.g. 1, 0.5, 0.1");
    *directions = (int)nearbyint(n);
    if (pts->format > POINT_FORMAT_JSON && pts->points && (!output || !is_folder(output))) {
        char why[200];
        snprintf(why, sizeof why, "--format %s with --points writes one file per site: OUTPUT "
                 "must be an existing folder", format_name(pts));
        return run_usage_error("horizon", why);
    }
    if (pts->horizon_of == HORIZON_OF_CANOPY && !pts->trees)
        return run_usage_error("horizon", "--horizon-of canopy needs --canopy");
    if (pts->horizon_of == HORIZON_OF_CANOPY && pts->format <= POINT_FORMAT_JSON)
        return run_usage_error("horizon", "--horizon-of is for the PV formats: csv and json "
                                          "carry both profiles (canopy_elevation_deg)");
    if (pts->far && north_grid)
        return run_usage_error("horizon", "--far takes true north: the two DEMs' grid norths "
                                          "differ (leave out --north grid)");
    return 0;
}

/* --far: the far DEM, the sites on it and the merged profile's room; the
 * sources PV files name. */
static ss_status open_far(writer *w, const char *path, const site_rec *sites, int n_sites,
                          int directions)
{
    ss_status st = horizon_far_open(w->ctx, path, directions, &w->far);
    if (st == SS_OK)
        st = horizon_far_place(w->far, sites, n_sites, 1);
    if (st == SS_OK && !(w->merged = malloc(sizeof *w->merged * (size_t)directions)))
        st = ss_ctx_error(w->ctx, SS_ERR_MEMORY, "out of memory for merged profiles");
    return st;
}

/* Everything one point run holds, released by point_job_close. */
typedef struct {
    run_state run;
    ss_dem dem;
    ss_dem_frame frame;
    int have_dem;
    site_rec one, *sites;
    int n_sites;
    ss_site_frame *sf;
    ss_point_grid *pg;
    ss_point_site *psites;
    ss_sweep_options opt;
    trees tr; /* --canopy */
    writer w;
    char *tmp; /* the output's temporary name */
} point_job;

/* --canopy: the trees on the DEM's grid (held whole for the sites), the
 * highest crown top and one profile's room. */
static ss_status open_crowns(point_job *j, const horizon_point_settings *pts, int directions)
{
    writer *w = &j->w;
    ss_status st = trees_read(j->run.ctx, &j->dem, j->dem.grid.z, pts->trees, &j->tr);
    if (st != SS_OK)
        return st;
    w->trees = &j->tr;
    w->ground = j->dem.grid;
    w->psites = j->psites;
    w->max_top_m = crowns_max_top(&w->ground, &j->tr.canopy);
    w->crown_deg = malloc(sizeof *w->crown_deg * (size_t)directions);
    if (pts->horizon_of == HORIZON_OF_CANOPY)
        w->canopy = malloc(sizeof *w->canopy * (size_t)directions);
    if (!w->crown_deg || (pts->horizon_of == HORIZON_OF_CANOPY && !w->canopy))
        return ss_ctx_error(j->run.ctx, SS_ERR_MEMORY, "out of memory for the crowns' profiles");
    return SS_OK;
}

/* Reads sites and DEM, places the sites and opens the output. */
static ss_status point_job_setup(point_job *j, const common_settings *common,
                                 const horizon_point_settings *pts, const char **pos, int n_inputs,
                                 const char *output, int directions)
{
    writer *w = &j->w;
    w->ctx = j->run.ctx;
    w->file_format = horizon_file_format_named(format_name(pts));
    int folder_mode = w->file_format && pts->points;
    ss_status st = SS_OK;
    if (pts->points) {
        st = horizon_sites_read(w->ctx, pts->points, pts->height_m, folder_mode, &j->sites, &j->n_sites);
    } else {
        snprintf(j->one.id, sizeof j->one.id, "site");
        j->one.height_m = pts->height_m;
        parse_pair(pts->point, &j->one.x, &j->one.y); /* checked by check_settings */
        j->sites = &j->one;
        j->n_sites = 1;
    }
    if (st == SS_OK &&
        (st = run_read_dem(&j->run, pos, n_inputs, common, &j->dem, &j->frame)) == SS_OK)
        j->have_dem = 1;
    if (st == SS_OK && !j->frame.georeferenced)
        st = ss_ctx_error(w->ctx, SS_ERR_INPUT, "'%s' is not georeferenced: sites need a DEM with a CRS",
                 pos[0]);
    if (st == SS_OK) {
        run_sweep_options(common, &j->frame, &j->opt);
        j->opt.directions = directions;
        j->opt.offset_deg = 0.0;
        st = ss_site_frame_open(j->run.ctx, &j->dem, pts->point_crs, &j->sf);
    }
    if (st == SS_OK)
        st = ss_point_grid_new(j->run.ctx, &j->dem.grid, &j->pg);
    if (st == SS_OK) {
        j->psites = malloc(sizeof *j->psites * (size_t)j->n_sites);
        w->cast_col = malloc(sizeof(double) * (size_t)directions * 4);
        if (!j->psites || !w->cast_col)
            st = ss_ctx_error(w->ctx, SS_ERR_MEMORY, "out of memory for %d sites", j->n_sites);
    }
    if (st == SS_OK)
        st = place_sites(&j->run, common, &j->frame, j->sf, j->pg, j->sites, j->n_sites,
                         j->psites);
    if (st == SS_OK && pts->far)
        st = open_far(w, pts->far, j->sites, j->n_sites, directions);
    if (st == SS_OK && pts->trees)
        st = open_crowns(j, pts, directions);
    if (st != SS_OK)
        return st;
    w->pts = pts;
    w->dem_name = j->dem.description;
    w->opt = &j->opt;
    w->sf = j->sf;
    w->sites = j->sites;
    w->n_sites = j->n_sites;
    w->ctx = j->run.ctx;
    w->quiet = common->quiet;
    w->true_north = common->sweep.north != SS_NORTH_GRID;
    w->cast_row = w->cast_col + directions;
    w->cast_lon = w->cast_row + directions;
    w->cast_lat = w->cast_lon + directions;
    if (w->far)
        snprintf(w->sources, sizeof w->sources,
                 "near %s merged with the far terrain %s (the larger elevation per azimuth)",
                 j->dem.description, horizon_far_name(w->far));
    else
        snprintf(w->sources, sizeof w->sources, "%s", j->dem.description);
    if (w->canopy) {
        size_t used = strlen(w->sources);
        snprintf(w->sources + used, sizeof w->sources - used,
                 ", with the crowns of %.400s (canopy horizon)", pts->trees->canopy);
    }
    w->folder = folder_mode ? output : NULL;
    w->out = folder_mode ? NULL : stdout;
    if (output && !folder_mode && (st = ss_output_check(w->ctx, output)) == SS_OK) {
        w->out = open_temporary(output, &j->tmp);
        if (!w->out)
            st = ss_ctx_error(w->ctx, SS_ERR_OUTPUT, "cannot create '%s'", output);
    }
    return st;
}

static void point_job_close(point_job *j)
{
    free(j->w.cast_col);
    free(j->w.merged);
    free(j->w.crown_deg);
    free(j->w.canopy);
    trees_free(&j->tr);
    horizon_far_close(j->w.far);
    free(j->psites);
    free(j->tmp);
    ss_point_grid_free(j->pg);
    ss_site_frame_close(j->sf);
    if (j->have_dem) {
        ss_dem_frame_close(&j->frame);
        ss_dem_free(&j->dem);
    }
    if (j->sites != &j->one)
        free(j->sites);
    run_end(&j->run);
}

int horizon_points_run(const common_settings *common, const horizon_point_settings *pts,
                       const char **pos, int n_pos)
{
    /* One positional: the DEM, profiles on stdout. More: OUTPUT last. */
    int n_inputs = n_pos > 1 ? n_pos - 1 : n_pos;
    const char *output = n_pos > 1 && strcmp(pos[n_pos - 1], "-") != 0 ? pos[n_pos - 1] : NULL;
    int directions = 0;
    int rc = check_settings(pts, common->sweep.north == SS_NORTH_GRID, output, &directions);
    if (rc)
        return rc;
    point_job j;
    memset(&j, 0, sizeof j);
    if ((rc = run_begin(&j.run, "horizon", common)))
        return rc;
    writer *w = &j.w;
    ss_status st = point_job_setup(&j, common, pts, pos, n_inputs, output, directions);
    if (st == SS_OK) {
        write_head(w);
        st = ss_point_horizons(j.run.ctx, j.pg, &j.opt, j.psites, j.n_sites, store_site, w);
        if (w->status != SS_OK)
            st = w->status;
        if (st == SS_OK && pts->format == POINT_FORMAT_JSON)
            fprintf(w->out, "\n  ]\n}\n");
    }
    if (w->out && w->out != stdout)
        st = commit_file(w->ctx, w->out, j.tmp, output, st);
    else if (w->out)
        fflush(stdout);
    rc = st == SS_OK ? 0 : run_fail(&j.run, st);
    if (st == SS_OK && !common->quiet && output) {
        run_print_dem(&j.run, &j.dem, &j.frame);
        printf("horizon profiles of %d site%s x %d azimuths (step %.10g deg) -> %s (%s)\n",
               j.n_sites, j.n_sites > 1 ? "s" : "", directions, pts->step_deg, output,
               format_name(pts));
    }
    point_job_close(&j);
    return rc;
}

ss_status site_horizon_open(site_horizon *sh, ss_ctx *ctx, const char *dem_path, double lon_deg,
                            double lat_deg, const site_horizon_settings *set)
{
    memset(sh, 0, sizeof *sh);
    sh->ctx = ctx;
    const char *paths[] = {dem_path};
    ss_status st = ss_dem_read(ctx, paths, 1, NULL, &sh->dem);
    if (st == SS_OK && (st = ss_dem_frame_open(ctx, &sh->dem, &sh->frame)) != SS_OK)
        ss_dem_free(&sh->dem);
    sh->have_dem = st == SS_OK;
    if (st == SS_OK)
        st = ss_site_frame_open(ctx, &sh->dem, NULL, &sh->sf);
    if (st == SS_OK)
        st = ss_site_locate(sh->sf, lon_deg, lat_deg, &sh->site.col, &sh->site.row);
    if (st == SS_OK)
        st = ss_point_grid_new(ctx, &sh->dem.grid, &sh->pg);
    if (st == SS_OK)
        st = ss_point_ground_height(ctx, sh->pg, sh->site.col, sh->site.row, &sh->ground_m);
    if (st == SS_OK)
        st = ss_geo_grid_north(sh->frame.geo, sh->site.col, sh->site.row, &sh->site.grid_north_deg);
    sh->site.observer_height_m = set->height_m;
    ss_sweep_options_default(&sh->opt);
    sh->opt.directions = 1;
    sh->opt.lines = (ss_line_model)set->lines;
    sh->opt.earth_radius_m = set->curvature ? sh->frame.earth_radius_m : 0.0;
    sh->opt.refraction_k = set->curvature ? set->refraction_k : 0.0;
    return st;
}

ss_status site_horizon_at(site_horizon *sh, double azimuth_deg, double *elevation_deg)
{
    ss_point_horizon_result r;
    sh->opt.offset_deg = azimuth_deg;
    ss_status st = ss_point_horizon(sh->ctx, sh->pg, &sh->opt, &sh->site, &r);
    *elevation_deg = st == SS_OK ? r.elevation_deg : NAN;
    return st;
}

void site_horizon_describe(const site_horizon *sh, char *buf, size_t size)
{
    char model[200];
    model_text(&sh->opt, model, sizeof model);
    snprintf(buf, size,
             "terrain horizon of %s exactly at the sun's azimuth: %s, observer %g m "
             "above the ground",
             sh->dem.description, model, sh->site.observer_height_m);
}

void site_horizon_close(site_horizon *sh)
{
    ss_point_grid_free(sh->pg);
    ss_site_frame_close(sh->sf);
    if (sh->have_dem) {
        ss_dem_frame_close(&sh->frame);
        ss_dem_free(&sh->dem);
    }
    sh->pg = NULL;
    sh->sf = NULL;
    sh->have_dem = 0;
}
