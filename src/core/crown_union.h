/* A union of open intervals kept sorted and disjoint, for the crowns met
 * along a line: the levels they hold toward one sun (vegetation.c), or the
 * rises they hide from one cell (canopy_sky.c). */
#ifndef SS_CROWN_UNION_H
#define SS_CROWN_UNION_H

#include <stdlib.h>
#include <string.h>

#include "products_internal.h"

typedef struct {
    double lo, hi;
} crown_span;

/* The union of the crowns ahead on one line. */
typedef struct {
    crown_span *span;
    size_t n, cap;
} crown_union;

/* The index of the first span whose lo is >= z (spans are sorted and
 * disjoint, so their his are sorted too). */
static inline size_t first_at_or_above(const crown_union *u, double z)
{
    size_t a = 0, b = u->n;
    while (a < b) {
        size_t m = a + (b - a) / 2;
        if (u->span[m].lo < z)
            a = m + 1;
        else
            b = m;
    }
    return a;
}

static inline int union_holds(const crown_union *u, double z)
{
    size_t k = first_at_or_above(u, z);
    return k > 0 && z < u->span[k - 1].hi;
}

/* Merges (lo, hi) in: spans that overlap it (open intervals that share
 * more than an end) become one. */
static inline int union_add(crown_union *u, double lo, double hi)
{
    size_t k = first_at_or_above(u, lo);
    if (k > 0 && u->span[k - 1].hi > lo)
        --k;
    size_t end = k;
    while (end < u->n && u->span[end].lo < hi) {
        lo = fmin(lo, u->span[end].lo);
        hi = fmax(hi, u->span[end].hi);
        ++end;
    }
    if (end == k) { /* nothing overlaps: insert */
        if (u->n == u->cap) {
            size_t cap = u->cap ? 2 * u->cap : 16;
            crown_span *s = ss_realloc(u->span, cap * sizeof *s);
            if (!s)
                return -1;
            u->span = s;
            u->cap = cap;
        }
        memmove(u->span + k + 1, u->span + k, (u->n - k) * sizeof *u->span);
        ++u->n;
    } else { /* spans k .. end-1 become one */
        memmove(u->span + k + 1, u->span + end, (u->n - end) * sizeof *u->span);
        u->n -= end - k - 1;
    }
    u->span[k] = (crown_span){lo, hi};
    return 0;
}

/* A crown's bottom above its cell's surface. */
static inline double trunk_of(const ss_canopy *c, size_t i)
{
    return c->trunk_m ? c->trunk_m[i] : c->trunk_ratio * c->height_m[i];
}

#endif
