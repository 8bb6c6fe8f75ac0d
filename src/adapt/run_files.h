/* The files a run reads and writes, registered before any work and compared
 * once (ss_run_files_check), so that no output replaces an input or another
 * output. Every file a command names is registered: the command line does it
 * from its option tables, where a file option is declared as an input or an
 * output (src/cli/options.h), and from its positionals and scene file; a new
 * file option cannot be missed. Files are the same when they are one file
 * (device and inode, links followed), or, for an output not yet there, when
 * their names resolve to the same folder and name (doc/cli.md). */
#ifndef SS_RUN_FILES_H
#define SS_RUN_FILES_H

#include "skysweep.h"

typedef struct {
    char *path;
    char named_by[40]; /* how the user named it: "--weather", "input", "OUTPUT" */
    int output;           /* 1: the run writes it; 0: it reads it */
} ss_run_file;

typedef struct {
    ss_run_file *files;
    int n, cap;
} ss_run_files;

/* Adds a file (both strings are copied). -1 when memory is out. */
int ss_run_files_add(ss_run_files *set, const char *path, const char *named_by, int output);
/* SS_ERR_ARGUMENT, with one line naming both, when an output is the same
 * file as an input or as another output; else SS_OK. */
ss_status ss_run_files_check(ss_ctx *ctx, const ss_run_files *set);
/* Empties the set and frees what it holds. */
void ss_run_files_clear(ss_run_files *set);

#endif
