/* Roof planes of one building (roof_planes.h). */
#include "config.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "roof_planes.h"

/* Least-squares sums of z = a e + b n + c. */
typedef struct {
    double s1, se, sn, sz, see, snn, sen, sez, snz;
} plane_sums;

static void sums_add(plane_sums *s, double e, double n, double z)
{
    s->s1 += 1, s->se += e, s->sn += n, s->sz += z;
    s->see += e * e, s->snn += n * n, s->sen += e * n, s->sez += e * z, s->snz += n * z;
}

/* The plane of the sums (Cramer's rule on the normal equations); 0 where
 * the cells do not fix one (fewer than three, or all in a line). */
static int sums_solve(const plane_sums *s, double *a, double *b, double *c)
{
    double m[3][3] = {{s->see, s->sen, s->se}, {s->sen, s->snn, s->sn}, {s->se, s->sn, s->s1}};
    double v[3] = {s->sez, s->snz, s->sz};
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (s->s1 < 3 || fabs(det) < 1e-9 * (1 + s->see * s->snn * s->s1))
        return 0;
    double r[3];
    for (int k = 0; k < 3; ++k) {
        double t[3][3];
        memcpy(t, m, sizeof t);
        for (int i = 0; i < 3; ++i)
            t[i][k] = v[i];
        r[k] = (t[0][0] * (t[1][1] * t[2][2] - t[1][2] * t[2][1]) -
                t[0][1] * (t[1][0] * t[2][2] - t[1][2] * t[2][0]) +
                t[0][2] * (t[1][0] * t[2][1] - t[1][1] * t[2][0])) /
               det;
    }
    *a = r[0], *b = r[1], *c = r[2];
    return 1;
}

/* Angle (degrees) between the normals of two planes' gradients. */
static double normals_angle_deg(double a1, double b1, double a2, double b2)
{
    double dot = a1 * a2 + b1 * b2 + 1;
    double cosine = dot / sqrt((a1 * a1 + b1 * b1 + 1) * (a2 * a2 + b2 * b2 + 1));
    return acos(fmin(1.0, cosine)) * 180.0 / M_PI;
}

/* The building's window: each window cell's index into the building's
 * cells (-1: not the building's), its coordinates and height. */
typedef struct {
    int cols, rows;
    int *at;
    const float *z;
    int width, col0, row0;
    double cx, cy;
    const int *cells;
    size_t n;
} window;

static double cell_e(const window *w, size_t i) { return (w->cells[i] % w->width - w->col0) * w->cx; }
static double cell_n(const window *w, size_t i) { return -(w->cells[i] / w->width - w->row0) * w->cy; }
static double cell_z(const window *w, size_t i) { return w->z[w->cells[i]]; }

/* The building's cell at window position (c, r), or -1. */
static int cell_at(const window *w, int c, int r)
{
    return c < 0 || r < 0 || c >= w->cols || r >= w->rows ? -1 : w->at[r * w->cols + c];
}

/* Each cell's local plane over its 3 x 3 neighbours in the footprint
 * (six at least): gradient and rms residual; rms NAN where none. */
static void local_fits(const window *w, double *ga, double *gb, double *rms)
{
    for (size_t i = 0; i < w->n; ++i) {
        int c = w->cells[i] % w->width - w->col0, r = w->cells[i] / w->width - w->row0;
        plane_sums s = {0};
        int nb[9], k = 0;
        for (int dr = -1; dr <= 1; ++dr)
            for (int dc = -1; dc <= 1; ++dc) {
                int j = cell_at(w, c + dc, r + dr);
                if (j >= 0 && isfinite(cell_z(w, (size_t)j))) {
                    sums_add(&s, cell_e(w, (size_t)j), cell_n(w, (size_t)j), cell_z(w, (size_t)j));
                    nb[k++] = j;
                }
            }
        double a, b, c0;
        rms[i] = NAN;
        if (k < 6 || !isfinite(cell_z(w, i)) || !sums_solve(&s, &a, &b, &c0))
            continue;
        double ss = 0;
        for (int m = 0; m < k; ++m) {
            double d = cell_z(w, (size_t)nb[m]) - (a * cell_e(w, (size_t)nb[m]) +
                                                   b * cell_n(w, (size_t)nb[m]) + c0);
            ss += d * d;
        }
        ga[i] = a, gb[i] = b, rms[i] = sqrt(ss / k);
    }
}

static const double *rms_sorted_by;
static int by_rms(const void *x, const void *y)
{
    double a = rms_sorted_by[*(const int *)x], b = rms_sorted_by[*(const int *)y];
    return (a > b) - (a < b);
}

static int by_value(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

static double plane_residual(const roof_plane *p, const window *w, size_t i)
{
    return cell_z(w, i) - (p->a * cell_e(w, i) + p->b * cell_n(w, i) + p->c);
}

static void set_orientation(roof_plane *p)
{
    p->tilt_deg = atan(hypot(p->a, p->b)) * 180.0 / M_PI;
    double az = atan2(-p->a, -p->b) * 180.0 / M_PI; /* downslope: -gradient */
    p->aspect_grid_deg = az < 0 ? az + 360.0 : az;
}

static double plane_area_m2(const window *w, size_t n_cells, double tilt_deg)
{
    return (double)n_cells * w->cx * w->cy / cos(tilt_deg * M_PI / 180.0);
}

/* Grows a region from seed over 4-neighbours whose local normals agree
 * with the region's plane and whose heights lie on it, refitting the
 * plane each time the region doubles. Returns the region's cell count;
 * *fixed is 0 where its cells do not fix a plane (a row of cells along a
 * ridge or a hip, whose mixed normals agree with each other). */
static size_t grow_region(const window *w, const roof_plane_options *o, int seed,
                          const double *ga, const double *gb, const double *rms, int id,
                          int *label, int *queue, roof_plane *p, int *fixed)
{
    p->a = ga[seed], p->b = gb[seed];
    p->c = cell_z(w, (size_t)seed) - p->a * cell_e(w, (size_t)seed) -
           p->b * cell_n(w, (size_t)seed);
    plane_sums s = {0};
    size_t head = 0, tail = 0, fitted = 1;
    queue[tail++] = seed;
    label[seed] = id;
    sums_add(&s, cell_e(w, (size_t)seed), cell_n(w, (size_t)seed), cell_z(w, (size_t)seed));
    const int step[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    while (head < tail) {
        int i = queue[head++];
        int c = w->cells[i] % w->width - w->col0, r = w->cells[i] / w->width - w->row0;
        for (int k = 0; k < 4; ++k) {
            int j = cell_at(w, c + step[k][0], r + step[k][1]);
            if (j < 0 || label[j] != ROOF_NONE || isnan(rms[j]) ||
                normals_angle_deg(ga[j], gb[j], p->a, p->b) > o->max_angle_deg ||
                fabs(plane_residual(p, w, (size_t)j)) > o->tolerance_m)
                continue;
            label[j] = id;
            queue[tail++] = j;
            sums_add(&s, cell_e(w, (size_t)j), cell_n(w, (size_t)j), cell_z(w, (size_t)j));
            if (tail >= 2 * fitted && tail >= 6) {
                sums_solve(&s, &p->a, &p->b, &p->c);
                fitted = tail;
            }
        }
    }
    *fixed = sums_solve(&s, &p->a, &p->b, &p->c);
    return tail;
}

/* Joins cells left over to the 4-neighbouring plane they lie closest to,
 * within the tolerance, until none joins (ridge, hip and eave cells whose
 * 3 x 3 normals mixed two planes, cells beside a chimney). */
static void join_left_over(const window *w, const roof_plane_options *o, const roof_plane *planes,
                           int *label, int *joins)
{
    const int step[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (int changed = 1; changed;) {
        changed = 0;
        for (size_t i = 0; i < w->n; ++i) {
            joins[i] = ROOF_NONE;
            if (label[i] != ROOF_NONE || !isfinite(cell_z(w, i)))
                continue;
            int c = w->cells[i] % w->width - w->col0, r = w->cells[i] / w->width - w->row0;
            double best = o->tolerance_m;
            for (int k = 0; k < 4; ++k) {
                int j = cell_at(w, c + step[k][0], r + step[k][1]);
                if (j < 0 || label[j] < 0)
                    continue;
                double d = fabs(plane_residual(&planes[label[j]], w, i));
                if (d <= best)
                    best = d, joins[i] = label[j];
            }
        }
        for (size_t i = 0; i < w->n; ++i)
            if (joins[i] >= 0)
                label[i] = joins[i], changed = 1;
    }
}

/* The plane of each region by least squares, twice without the cells the
 * first fit leaves more than 3 robust deviations (1.4826 MAD, at least
 * 3 cm) away; counts its cells. */
static void fit_robust(const window *w, roof_plane *planes, int n_planes, const int *label,
                       double *resid)
{
    for (int p = 0; p < n_planes; ++p) {
        roof_plane *pl = &planes[p];
        double limit = INFINITY;
        for (int pass = 0; pass < 3; ++pass) {
            plane_sums s = {0};
            for (size_t i = 0; i < w->n; ++i)
                if (label[i] == p && fabs(plane_residual(pl, w, i)) <= limit)
                    sums_add(&s, cell_e(w, i), cell_n(w, i), cell_z(w, i));
            sums_solve(&s, &pl->a, &pl->b, &pl->c);
            size_t k = 0;
            double ss = 0;
            for (size_t i = 0; i < w->n; ++i)
                if (label[i] == p) {
                    double d = plane_residual(pl, w, i);
                    resid[k++] = fabs(d);
                    ss += d * d;
                }
            pl->n_cells = k;
            pl->rms_m = k ? sqrt(ss / (double)k) : 0;
            qsort(resid, k, sizeof *resid, by_value);
            double mad = k ? resid[k / 2] : 0; /* the median |residual| */
            limit = fmax(3 * 1.4826 * mad, 0.03);
        }
        set_orientation(pl);
    }
}

/* Cells of no plane that stand higher than the nearest plane cell's plane
 * (within 3 cells) by more than the threshold: obstacles. */
static void mark_obstacles(const window *w, const roof_plane_options *o, const roof_plane *planes,
                           int *label)
{
    for (size_t i = 0; i < w->n; ++i) {
        if (label[i] != ROOF_NONE || !isfinite(cell_z(w, i)))
            continue;
        int c = w->cells[i] % w->width - w->col0, r = w->cells[i] / w->width - w->row0;
        int nearest = -1, best = 1 << 30;
        for (int dr = -3; dr <= 3; ++dr)
            for (int dc = -3; dc <= 3; ++dc) {
                int j = cell_at(w, c + dc, r + dr);
                if (j >= 0 && label[j] >= 0 && dr * dr + dc * dc < best)
                    best = dr * dr + dc * dc, nearest = label[j];
            }
        if (nearest >= 0 && plane_residual(&planes[nearest], w, i) > o->obstacle_m)
            label[i] = ROOF_OBSTACLE;
    }
}

/* Drops planes smaller than the minimum area (their cells to none) and
 * numbers the rest 0, 1, ... Returns how many are left. */
static int drop_small(const window *w, const roof_plane_options *o, roof_plane *planes,
                      int n_planes, int *label)
{
    int *renumber = malloc(sizeof(int) * (size_t)(n_planes + 1)), kept = 0;
    if (!renumber)
        return -1;
    for (int p = 0; p < n_planes; ++p) {
        int keep = plane_area_m2(w, planes[p].n_cells, planes[p].tilt_deg) >= o->min_area_m2;
        renumber[p] = keep ? kept : ROOF_NONE;
        if (keep)
            planes[kept++] = planes[p];
    }
    for (size_t i = 0; i < w->n; ++i)
        if (label[i] >= 0)
            label[i] = renumber[label[i]];
    free(renumber);
    return kept;
}

/* Numbers the planes by their first cell in the grid's row order, so that
 * the numbers depend on the roof alone (not on the order seeds were taken
 * in, nor on the window). rank: at least n_planes ints. */
static void number_by_first_cell(const window *w, roof_plane *planes, int n_planes, int *label,
                                 int *rank)
{
    int *first = malloc(sizeof(int) * (size_t)n_planes);
    roof_plane *copy = malloc(sizeof *copy * (size_t)n_planes);
    if (!first || !copy) { /* keep the seeds' order */
        free(first);
        free(copy);
        return;
    }
    for (int p = 0; p < n_planes; ++p)
        first[p] = INT_MAX;
    for (size_t i = 0; i < w->n; ++i)
        if (label[i] >= 0 && w->cells[i] < first[label[i]])
            first[label[i]] = w->cells[i];
    for (int p = 0; p < n_planes; ++p) {
        rank[p] = 0;
        for (int q = 0; q < n_planes; ++q)
            rank[p] += first[q] < first[p];
        copy[p] = planes[p];
    }
    for (int p = 0; p < n_planes; ++p)
        planes[rank[p]] = copy[p];
    for (size_t i = 0; i < w->n; ++i)
        if (label[i] >= 0)
            label[i] = rank[label[i]];
    free(first);
    free(copy);
}

int roof_planes_find(const float *z, int width, double cell_x_m, double cell_y_m, int col0,
                     int row0, int cols, int rows, const int *cells, size_t n_cells,
                     const roof_plane_options *o, roof_plane **planes_out, int *label)
{
    window w = {cols, rows, malloc(sizeof(int) * (size_t)cols * (size_t)rows), z, width, col0,
                row0, cell_x_m, cell_y_m, cells, n_cells};
    double *ga = malloc(sizeof(double) * (n_cells + 1)), *gb = malloc(sizeof(double) * (n_cells + 1));
    double *rms = malloc(sizeof(double) * (n_cells + 1));
    int *order = malloc(sizeof(int) * (n_cells + 1)), *queue = malloc(sizeof(int) * (n_cells + 1));
    roof_plane *planes = malloc(sizeof *planes * (n_cells + 1));
    int n_planes = -1;
    *planes_out = NULL;
    if (!w.at || !ga || !gb || !rms || !order || !queue || !planes)
        goto done;
    for (int k = 0; k < cols * rows; ++k)
        w.at[k] = -1;
    for (size_t i = 0; i < n_cells; ++i) {
        w.at[(cells[i] / width - row0) * cols + cells[i] % width - col0] = (int)i;
        label[i] = ROOF_NONE;
    }
    local_fits(&w, ga, gb, rms);
    size_t n_seeds = 0;
    for (size_t i = 0; i < n_cells; ++i)
        if (!isnan(rms[i]) && rms[i] <= 0.5 * o->tolerance_m)
            order[n_seeds++] = (int)i;
    rms_sorted_by = rms;
    qsort(order, n_seeds, sizeof *order, by_rms);
    /* Regions grown from the flattest cells; a region too small gives its
     * cells back, and none of them seeds again. */
    n_planes = 0;
    unsigned char *seeded = calloc(n_cells + 1, 1);
    if (!seeded) {
        n_planes = -1;
        goto done;
    }
    for (size_t k = 0; k < n_seeds; ++k) {
        int s = order[k];
        if (label[s] != ROOF_NONE || seeded[s])
            continue;
        roof_plane p = {0};
        int fixed;
        size_t n = grow_region(&w, o, s, ga, gb, rms, n_planes, label, queue, &p, &fixed);
        set_orientation(&p);
        p.n_cells = n;
        for (size_t q = 0; q < n; ++q)
            seeded[queue[q]] = 1;
        if (fixed && plane_area_m2(&w, n, p.tilt_deg) >= o->min_area_m2)
            planes[n_planes++] = p;
        else
            for (size_t q = 0; q < n; ++q)
                label[queue[q]] = ROOF_NONE;
    }
    free(seeded);
    join_left_over(&w, o, planes, label, queue);
    fit_robust(&w, planes, n_planes, label, rms);
    n_planes = drop_small(&w, o, planes, n_planes, label);
    if (n_planes > 0) {
        mark_obstacles(&w, o, planes, label);
        number_by_first_cell(&w, planes, n_planes, label, order);
    }
done:
    free(w.at);
    free(ga);
    free(gb);
    free(rms);
    free(order);
    free(queue);
    if (n_planes > 0)
        *planes_out = planes;
    else
        free(planes);
    return n_planes;
}
