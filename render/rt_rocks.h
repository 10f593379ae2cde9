/* rt_rocks.h - boulders (boulders.h) for the Embree back-end: a scene per
 * body of its own, instanced with the body's transform, holding one user
 * geometry per octave of diameter. Each rock is a primitive that refers to
 * its shared shape: 48 bytes in the list, 64 here, plus the tree's share,
 * where an Embree instance costs about 390 bytes (measured with Embree
 * 3.13: a million instances take 368 MiB). Rocks smaller than a
 * cut are not traced: octaves wholly below it are disabled, and the rest of
 * the boulders below it are refused in the intersection test. Internal to
 * the Embree back-end (rt_embree.c). */
#ifndef NC_RT_ROCKS_H
#define NC_RT_ROCKS_H

#include <embree3/rtcore.h>

#include "core/vec.h"
#include "render/boulders.h"

struct nc__rt_rocks;

struct nc__rt_rock_octave {
    struct nc__rt_rocks *rocks;
    size_t first; /* its first rock in the list */
    RTCGeometry geom;
    int enabled;
};

/* What the intersection test reads of a rock: one cache line. */
struct nc__rt_rock {
    float c[3];   /* centre relative to the anchor, body frame, m */
    float M[9];   /* body frame -> rock frame over half_m: R^T / half_m, row-major */
    float ext[3]; /* the rock's extent from c along each body axis, m */
    uint32_t shape;
};

_Static_assert(sizeof(struct nc__rt_rock) == 64, "a rock record is one cache line");

struct nc__rt_rocks {
    const struct nc_boulder_field *field;
    const struct nc_vec3 *anchor_m; /* the body's anchor (body frame): geometry is relative to it */
    struct nc__rt_rock *rock;       /* field->rock[i] as traced */
    RTCScene scene;
    struct nc__rt_rock_octave octave[NC_BOULDER_OCTAVES];
    int noctaves;
    double min_d_m; /* the cut: the smallest diameter traced */
    size_t traced;  /* rocks at or above the cut: rock[0 .. traced) */
    double cut_cover; /* nc_boulders_cover() of the rocks below the cut */
    int dirty;        /* the scene needs a commit */
};

/* The list index of the rock a hit in the rocks' scene names. */
static inline size_t nc__rt_rock_index(const struct nc__rt_rocks *r, unsigned geom_id, unsigned prim_id)
{
    return r->octave[geom_id].first + prim_id;
}

/* Lane i of an Embree ray packet of width N (RTCRayN: origin, tnear,
 * direction, time, tfar, ... by component), as a user geometry reads it.
 * Shared by the analytic ellipsoid (rt_embree.c) and the rocks. */
struct nc__rt_lane {
    float o[3], d[3], tnear, tfar;
};

static inline struct nc__rt_lane nc__rt_lane(const float *ray, unsigned N, unsigned i)
{
    return (struct nc__rt_lane){.o = {ray[0 * N + i], ray[1 * N + i], ray[2 * N + i]},
                                .d = {ray[4 * N + i], ray[5 * N + i], ray[6 * N + i]},
                                .tnear = ray[3 * N + i],
                                .tfar = ray[8 * N + i]};
}

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

/* The rock scene of field f, rocks relative to *anchor_m, every rock traced
 * until the first nc__rt_rocks_cut. Not committed: nc__rt_rocks_commit. */
int nc__rt_rocks_init(RTCDevice dev, const struct nc_boulder_field *f, const struct nc_vec3 *anchor_m,
                      struct nc__rt_rocks *r);
/* Trace rocks of diameter min_d_m or more only (0: all). */
void nc__rt_rocks_cut(struct nc__rt_rocks *r, double min_d_m);
/* Move the rocks to the anchor (moved: after a re-anchor) and, if that or a
 * cut changed the scene, commit it (a rebuild of its tree). */
void nc__rt_rocks_commit(struct nc__rt_rocks *r, int moved);
void nc__rt_rocks_free(struct nc__rt_rocks *r);

#endif
