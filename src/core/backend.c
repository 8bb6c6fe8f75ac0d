/* What the backends and the driver share about a walk and its backend
 * (backend.h), whichever device runs it. */
#include "config.h"

#include "backend.h"

int ss_walk_planes(const ss_walk *walk)
{
    if (walk->term != SS_TERM_HORIZON)
        return 1;
    return walk->want & SS_HORIZON_WANT_CAST ? 4 : walk->want & SS_HORIZON_WANT_DIST ? 3 : 2;
}

size_t ss_backend_carry_floats(const ss_backend *b)
{
    return (size_t)b->carried * (size_t)ss_walk_planes(&b->walk) * (size_t)b->width;
}
