/* Every allocation of the core goes through here, so that a test can make
 * the n-th one fail (SQLite's fault injection, doc/reliability.md) and check that
 * every public call then returns SS_ERR_MEMORY, leaks nothing and leaves
 * its context usable. Memory from here is released with free(). */
#include "config.h"

#include <stdatomic.h>
#include <stdlib.h>

#include "ctx_internal.h"

static atomic_long allocations;   /* made since the process started */
static atomic_long fail_at = 0;   /* that count fails (once); 0: none */

static int injected_failure(void)
{
    long n = atomic_fetch_add(&allocations, 1) + 1;
    long at = atomic_load(&fail_at);
    return at > 0 && n == at;
}

void *ss_malloc(size_t bytes)
{
    return injected_failure() ? NULL : malloc(bytes);
}

void *ss_calloc(size_t count, size_t size)
{
    return injected_failure() ? NULL : calloc(count, size);
}

void *ss_realloc(void *p, size_t bytes)
{
    return injected_failure() ? NULL : realloc(p, bytes);
}

void *ss_alloc_grid(size_t bytes)
{
    const size_t align = 4096;
    size_t rounded = (bytes + align - 1) / align * align;
    return injected_failure() ? NULL : aligned_alloc(align, rounded ? rounded : align);
}

long ss_fault_allocations(void)
{
    return atomic_load(&allocations);
}

void ss_fault_fail_allocation(long n)
{
    atomic_store(&fail_at, n > 0 ? atomic_load(&allocations) + n : 0);
}
