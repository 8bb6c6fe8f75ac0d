/* The CLI's commands and the helpers they share. */
#ifndef SS_CLI_COMMANDS_H
#define SS_CLI_COMMANDS_H

#include "run.h"

#define COMMAND_MAX_INPUTS 256

/* svf and openness: the registry's sky products (argv[0] names which). */
int cmd_sky(int argc, char **argv);
/* A registry product with a run call and no command of its own (argv[0]
 * names which): cmd_product.c. */
int cmd_product(int argc, char **argv);
int cmd_horizon(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_sun(int argc, char **argv);
int cmd_weather(int argc, char **argv);
int cmd_shadow(int argc, char **argv);
int cmd_hillshade(int argc, char **argv);
int cmd_insolation(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_quicklook(int argc, char **argv);
int cmd_roofs(int argc, char **argv);
int cmd_canopy(int argc, char **argv);

/* Prints the OpenCL devices; returns the exit code. */
int command_list_devices(void);
/* One summary line about the sweep: directions, device, speed. */
void command_print_sweep(run_state *run, const ss_sweep_options *opt, int width, int height);
/* The summary's line on box shadows by each cell's own ray (`label`, e.g.
 * "shadow "), where the run marched any. */
void command_print_box_march(run_state *run, const char *label);
/* The sweep summary of a job that may be banded (with the rows per band
 * and the hulls handed on). */
void command_print_job_sweep(sweep_job *job, const ss_band_stats *bands);
/* The summary's memory line: the peak resident memory, swept how ("whole
 * grid", "bands"), and beside it the bound it kept to and the peak the
 * memory plan expected. */
void command_print_memory(const sweep_job *job, const char *how);
/* Records an out-of-memory failure in the context; returns its status. */
ss_status command_out_of_memory(run_state *run);

#endif
