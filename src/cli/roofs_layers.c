/* The layers skysweep roofs writes: the GeoPackage's buildings, roof_planes,
 * panels and plane_shade with their fields, the CSV of the planes, the
 * shade masks and the kept per-cell raster (doc/roofs.md). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crown_light.h"
#include "roofs.h"
#include "temporaries.h"
#include "temporary_name.h"

static const char *const month_abbr[12] = {"jan", "feb", "mar", "apr", "may", "jun",
                                           "jul", "aug", "sep", "oct", "nov", "dec"};

/* Suitability after sonnendach.ch's classes of annual irradiation. */
static int suitability_class(double kwh_m2)
{
    return !isfinite(kwh_m2) ? 0 : kwh_m2 < 800 ? 1 : kwh_m2 < 1000 ? 2 : kwh_m2 < 1200 ? 3
                                                   : kwh_m2 < 1400 ? 4
                                                                   : 5;
}
static const char *const class_names[6] = {"none", "low", "medium", "good", "very good",
                                           "excellent"};

#define PLANE_FIELDS 33
#define BUILDING_FIELDS 31
#define PANEL_FIELDS 7
#define SHADE_FIELDS 7
static ss_field plane_fields[PLANE_FIELDS], building_fields[BUILDING_FIELDS],
    panel_fields[PANEL_FIELDS], shade_fields[SHADE_FIELDS];
static char month_names[2][12][24];

static int common_fields(ss_field *f, int n, int slot)
{
    f[n++] = (ss_field){"usable_area_m2", SS_FIELD_REAL, "m2",
                        "true (3D) area of the usable cells: clear of edges and obstacles by the "
                        "setback, at least the minimum irradiation, tilt at most the maximum"};
    f[n++] = (ss_field){"n_panels", SS_FIELD_INT, "", "modules laid on the usable cells"};
    f[n++] = (ss_field){"kwp", SS_FIELD_REAL, "kWp", "n_panels x the module's power"};
    f[n++] = (ss_field){"kwh_ac_year", SS_FIELD_REAL, "kWh/year",
                        "AC energy of the modules: each its kWp x the mean AC kWh/kWp of the "
                        "cells it covers (PVWatts, as insolation --pv)"};
    f[n++] = (ss_field){"kwh_dc_year", SS_FIELD_REAL, "kWh/year",
                        "DC energy of the modules, after the system losses, before the inverter: "
                        "each its kWp x the mean DC kWh/kWp of the cells it covers (insolation "
                        "--pv's pv_yield)"};
    f[n++] = (ss_field){"kwh_per_kwp", SS_FIELD_REAL, "kWh/kWp/year", "kwh_ac_year / kwp"};
    for (int m = 0; m < 12; ++m) {
        snprintf(month_names[slot][m], sizeof month_names[slot][m], "kwh_ac_%s", month_abbr[m]);
        f[n++] = (ss_field){month_names[slot][m], SS_FIELD_REAL, "kWh/month",
                            "the month's share of kwh_ac_year (as its share of the modules' "
                            "cells' irradiation)"};
    }
    f[n++] = (ss_field){"kwh_m2_year", SS_FIELD_REAL, "kWh/m2/year",
                        "mean irradiation on the roof (its cells clear of edges by the setback)"};
    f[n++] = (ss_field){"unshaded_kwh_m2_year", SS_FIELD_REAL, "kWh/m2/year",
                        "the same surface with no horizon (no shade, sky to the horizontal)"};
    f[n++] = (ss_field){"shading_loss_pct", SS_FIELD_REAL, "%",
                        "100 x (1 - kwh_m2_year / unshaded_kwh_m2_year)"};
    f[n++] = (ss_field){"class", SS_FIELD_TEXT, "",
                        "suitability by kwh_m2_year (sonnendach.ch): low < 800, medium < 1000, "
                        "good < 1200, very good < 1400, excellent"};
    f[n++] = (ss_field){"class_code", SS_FIELD_INT, "", "1 low .. 5 excellent"};
    return n;
}

void roofs_define_fields(void)
{
    int n = 0;
    ss_field *f = plane_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"plane_id", SS_FIELD_INT, "", "1.. within the building"};
    f[n++] = (ss_field){"tilt_deg", SS_FIELD_REAL, "deg", "tilt from the horizontal"};
    f[n++] = (ss_field){"azimuth_deg", SS_FIELD_REAL, "deg",
                        "azimuth of the downslope direction, clockwise from true north (pvlib's "
                        "surface_azimuth); 180 (0 south of the equator) where tilt < 1"};
    f[n++] = (ss_field){"area_m2", SS_FIELD_REAL, "m2", "true (3D) area: planimetric / cos tilt"};
    f[n++] = (ss_field){"fit_rms_m", SS_FIELD_REAL, "m", "rms distance of its cells from the "
                                                          "plane"};
    n = common_fields(f, n, 0);
    f[n++] = (ss_field){"panel_tilt_deg", SS_FIELD_REAL, "deg",
                        "the modules' tilt: the plane's, or the racks' on a flat roof"};
    f[n++] = (ss_field){"panel_azimuth_deg", SS_FIELD_REAL, "deg",
                        "the way the modules face, clockwise from true north: the plane's, or "
                        "the equator on a flat roof"};
    f[n++] = (ss_field){"racked", SS_FIELD_INT, "", "1: a flat roof, modules on racks"};
    f[n++] = (ss_field){"landscape", SS_FIELD_INT, "",
                        "1: modules' long side along the rows, 0: up the slope (portrait)"};
    n = 0;
    f = panel_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"plane_id", SS_FIELD_INT, "", "its roof plane"};
    f[n++] = (ss_field){"panel_id", SS_FIELD_INT, "", "1.. within the plane"};
    f[n++] = (ss_field){"tilt_deg", SS_FIELD_REAL, "deg", "the module's tilt"};
    f[n++] = (ss_field){"azimuth_deg", SS_FIELD_REAL, "deg",
                        "the way the module faces, clockwise from true north"};
    f[n++] = (ss_field){"kwp", SS_FIELD_REAL, "kWp", "the module's power"};
    f[n++] = (ss_field){"kwh_ac_year", SS_FIELD_REAL, "kWh/year",
                        "its kWp x the mean AC kWh/kWp of the cells it covers"};
    n = 0;
    f = shade_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"plane_id", SS_FIELD_INT, "", "its roof plane"};
    f[n++] = (ss_field){"month", SS_FIELD_INT, "", "1..12, of the weather file's local time"};
    f[n++] = (ss_field){"hour", SS_FIELD_INT, "",
                        "0..23, the hour of the weather file's local (standard) time the "
                        "records' suns fall in"};
    f[n++] = (ss_field){"sun_fraction", SS_FIELD_REAL, "",
                        "share of the plane's cells in direct sun (sunlit, facing the sun), "
                        "averaged over the month's records of that hour; 0 at night"};
    f[n++] = (ss_field){"n_records", SS_FIELD_INT, "", "weather records averaged"};
    f[n++] = (ss_field){"usable_cells", SS_FIELD_INT, "",
                        "1: the plane's usable cells are counted, 0: all its cells (none "
                        "usable)"};
    n = 0;
    f = building_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"partly_outside", SS_FIELD_INT, "", "1: part of the footprint lies "
                                                             "outside the DSM"};
    f[n++] = (ss_field){"repaired", SS_FIELD_INT, "", "1: invalid geometry made valid"};
    f[n++] = (ss_field){"n_planes", SS_FIELD_INT, "", "roof planes"};
    f[n++] = (ss_field){"footprint_area_m2", SS_FIELD_REAL, "m2", "cells of the footprint"};
    f[n++] = (ss_field){"area_m2", SS_FIELD_REAL, "m2", "true (3D) area of the roof planes"};
    f[n++] = (ss_field){"obstacle_area_m2", SS_FIELD_REAL, "m2", "planimetric area of obstacle "
                                                                 "cells"};
    f[n++] = (ss_field){"height_m", SS_FIELD_REAL, "m",
                        "highest roof-plane cell above the median ground (--dtm; null without)"};
    n = common_fields(f, n, 1);
}

static void plane_values(const plane_row *p, const char *building_id, ss_value *v)
{
    int n = 0;
    v[n++].text = building_id;
    v[n++].num = p->number;
    v[n++].num = p->tilt_deg;
    v[n++].num = p->azimuth_deg;
    v[n++].num = p->area_m2;
    v[n++].num = p->fit.rms_m;
    v[n++].num = p->usable_area_m2;
    v[n++].num = p->n_panels;
    v[n++].num = p->kwp;
    v[n++].num = p->kwh_ac_year;
    v[n++].num = p->kwh_dc_year;
    v[n++].num = p->kwh_per_kwp;
    for (int m = 0; m < 12; ++m)
        v[n++].num = p->kwh_ac_month[m];
    v[n++].num = p->kwh_m2_year;
    v[n++].num = p->unshaded_kwh_m2_year;
    v[n++].num = p->shading_loss_pct;
    int cls = suitability_class(p->kwh_m2_year);
    v[n++].text = class_names[cls];
    v[n++].num = cls ? cls : NAN;
    v[n++].num = p->panel_tilt_deg;
    v[n++].num = p->panel_azimuth_deg;
    v[n++].num = p->racked;
    v[n++].num = p->landscape;
}

static void building_values(const ss_footprint *fp, const building_sums *b, ss_value *v)
{
    int n = 0;
    v[n++].text = fp->id;
    v[n++].num = fp->partly_outside;
    v[n++].num = fp->repaired;
    v[n++].num = b->n_planes;
    v[n++].num = b->footprint_area_m2;
    v[n++].num = b->roof_area_m2;
    v[n++].num = b->obstacle_area_m2;
    v[n++].num = b->height_m;
    v[n++].num = b->usable_area_m2;
    v[n++].num = b->n_panels;
    v[n++].num = b->kwp;
    v[n++].num = b->kwh_ac_year;
    v[n++].num = b->kwh_dc_year;
    v[n++].num = b->kwp > 0 ? b->kwh_ac_year / b->kwp : NAN;
    for (int m = 0; m < 12; ++m)
        v[n++].num = b->kwh_ac_month[m];
    double mean = b->inner_area_m2 > 0 ? b->inner_kwh / b->inner_area_m2 : NAN;
    double unshaded = b->inner_area_m2 > 0 ? b->inner_unshaded_kwh / b->inner_area_m2 : NAN;
    v[n++].num = mean;
    v[n++].num = unshaded;
    v[n++].num = unshaded > 0 ? 100.0 * (1.0 - mean / unshaded) : NAN;
    int cls = suitability_class(mean);
    v[n++].text = class_names[cls];
    v[n++].num = cls ? cls : NAN;
}

/* A text as RFC 4180 quotes it (a quote doubled). */
static void write_csv_text(FILE *f, const char *text)
{
    fputc('"', f);
    for (const char *c = text; *c; ++c)
        fputs(*c == '"' ? "\"\"" : (char[2]){*c, 0}, f);
    fputc('"', f);
}

/* The planes as CSV, written to a temporary and renamed into place. */
static ss_status write_csv(ss_ctx *ctx, const char *path, const plane_row *rows, size_t n,
                           const ss_footprints *fps)
{
    char *tmp = ss_temporary_name(path, "tmp");
    FILE *f = tmp ? fopen(tmp, "w") : NULL;
    if (!f) {
        free(tmp);
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s'", path);
    }
    ss_temporaries_track(path);
    for (int k = 0; k < PLANE_FIELDS; ++k)
        fprintf(f, "%s%s", k ? "," : "", plane_fields[k].name);
    fprintf(f, "\n");
    ss_value v[PLANE_FIELDS];
    for (size_t i = 0; i < n; ++i) {
        memset(v, 0, sizeof v);
        plane_values(&rows[i], fps->items[rows[i].building].id, v);
        for (int k = 0; k < PLANE_FIELDS; ++k) {
            fputs(k ? "," : "", f);
            if (plane_fields[k].type == SS_FIELD_TEXT)
                write_csv_text(f, v[k].text ? v[k].text : "");
            else if (isfinite(v[k].num))
                fprintf(f, "%.10g", v[k].num);
        }
        fprintf(f, "\n");
    }
    int ok = !ferror(f) & (fclose(f) == 0);
    ss_status st = SS_OK;
    if (!ok || !ss_temporaries_hold())
        st = ss_ctx_error(ctx, ok ? SS_ERR_CANCELLED : SS_ERR_OUTPUT, "cannot write '%s'", path);
    else {
        if (rename(tmp, path) != 0)
            st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename '%s' to '%s'", tmp, path);
        ss_temporaries_release();
    }
    if (st != SS_OK)
        remove(tmp);
    ss_temporaries_forget(path);
    free(tmp);
    return st;
}

/* The table plane_shade: a row per plane, month and hour with records. */
static ss_status write_shade_table(ss_vector_writer *w, const roofs_run *r)
{
    int layer;
    ss_status st = ss_vector_table(w, "plane_shade",
                                   "skysweep roofs: each roof plane's share in direct sun by "
                                   "month and hour (doc/roofs.md)",
                                   shade_fields, SHADE_FIELDS, &layer);
    for (size_t i = 0; st == SS_OK && i < r->n_planes; ++i)
        for (int m = 0; st == SS_OK && m < 12; ++m)
            for (int h = 0; st == SS_OK && h < 24; ++h) {
                int n = r->shade.records[m * 24 + h];
                if (!n)
                    continue;
                const plane_row *p = &r->planes[i];
                ss_value v[SHADE_FIELDS] = {{.text = r->fps.items[p->building].id},
                                            {.num = p->number},
                                            {.num = m + 1},
                                            {.num = h},
                                            {.num = roof_shade_fraction(&r->shade, i, m, h)},
                                            {.num = n},
                                            {.num = p->shade_on_usable}};
                st = ss_vector_add(w, layer, NULL, v);
            }
    return st;
}

/* --shade-masks into a temporary (renamed with the GeoPackage). */
static ss_status write_masks(roofs_run *r, char **tmp)
{
    static char names[SHADE_SLOTS][40];
    const char *descriptions[SHADE_SLOTS];
    for (int m = 0; m < 12; ++m)
        for (int h = 0; h < 24; ++h) {
            snprintf(names[m * 24 + h], sizeof names[0], "month %02d hour %02d", m + 1, h);
            descriptions[m * 24 + h] = names[m * 24 + h];
        }
    return ss_masks_write(r->job.run.ctx, r->set.shade_masks, &r->job.dem, SHADE_SLOTS,
                          r->shade.masks, descriptions, tmp);
}

/* --cell-raster: the insolation run's raster, beside it, moved into place
 * whole (close_run no longer finds it to remove). */
static ss_status keep_cell_raster(roofs_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    if (!ss_temporaries_hold())
        return ss_ctx_error(ctx, SS_ERR_CANCELLED, "stopped before '%s' was renamed",
                            r->set.cell_raster);
    ss_status st = SS_OK;
    if (ss_output_rename(r->raster, r->set.cell_raster) != 0)
        st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename '%s' to '%s'", r->raster,
                          r->set.cell_raster);
    else
        *r->raster = '\0';
    ss_temporaries_release();
    return st;
}

ss_status roofs_write_outputs(roofs_run *r)
{
    double t0 = run_now();
    ss_ctx *ctx = r->job.run.ctx;
    ss_vector_writer *w;
    char *masks_tmp = NULL;
    ss_status st = r->set.shade_masks ? write_masks(r, &masks_tmp) : SS_OK;
    if (st == SS_OK)
        st = ss_vector_open(ctx, r->job.output, &r->job.dem, &w);
    if (st != SS_OK) {
        ss_masks_abort(r->set.shade_masks, masks_tmp);
        return st;
    }
    int lb, lp;
    char trees_note[600] = "", light[200], described[1300];
    const insolation_tree_settings *t = &r->set.trees;
    if (t->trees.canopy) {
        crown_light_describe(&t->light, t->trees.transmissivity, light, sizeof light);
        char leaf_on[40] = "Beer-Lambert";
        if (!t->light.beer_lambert)
            snprintf(leaf_on, sizeof leaf_on, "%.4g", t->trees.transmissivity);
        snprintf(trees_note, sizeof trees_note,
                 "; with trees from %s, transmissivity %s leaf on, %.4g leaf off, crown "
                 "light: %s (doc/vegetation.md)",
                 t->trees.canopy, leaf_on, t->transmissivity_leaf_off, light);
    }
    snprintf(described, sizeof described,
             "skysweep roofs: per building, sums over its roof planes (doc/roofs.md); under %s%s",
             r->sky_note, trees_note);
    st = ss_vector_layer(w, "buildings", described, building_fields, BUILDING_FIELDS, &lb);
    snprintf(described, sizeof described,
             "skysweep roofs: roof planes fitted in the DSM inside each footprint "
             "(doc/roofs.md); under %s%s",
             r->sky_note, trees_note);
    if (st == SS_OK)
        st = ss_vector_layer(w, "roof_planes", described, plane_fields, PLANE_FIELDS, &lp);
    ss_value v[BUILDING_FIELDS];
    for (size_t b = 0; st == SS_OK && b < r->fps.n; ++b) {
        memset(v, 0, sizeof v);
        building_values(&r->fps.items[b], &r->sums[b], v);
        st = ss_vector_add(w, lb, r->fps.items[b].geometry, v);
    }
    ss_value pv_row[PLANE_FIELDS]; /* a plane has more fields than a building */
    for (size_t i = 0; st == SS_OK && i < r->n_planes; ++i) {
        memset(pv_row, 0, sizeof pv_row);
        plane_values(&r->planes[i], r->fps.items[r->planes[i].building].id, pv_row);
        st = ss_vector_add(w, lp, r->planes[i].geometry, pv_row);
    }
    int lpanels;
    if (st == SS_OK && r->set.panels_layer)
        st = ss_vector_layer(w, "panels",
                             "skysweep roofs: each module of the panel layout, its footprint on "
                             "the ground (doc/roofs.md)",
                             panel_fields, PANEL_FIELDS, &lpanels);
    for (size_t i = 0; st == SS_OK && r->set.panels_layer && i < r->n_panels; ++i) {
        const panel_row *k = &r->panels[i];
        const plane_row *p = &r->planes[k->plane];
        ss_value pv[PANEL_FIELDS] = {{.text = r->fps.items[p->building].id},
                                     {.num = p->number},
                                     {.num = k->number},
                                     {.num = p->panel_tilt_deg},
                                     {.num = p->panel_azimuth_deg},
                                     {.num = r->set.panel.power_w / 1000.0},
                                     {.num = k->kwh_ac_year}};
        st = ss_vector_add(w, lpanels, k->geometry, pv);
    }
    if (st == SS_OK && r->set.shade_table)
        st = write_shade_table(w, r);
    if (st == SS_OK && r->set.csv)
        st = write_csv(ctx, r->set.csv, r->planes, r->n_planes, &r->fps);
    if (st == SS_OK)
        st = ss_vector_commit(w);
    else
        ss_vector_abort(w);
    if (st == SS_OK && masks_tmp)
        st = ss_masks_commit(ctx, r->set.shade_masks, masks_tmp);
    else
        ss_masks_abort(r->set.shade_masks, masks_tmp);
    if (st == SS_OK && r->set.cell_raster)
        st = keep_cell_raster(r);
    r->seconds_write = run_now() - t0;
    return st;
}
