/* grow.h - a growable array's capacity, doubled as needed: one helper for
 * every list built in place (mesh readers, the camera-ray bins). */
#ifndef NC_GROW_H
#define NC_GROW_H

#include <errno.h>
#include <stdint.h>
#include <stdlib.h>

/* Make *p hold at least need elements of elem bytes (*cap: what it holds);
 * 0, or -ENOMEM with *p and *cap unchanged. */
static inline int nc_grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 1024;
    while (c < need && c <= SIZE_MAX / 2)
        c *= 2;
    if (c < need || c > SIZE_MAX / elem) /* a size no allocation can hold */
        return -ENOMEM;
    void *q = realloc(*p, c * elem);
    if (!q)
        return -ENOMEM;
    *p = q;
    *cap = c;
    return 0;
}

#endif
