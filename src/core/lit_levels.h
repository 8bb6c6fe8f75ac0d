/* Per-cell proven bounds on the terrain horizon in every azimuth, so that a
 * shadow walk can stop where no cell further along its line can be shaded
 * (insolation's exact steps, doc/performance.md). A wrong bound would light
 * a shaded cell: tests/test_lit_levels.c checks every cell's bound against
 * the walks themselves, and exact runs with and without the bounds. */
#ifndef SS_LIT_LEVELS_H
#define SS_LIT_LEVELS_H

#include "ctx_internal.h" /* ss_malloc */
#include "ss_band.h"      /* SS_LIT_SECTORS, SS_LIT_BLOCK_SHIFT */

/* A cell's bound is rounded up to a level: level k is (k + 1) steps of
 * SS_LIT_STEP_DEG. */
#define SS_LIT_STEP_DEG 0.5
#define SS_LIT_LEVELS 179 /* the last, 89.5 degrees */
double ss_lit_level_deg(int level);
/* A cell for which no level is proven. */
#define SS_LIT_UNBOUNDED 255

/* The bounds hold per sector of azimuth: SS_LIT_SECTORS sectors of equal
 * width, clockwise from the grid's north (the azimuth less the options'
 * grid_north_deg), sector 0 starting at 0 degrees. A city's cell beside a
 * tall wall is bounded low in the sectors that face away from it. Eight:
 * sixteen lower the Gothenburg DSM's median bound facing south from 38
 * to 33 degrees but skip only 3.0 % of a June week's walks there against
 * eight's 2.4 %, for twice the bytes (doc/performance.md). */
/* (SS_LIT_SECTORS, the kernels' too, is defined in kernels/ss_band.h.) */
/* The sector of walks at this azimuth in the grid's frame (degrees, any
 * finite value). */
int ss_lit_sector(double grid_azimuth_deg);

/* Per sector and cell of a grid of heights held whole (NaN at nodata;
 * cell sizes in metres): the first level k whose angle lies above every
 * horizon that interpolated lines (kernels/ss_lines.h) at an azimuth of
 * the sector can give the cell, with or without curvature, or
 * SS_LIT_UNBOUNDED; 0 at nodata cells, which have no horizon. The
 * sectors' planes of width x height bytes follow each other, sector 0
 * first. Freed with free(); NULL when out of memory (the walks then go
 * whole). Its work space, about 44 + 4 SS_LIT_SECTORS bytes a cell, is
 * freed before it returns. sectors 1: one bound for every azimuth, the
 * largest of the sectors' (each zone counts toward every sector), in each
 * sector's plane: the zones made once instead of about twice
 * (ss_lit_sectors_for); else SS_LIT_SECTORS. */
unsigned char *ss_lit_levels(const float *z, int width, int height, double cell_x_m,
                             double cell_y_m, int sectors);
/* The same for box lines (kernels/ss_box.h) of `families` families. */
unsigned char *ss_lit_levels_box(const float *z, int width, int height, double cell_x_m,
                                 double cell_y_m, int families, int sectors);

/* The same levels for a DEM read in bands (src: its band_rows less than
 * its height), made in two passes over it: the highest height of each
 * block of 8 x 8 cells and the block levels above, held whole (a
 * sixty-fourth of the heights and a third more); then each band of rows
 * with LOCAL_REACH rows around it, whose cells within that reach give the
 * bounds' near zones and lower levels (lit_levels.c's proof, the same
 * zones; the farther levels take no slope cap, which only lowers a bound).
 * The levels go to a store of cells (a temporary file), with the largest
 * level of each block of 2^SS_LIT_BLOCK_SHIFT cells per sector held whole;
 * families 0: interpolated lines, else box lines of that many families.
 * *out NULL where memory is short (the walks then go whole). */
typedef struct ss_lit_bands ss_lit_bands;
/* Bytes a cell of a band's window takes while its levels are made (the
 * heights 4, levels_of's tangents per sector and ten work planes, the
 * levels): the window holds the band's rows and LOCAL_REACH more on each
 * side, ss_lit_bands_window_rows(rows, height). */
#define SS_LIT_MAKING_CELL_BYTES (4 + 4 * SS_LIT_SECTORS + 40 + SS_LIT_SECTORS)
int ss_lit_bands_window_rows(int band_rows, int height);
ss_status ss_lit_bands_make(ss_ctx *ctx, const ss_source *src, int families, int sectors,
                            ss_lit_bands **out);
/* A band visit's levels for its held rows [lo, lo + n), in the layout
 * kernels/ss_passes.h reads (ss_band_horizon_line): each sector's plane of
 * n rows, then each sector's blocks; ss_lit_bands_bytes(lb, n) bytes. */
ss_status ss_lit_bands_read(ss_lit_bands *lb, int lo, int n, unsigned char *out);
size_t ss_lit_bands_bytes(const ss_lit_bands *lb, int held_rows);
void ss_lit_bands_free(ss_lit_bands *lb);

/* Whether exact shadow walks use the bounds (held whole or in bands): their
 * proof is for interpolated and box lines, and fewer than 48 walked steps
 * do not repay them (interpolated: 0.2 s on 857 x 793 cells, about 16
 * steps' walks there; box lines of 32 families: 0.15 s on the Gothenburg
 * DSM's 234 x 223, where the bounds, mostly above its highest sun, skip
 * 0.9 % of a June week's walks, 3 ms a step of about 0.3 s). The plan
 * (plan.c) and the run (insolation.c) both ask here. */
int ss_lit_levels_used(int walked_steps, int lines);

/* The sectors the bounds of a run are made in: SS_LIT_SECTORS where the
 * walks repay making them, walked steps times the walks' cost per step
 * (box lines: their families; interpolated lines: 1) at least 2048; else
 * 1. Sectors take about twice the making (a zone counts toward about two)
 * and pay where a cell is open in some azimuths, as beside a wall:
 * measured on terrain (Kilauea's sample, box lines x4, five June days,
 * 65 walked steps) 9.3 s user with one bound against 10.3 s with sectors;
 * on the Gothenburg DSM (box lines x32, a June week, 109 walked steps)
 * 53.0 s with one bound against 42.3 s with sectors (doc/performance.md). */
int ss_lit_sectors_for(int walked_steps, int lines, int families);

/* The highest level at or below elevation_deg (-1: none): a cell whose
 * level is at most this has every horizon below a sun that high. */
int ss_lit_level_below(double elevation_deg);

#endif
