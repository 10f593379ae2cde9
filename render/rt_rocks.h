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

/* A user geometry's hit for lane i of a's packet: tfar = t, geometric
 * normal n (unnormalised, the geometry's frame), ids from a. Shared by the
 * analytic ellipsoid (rt_embree.c) and the rocks. */
static inline void nc__rt_user_hit(const struct RTCIntersectFunctionNArguments *a, unsigned i, float t,
                                   const float n[3])
{
    float *ray = (float *)a->rayhit, *hit = ray + 12 * a->N;
    unsigned N = a->N;
    ray[8 * N + i] = t;
    for (int k = 0; k < 3; k++)
        hit[k * N + i] = n[k];
    hit[3 * N + i] = 0;
    hit[4 * N + i] = 0;
    ((unsigned *)hit)[5 * N + i] = a->primID;
    ((unsigned *)hit)[6 * N + i] = a->geomID;
    ((unsigned *)hit)[7 * N + i] = a->context->instID[0];
}

/* The user geometry of r's rocks, committed; NULL if Embree refused. */
RTCGeometry nc__rt_rocks_geometry(RTCDevice dev, struct nc__rt_rocks *r);

#endif
