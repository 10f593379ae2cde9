/* rt_bins.h - camera rays against binned triangles. When every camera ray
 * of a render leaves one point (no rolling-shutter motion, no lens
 * distortion: a pinhole at rest over the pass), each triangle that can be a
 * ray's first hit is listed in the 4x4-pixel blocks its image overlaps, and
 * a block's rays are tested against its list alone: no tree to walk, a
 * packet of 16 rays against one triangle per step. The tests are exact
 * closest-hit tests (watertight across shared edges, ties to the lowest
 * triangle); the lists are conservative (a triangle's image is bounded by
 * its projected vertices, padded for the float rays). Internal to the
 * ray-tracing back-end (rt_embree.c); it knows nothing of Embree. */
#ifndef NC_RT_BINS_H
#define NC_RT_BINS_H

#include <stddef.h>
#include <stdint.h>

#include "core/vec.h"
#include "render/rt.h"

#define NC_BINS_BLOCK 4 /* pixels a block side (render.c's 4x4 blocks) */

/* Bounds of a run of NC_BINS_CLUSTER consecutive triangles (the last run
 * may be shorter), body frame: a sphere holding them and a cone holding
 * their facet normals. A run wholly outside the image, or whose triangles
 * all face away from the rays' origin by more than the float vertices can
 * move them, is skipped whole; no triangle listed otherwise is lost. Meshes
 * whose triangle order follows the surface (a subdivided solid's does)
 * give tight runs; others only cost the test. */
#define NC_BINS_CLUSTER 64
struct nc__bins_cluster {
    double c[3], r;            /* sphere: centre, radius (m) */
    double a[3], cos_t, sin_t; /* cone: unit axis, half-angle (cos_t <= 0: no cone) */
    double alt;                /* the smallest altitude of its triangles, m */
};

/* Triangles tri[0 .. nt) of vertices v: their normals (v1 - v0) x (v2 - v0)
 * into ng[3 nt] (computed in double, as Embree's convention has it) and
 * their clusters into out[(nt + NC_BINS_CLUSTER - 1) / NC_BINS_CLUSTER]. */
void nc__bins_facets(const double *v, const unsigned *tri, size_t nt, float *ng, struct nc__bins_cluster *out);

/* A triangle mesh as shown this pass. */
struct nc__bins_body {
    const double *v;       /* body-frame vertices, m (x, y, z each) */
    const unsigned *tri;   /* the triangles shown: 3 vertex indices each */
    const float *ng;       /* and their normals in the body frame, 3 each (nc__bins_facets; copied to the hits) */
    const struct nc__bins_cluster *cl; /* their clusters (nc__bins_facets; NULL: none skipped) */
    size_t nv, nt;
    struct nc_mat3 R;      /* body -> scene */
    struct nc_vec3 origin; /* body origin relative to the rays' origin, scene frame, m */
    /* Only triangles that face the rays' origin (their (v1 - v0) x (v2 - v0)
     * towards it) can be hit first: a closed, outward mesh seen from outside
     * its bounding sphere. Else both sides are listed. */
    int front_only;
};

/* The image: the ray through image point (x, y) (pixel units; pixel centres
 * at integers) runs along d00 + x ex + y ey (scene frame), and every sample
 * of pixel (px, py) lies in [px - 1/2, px + 1/2] x [py - 1/2, py + 1/2]. */
struct nc__bins_view {
    struct nc_vec3 d00, ex, ey;
    int width_px, height_px;
};

/* A listed triangle: what the test reads (e, n, nv0), then the normal the
 * shading takes; one cache line. */
struct nc__bins_tri {
    float e[3][3]; /* v1 x v2, v2 x v0, v0 x v1 (rays' origin at 0): the edge planes */
    float n[3];    /* (v1 - v0) x (v2 - v0) */
    float nv0;     /* n . v0 */
    float ng[3];   /* the body's normal of it (nc__bins_body.ng) */
};

struct nc_pool;

struct nc__bins {
    int bw, bh, nparts;
    int avx512; /* the build's triangle setup and the test in AVX-512 registers (the same bits as without) */
    int plain;  /* set by the caller: never AVX-512 (tests compare the two) */
    size_t nblocks;
    /* The build's input. */
    struct nc__bins_body body[NC_MAX_BODIES];
    int nbodies;
    size_t v_off[NC_MAX_BODIES + 1], t_off[NC_MAX_BODIES + 1], c_off[NC_MAX_BODIES + 1]; /* bodies' first vertex, triangle, cluster */
    double Mi[3][3]; /* scene direction -> (x s, y s, s) of image point (x, y) */
    double side[4][3]; /* unit normals of the planes through the origin bounding the blocks' samples, inwards */
    uint8_t *cl_live;  /* per cluster: may hold a listed triangle */
    double pad_px;
    /* Part p of the build takes the triangles [t_off end * p / nparts, ...
     * (p + 1) / nparts) and lists those it keeps from slot (its first
     * triangle) on: slots ascend with the triangles, whatever nparts. */
    struct nc__bins_tri *cand; /* by slot */
    uint32_t *tri;             /* slot -> triangle (over all bodies: t_off[body] + index) */
    int16_t (*range)[4];       /* slot -> blocks x0, x1, y0, y1 */
    size_t *kept;              /* per part: slots used */
    uint32_t *count;           /* per part and block: entries, then the fill's cursors */
    uint32_t *start;           /* block k's candidate slots: list[start[k] .. start[k + 1]) */
    uint32_t *list;
    float (*vp)[6]; /* per vertex: position from the rays' origin (3), image x, y, depth sign */
    size_t cand_cap, tri_cap, range_cap, count_cap, start_cap, list_cap, vp_cap, kept_cap, cl_live_cap;
    int phase;
    _Atomic int next, straddle;
};

/* The body holding global index i of a table of offsets. */
static inline int nc__bins_body_of(const size_t *off, int nbodies, size_t i)
{
    int k = 0;
    while (k + 1 < nbodies && i >= off[k + 1])
        k++;
    return k;
}

/* The lists for this view, built on the threads of pool (NULL: the caller
 * alone) in nparts parts (the lists do not depend on it). Returns 1, 0 when
 * they cannot serve the view (a triangle crosses the plane through the
 * rays' origin parallel to the image: its image is unbounded), or a
 * negative error code. */
int nc__bins_build(struct nc__bins *b, const struct nc__bins_view *view, const struct nc__bins_body *bodies,
                   int nbodies, struct nc_pool *pool, int nparts);

/* Closest hits of npk packets of rays from the view's origin (tnear 0),
 * lane i of each in the block at (px0, py0) (multiples of NC_BINS_BLOCK):
 * per lane the slot of the triangle hit (-1: none) and its ray parameter. */
#define NC_BINS_GROUP 4 /* packets tested together */
void nc__bins_intersect(const struct nc__bins *b, int px0, int py0, const struct nc_ray16 *ray, int npk,
                        int32_t (*slot)[NC_PACKET], float (*t)[NC_PACKET]);

/* Barycentric weights (u of v1, v of v2) of ray direction d on candidate c. */
void nc__bins_uv(const struct nc__bins_tri *c, const float *d, float *u, float *v);

/* The body of the triangle in slot and, with prim, its index in that
 * body's triangles (one body and no prim: no memory read). */
static inline int nc__bins_which(const struct nc__bins *b, int32_t slot, uint32_t *prim)
{
    if (b->nbodies == 1 && !prim)
        return 0;
    const size_t g = b->tri[slot];
    const int k = nc__bins_body_of(b->t_off, b->nbodies, g);
    if (prim)
        *prim = (uint32_t)(g - b->t_off[k]);
    return k;
}

void nc__bins_free(struct nc__bins *b);

#endif
