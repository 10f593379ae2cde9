/* rt_rocks.h - boulders (boulders.h) as one Embree user geometry per body:
 * each rock a primitive that refers to its shared shape, 48 bytes plus the
 * tree's share, where an Embree instance costs about 390 bytes (measured
 * with Embree 3.13: a million instances take 368 MiB). Internal to the
 * Embree back-end (rt_embree.c). */
#ifndef NC_RT_ROCKS_H
#define NC_RT_ROCKS_H

#include <embree3/rtcore.h>

#include "core/vec.h"
#include "render/boulders.h"

struct nc__rt_rocks {
    const struct nc_boulder_field *field;
    const struct nc_vec3 *anchor_m; /* the body's anchor (body frame): geometry is relative to it */
};

/* The user geometry of r's rocks, committed; NULL if Embree refused. */
RTCGeometry nc__rt_rocks_geometry(RTCDevice dev, struct nc__rt_rocks *r);

#endif
