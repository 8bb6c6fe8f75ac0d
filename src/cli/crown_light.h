/* How light crosses crowns (doc/vegetation.md): the constant
 * transmissivity of the tree options (UMEP's), or Beer-Lambert by the
 * ray's path inside crowns. The options, declared once for the commands
 * that take them (shadow, insolation). */
#ifndef SS_CLI_CROWN_LIGHT_H
#define SS_CLI_CROWN_LIGHT_H

#include "commands.h"
#include "run.h"

typedef struct {
    int beer_lambert; /* index into "constant|beer-lambert" */
    double leaf_area_density, extinction;
} crown_light_settings;

/* The options, their values in a crown_light_settings at `base` in the
 * command's settings. */
const opt_spec *crown_light_options(size_t base);

/* --leaf-area-density and --extinction without --crown-light beer-lambert,
 * and Beer-Lambert without --canopy, are refused rather than ignored, and
 * so is --transmissivity with Beer-Lambert, which takes the light it would
 * (insolation's leaf-on beam and sky through crowns alike): an exit code,
 * or -1 when they are fine. */
int crown_light_alone(const char *command, const opt_spec *const *tables, const void *settings,
                      const crown_light_settings *set, int have_canopy);

/* Bytes per cell Beer-Lambert holds for the whole grid beside the
 * command's trees: the paths and the fractions. */
#define CROWN_LIGHT_CELL_BYTES (2.0 * sizeof(float))

/* CROWN_LIGHT metadata, and the summary's words. */
void crown_light_describe(const crown_light_settings *set, double transmissivity, char *buf,
                          size_t size);

/* Writes CROWN_LIGHT (described); with Beer-Lambert also TRANSMISSIVITY,
 * which trees_metadata gave the constant that Beer-Lambert replaces. */
void crown_light_metadata(ss_raster_writer *w, const crown_light_settings *set,
                          const char *described);

#endif
