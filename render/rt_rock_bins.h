/* rt_rock_bins.h - camera rays against binned rocks. Where the bins of
 * rt_bins.h serve a pass, every rock traced (rt_rocks.h) is listed in the
 * 4x4-pixel blocks its bounding sphere's image overlaps, each entry with
 * the pixels of the block it can reach and the nearest depth of its
 * sphere; a packet of camera rays is tested against its block's list
 * alone, with the rocks' own test (nc__rt_rock_lanes) on the lanes the
 * entry names whose ray reaches that depth and meets the rock's box before
 * its closest hit so far: no tree of tiles to walk. The
 * lists are conservative (the sphere's image is bounded exactly, padded
 * for the float rays); a sphere across the plane through the rays' origin
 * parallel to the image has no bounded image, and the lists then cannot
 * serve the pass. Internal to the ray-tracing back-end (rt_embree.c). */
#ifndef NC_RT_ROCK_BINS_H
#define NC_RT_ROCK_BINS_H

#include <stddef.h>
#include <stdint.h>

#include "render/rt_bins.h"
#include "render/rt_rocks.h"

/* A body's rocks as shown this pass. */
struct nc__rock_bins_body {
    const struct nc__rt_rocks *rocks;
    const float *rot; /* body -> scene, row-major */
};

/* A listed rock: primitive prim of tile tile (the build's numbering), the
 * lanes of its block (bit i: pixel (i % 4, i / 4)) it can reach, and its
 * sphere's nearest point's s (the image's depth coordinate: a point q is
 * s (d00 + x ex + y ey)). */
struct nc__rock_entry {
    uint32_t prim;
    uint16_t tile, lanes;
    float s_near;
};

struct nc__rock_bins {
    int nparts;
    const struct nc__bins *view; /* the mesh bins of the pass: blocks, image map, padding */
    float rot[NC_MAX_BODIES][9];
    float o_body[NC_MAX_BODIES][3]; /* the rays' origin in each body's frame, R^T o */
    float s_of[3];                  /* s of a direction d: s_of . d */
    /* Tiles over every body, and their rocks end to end in that order. */
    const struct nc__rt_rock_tile **tile;
    uint8_t *tile_body;
    size_t *tile_first; /* tile k's rocks: [tile_first[k], tile_first[k + 1]) */
    size_t ntiles;
    double o[3]; /* the rays' origin, camera-relative scene frame */
    uint32_t *count, *start;
    struct nc__rock_entry *list;
    size_t count_cap, start_cap, list_cap;
    int phase;
    _Atomic int next, straddle;
};

/* The lists for the view whose mesh bins (nc__bins_build, returned 1) are
 * view, the rays leaving o (camera-relative scene frame), on pool's
 * threads in nparts parts (the lists do not depend on it). Returns 1, 0
 * when they cannot serve the pass, or a negative error code. */
int nc__rock_bins_build(struct nc__rock_bins *rb, const struct nc__bins *view, struct nc_vec3 o,
                        const struct nc__rock_bins_body *bodies, int nbodies, struct nc_pool *pool, int nparts);

/* Whether the block at (px0, py0) lists a rock. */
static inline int nc__rock_bins_listed(const struct nc__rock_bins *rb, int px0, int py0)
{
    const size_t k = (size_t)(py0 / NC_BINS_BLOCK) * (size_t)rb->view->bw + (size_t)(px0 / NC_BINS_BLOCK);
    return rb->start[k + 1] > rb->start[k];
}

/* Each lane's closest rock (nc__rock_bins_intersect): lane 16 q + i is
 * lane i of packet q. */
#define NC_ROCK_BINS_LANES (NC_BINS_GROUP * NC_PACKET)
struct nc__rock_bins_hits {
    float t[NC_ROCK_BINS_LANES];
    int32_t tile[NC_ROCK_BINS_LANES];
    uint32_t prim[NC_ROCK_BINS_LANES];
    float n[NC_ROCK_BINS_LANES][3];
    int detailed[NC_ROCK_BINS_LANES];
};

/* The closest rocks in front of the npk (1 to NC_BINS_GROUP) packets ray
 * (camera rays from o, lane i of each in pixel (px0 + i % 4, py0 + i / 4)
 * of the block at (px0, py0)) within (tnear, h->t): where one is met, h->t
 * becomes its distance, h->tile its tile (the build's numbering; -1 where
 * none is), h->prim its primitive, h->n the normal there (its tile's frame,
 * unnormalised) and h->detailed whether it was traced as its detailed
 * surface. Each entry is tested on the passing lanes of all the packets at
 * once, NC__RT_LANES at a time: each lane meets the same entries in the
 * same order as alone, so the same hits. */
void nc__rock_bins_intersect(const struct nc__rock_bins *rb, int px0, int py0, const struct nc_ray16 *ray, int npk,
                             struct nc__rock_bins_hits *h);

void nc__rock_bins_free(struct nc__rock_bins *rb);

#endif
