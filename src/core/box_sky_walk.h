/* What the box model's sky view by each cell's own ray (box_sky.h) shares
 * between its two walks: one cell at a time (box_sky.c), and four cells
 * side by side in SIMD lanes where the CPU has AVX2 (box_sky_lanes.c),
 * which give the same answer bit for bit. */
#ifndef SS_BOX_SKY_WALK_H
#define SS_BOX_SKY_WALK_H

#include <stddef.h>

#include "box_sky.h"

/* A square a ray crosses: its place from the ray's cell in the heights,
 * and the metres from the cell's centre where the ray enters it. (A top
 * below the eye would show where the ray leaves its square, but never
 * above the eye's own top, at 0 degrees: only tops above the eye count.) */
typedef struct {
    ptrdiff_t offset;
    double t_in;
} ss_sky_square;

/* The squares every ray toward one azimuth crosses, in order, until it is
 * a grid's width or height away from its cell (no ray of the grid goes
 * farther): at most width + height of them. The offsets' columns and rows
 * move by sx and sy, never back: within_x[m] squares lie at most m
 * columns from the cell (m < width), within_y[m] at most m rows, so a ray
 * from a cell m columns and m' rows from the grid's edge ahead crosses the
 * first min(within_x[m], within_y[m']) of them in the grid. */
typedef struct {
    ss_sky_square *sq;
    int sx, sy;
    int *within_x, *within_y;
    float sin_az, cos_az;
    double t_own; /* where every ray leaves its own cell's square */
} ss_sky_ray;

struct ss_box_sky_tops {
    double top;       /* the highest of sign * height over the grid */
    int across, down; /* blocks */
    float *block_top; /* across * down, -INFINITY where no heights */
};

/* Blocks are SS_SKY_BLOCK cells square: on Gothenburg's DSM 32 was the
 * fastest of 4, 8, 16, 32, 48 and 64 one cell at a time, and of 16, 32
 * and 64 in the lanes; on a 2048 x 2048 Kilauea 32 and 64 tied. */
#define SS_SKY_BLOCK 32
#define SS_SKY_LANES 4

/* The squares of the list toward grid_azimuth_deg (clockwise from the
 * grid's north). Returns 0 when out of memory, the ray to be freed still. */
int ss_sky_ray_init(ss_sky_ray *ray, const ss_grid *grid, double grid_azimuth_deg);
void ss_sky_ray_free(ss_sky_ray *ray);

/* How many squares of the list the ray from cell (col, row) crosses in
 * the grid. */
static inline int ss_sky_ray_squares(const ss_grid *g, const ss_sky_ray *ray, int col, int row)
{
    int ahead_x = ray->sx > 0 ? g->width - 1 - col : col;
    int ahead_y = ray->sy > 0 ? g->height - 1 - row : row;
    return ray->within_x[ahead_x] < ray->within_y[ahead_y] ? ray->within_x[ahead_x]
                                                           : ray->within_y[ahead_y];
}

/* The column (row) index m of within_x (within_y) at which the ray from a
 * cell at column (row) pos, stepping by step, leaves the cell's block. */
static inline int ss_sky_block_exit(int pos, int step)
{
    int in_block = pos % SS_SKY_BLOCK;
    return step > 0 ? SS_SKY_BLOCK - 1 - in_block : in_block;
}

/* Where the list first crosses out of column (row) m, given within_x
 * (within_y) of size entries, at most n: n where m lies past the grid. */
static inline int ss_sky_block_end(const int *within, int size, int m, int n)
{
    int end = m < size ? within[m] : n;
    return end < n ? end : n;
}

/* One cell's walk over squares [k, end) of the list from its heights z
 * (the cell's own first) while short of *stop, raising *best, the
 * tangent, where a top rises above it, and setting *at to that square:
 * room is the grid's highest top above the eye, so that no top past
 * room / best can rise above best. A top at or below the eye cannot pass
 * best * t >= 0, nor can nodata (NaN): no branch on them. Returns where it
 * stopped. */
static inline int ss_sky_walk(const ss_sky_square *sq, int k, int end, const float *z, float sign,
                              double eye, double room, double curv_k, double *best, double *stop,
                              int *at)
{
    double b = *best, s = *stop;
    for (; k < end && sq[k].t_in < s; ++k) {
        double t = sq[k].t_in, rise = sign * z[sq[k].offset] - eye - curv_k * t * t;
        if (rise > b * t) {
            b = rise / t;
            s = room / b;
            *at = k;
        }
    }
    *best = b;
    *stop = s;
    return k;
}

/* The tangent of cell (col, row)'s box horizon along the ray, never below
 * 0 (its own top reaches its edge), for heights times sign lowered by
 * curv_k t^2; *at: the list's index of the nearest square whose top sets
 * it, -1 for the cell's own. Only a square that rises strictly above all
 * before it moves *at, and the blocks passed over hold none that could.
 * The stop (a rounded room / best) may end the walk before a farther top
 * whose tangent ties the best exactly and rounds a unit above it: the
 * nearer of the two is kept, as the definition asks. */
double ss_sky_tangent(const ss_grid *g, const ss_sky_ray *ray, const ss_box_sky_tops *tops, int col,
                      int row, float sign, double curv_k, int *at);

/* Whether this CPU walks four cells at a time (ss_sky_tangents_avx2). */
int ss_sky_lanes_here(void);

/* The threads share a band's rows cut into pieces of SS_SKY_PIECE columns,
 * so that a band of one row still runs on every core: piece t of a band of
 * rows from row0 is its row and columns [col, end). A piece starts at a
 * multiple of SS_SKY_LANES, so the lanes group the cells as whole rows
 * would. */
#define SS_SKY_PIECE 256
_Static_assert(SS_SKY_PIECE % SS_SKY_LANES == 0, "a piece starts where a group of lanes may");
typedef struct {
    int row, col, end;
} ss_sky_piece;
static inline int ss_sky_pieces(int width)
{
    return (width + SS_SKY_PIECE - 1) / SS_SKY_PIECE;
}
static inline ss_sky_piece ss_sky_piece_at(long t, int row0, int width)
{
    int col = (int)(t % ss_sky_pieces(width)) * SS_SKY_PIECE;
    ss_sky_piece p = {row0 + (int)(t / ss_sky_pieces(width)), col,
                      col + SS_SKY_PIECE < width ? col + SS_SKY_PIECE : width};
    return p;
}

/* How many cells from column c of a row width cells long walk together:
 * SS_SKY_LANES where the lanes are on (lanes_on) and that many lie ahead
 * from a multiple of it, else one. */
static inline int ss_sky_lanes_at(int lanes_on, int c, int width)
{
    return lanes_on && c % SS_SKY_LANES == 0 && c + SS_SKY_LANES <= width ? SS_SKY_LANES : 1;
}

/* The AVX2 copy, built by GCC on x86-64 (box_sky_lanes.c repeats the
 * condition): ss_sky_tangent of the SS_SKY_LANES cells from (col, row),
 * col a multiple of SS_SKY_LANES and col + SS_SKY_LANES <= width, into
 * tangent. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SS_SKY_LANES_AVX2 1
void ss_sky_tangents_avx2(const ss_grid *g, const ss_sky_ray *ray, const ss_box_sky_tops *tops,
                          int col, int row, float sign, double curv_k, double *tangent);
#else
#define SS_SKY_LANES_AVX2 0
#endif

#endif
