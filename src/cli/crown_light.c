/* How light crosses crowns on the command line (crown_light.h). */
#include "config.h"

#include <stddef.h>
#include <stdio.h>

#include "crown_light.h"

#define SET(field) offsetof(crown_light_settings, field)
static const opt_spec crown_light_table[] = {
    {"crown-light", OPT_CHOICE, SET(beer_lambert), NULL, "constant", 0, 0,
     "constant|beer-lambert",
     "light through crowns (with --canopy): the constant --transmissivity (UMEP's), or "
     "Beer-Lambert, exp(-G LAD path) of the ray's path inside crowns (digital lines; "
     "doc/vegetation.md)"},
    {"leaf-area-density", OPT_DOUBLE, SET(leaf_area_density), "M2_M3", "1", 0.001, 20, NULL,
     "with --crown-light beer-lambert: leaf area per volume of crown (m2/m3)"},
    {"extinction", OPT_DOUBLE, SET(extinction), "G", "0.5", 0.01, 1, NULL,
     "with --crown-light beer-lambert: the leaves' extinction coefficient (0.5: leaves at "
     "random angles)"},
    OPT_END};
#undef SET

const opt_spec *crown_light_options(size_t base)
{
    static opt_spec out[sizeof crown_light_table / sizeof *crown_light_table];
    for (size_t i = 0; i < sizeof crown_light_table / sizeof *crown_light_table; ++i) {
        out[i] = crown_light_table[i];
        if (out[i].name)
            out[i].offset += base;
    }
    return out;
}

int crown_light_alone(const char *command, const opt_spec *const *tables, const void *settings,
                      const crown_light_settings *set, int have_canopy)
{
    static const char *const needs[] = {"leaf-area-density", "extinction"};
    for (size_t i = 0; !set->beer_lambert && i < sizeof needs / sizeof *needs; ++i)
        if (!opt_at_default(opt_find(tables, needs[i]), settings)) {
            char why[80];
            snprintf(why, sizeof why, "--%s needs --crown-light beer-lambert", needs[i]);
            return run_usage_error(command, why);
        }
    if (set->beer_lambert && !have_canopy)
        return run_usage_error(command, "--crown-light needs --canopy");
    if (set->beer_lambert && !opt_at_default(opt_find(tables, "transmissivity"), settings))
        return run_usage_error(command, "--transmissivity is the constant crowns' light: "
                                        "Beer-Lambert takes --leaf-area-density instead");
    return -1;
}

void crown_light_describe(const crown_light_settings *set, double transmissivity, char *buf,
                          size_t size)
{
    if (set->beer_lambert)
        snprintf(buf, size,
                 "Beer-Lambert: exp(-%.6g x %.6g m2/m3 x the ray's path inside crowns), paths "
                 "on digital lines",
                 set->extinction, set->leaf_area_density);
    else
        snprintf(buf, size, "constant: transmissivity %.6g", transmissivity);
}

void crown_light_metadata(ss_raster_writer *w, const crown_light_settings *set,
                          const char *described)
{
    ss_writer_metadata(w, "CROWN_LIGHT", described);
    if (set->beer_lambert)
        ss_writer_metadata(w, "TRANSMISSIVITY",
                           "none leaf on: Beer-Lambert's exp(-G LAD path) instead (CROWN_LIGHT)");
}
