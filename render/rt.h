/* rt.h - ray-tracing back-end interface (implemented with Embree 3 in
 * rt_embree.c and, for boulders, rt_rocks.c, rt_rocks_build.c and
 * rt_rock_mesh.c: the only files that include Embree headers).
 *
 * Rays live in the camera-relative scene frame: origin at the camera position,
 * axes of the scene frame. Each body is an instance whose geometry is stored
 * relative to an anchor point near the camera, in double-precision-derived
 * float coordinates, so that precision follows the camera, not the body origin.
 * Shadow rays leaving a body seen from afar go in that body's far frame
 * instead (nc_rt_far_frame: the same axes, its origin at the body's), where
 * they start as near its surface as its own size allows.
 */
#ifndef NC_RT_H
#define NC_RT_H

#include "render/scene.h"

#define NC_PACKET 16

struct nc_rt;

struct nc_ray16 {
    _Alignas(64) float ox[NC_PACKET];
    float oy[NC_PACKET], oz[NC_PACKET];
    float dx[NC_PACKET], dy[NC_PACKET], dz[NC_PACKET];
    float tnear[NC_PACKET], tfar[NC_PACKET];
    int valid[NC_PACKET]; /* -1 active, 0 inactive */
};

struct nc_hit16 {
    float t[NC_PACKET];                    /* ray parameter of the hit (tfar) */
    float nx[NC_PACKET], ny[NC_PACKET], nz[NC_PACKET]; /* geometric normal, scene frame, unnormalised */
    /* the facet's normal where nx.. is a smooth shading normal (a mesh's interpolated vertex normals), else the
     * same: a point of a facet turned away from the Sun is unlit whatever its shading normal */
    float fnx[NC_PACKET], fny[NC_PACKET], fnz[NC_PACKET];
    int body[NC_PACKET];                   /* body index, -1 for a miss */
    float albedo[NC_PACKET];               /* factor on the albedo there (albedo_var.h; 1: none) */
    int32_t rock[NC_PACKET];               /* the boulder hit (its index in the body's list), -1: none */
    uint32_t prim[NC_PACKET];              /* the body's own triangle hit, in its level's list (set where
                                              nc_rt_refine_on: nc_rt_refine_mesh16 reads it) */
};

struct nc_rt_stats {
    unsigned long reanchors; /* geometry rebuilt around a new anchor */
    /* Per body, at the last update: the level of detail shown (0 = the full
     * mesh or an analytic shape), its triangles and its error bound, m. */
    int lod_level[NC_MAX_BODIES];
    size_t lod_triangles[NC_MAX_BODIES];
    double lod_error_m[NC_MAX_BODIES];
    /* Per body with boulders, at the last update: the smallest diameter
     * traced, m (0: every rock), and how many rocks that leaves. */
    double boulder_min_m[NC_MAX_BODIES];
    size_t boulders_traced[NC_MAX_BODIES];
    /* ... and the cover of the rocks left out (nc_boulders_cover), which
     * the reflectance folds in (nc_material_fold_rocks). */
    double boulder_cut_cover[NC_MAX_BODIES];
    /* ... and render.boulder_mesh_px where its rocks have detailed
     * surfaces (rough faces), else 0. */
    double boulder_mesh_px[NC_MAX_BODIES];
    /* Since creation, as the renderer reports them (nc_rt_count_shadow_rays):
     * shadow rays proven unoccluded (nc_rt_shadow_cull16), and traced. */
    unsigned long shadow_rays_culled, shadow_rays_traced;
    /* Whether the last pass's camera rays went through the bins
     * (nc_rt_bin_camera served it). */
    int camera_bins;
    /* ... and camera-ray samples that met a surface, and those of them that
     * met its back, inner side (a camera inside a body sees little else). */
    unsigned long camera_hits, camera_back_hits;
    /* Per body, at the last update: the rock (its index in the body's list)
     * the camera is inside, -1 for none. Rocks are one-sided, so such a
     * camera sees out of the rock as if it were not there. */
    long camera_in_rock[NC_MAX_BODIES];
};

int nc_rt_create(const struct nc_scene *s, int threads, struct nc_rt **out);
/* Bring the back-end to the scene's current camera and body poses. */
int nc_rt_update(struct nc_rt *rt, const struct nc_scene *s);
/* Closest hits; coherent = camera rays. */
void nc_rt_intersect16(struct nc_rt *rt, const struct nc_ray16 *ray, struct nc_hit16 *hit, int coherent);
/* Camera rays through binned triangles (rt_bins.h) for this pass, when
 * every camera ray leaves one point o (camera-relative scene frame) along
 * d00 + x ex + y ey through image point (x, y) (pixels, centres at
 * integers) and every sample of pixel (px, py) lies within half a pixel of
 * it; cam NULL turns them off. Returns 1 when nc_rt_intersect_block serves
 * the pass (every body a mesh, no triangle across the plane through o
 * parallel to the image, and no more triangles than camera
 * samples could reach the bodies: the lists cost about half of what Embree
 * spends on a sample, per triangle), 0 when it does not, or a negative
 * error code. The lists are built on pool's threads (NULL: the caller's
 * alone), the same for any number. Boulders are traced in front of the
 * lists' hits, through the rocks' own lists (rt_rock_bins.h) or, where
 * those cannot serve the pass, the rocks alone. Call after nc_rt_update. */
struct nc_rt_pinhole {
    struct nc_vec3 o, d00, ex, ey;
    int width_px, height_px;
    int samples_per_pixel; /* the frame's, over all its passes: the choice is the same for each */
};
struct nc_pool;
int nc_rt_bin_camera(struct nc_rt *rt, const struct nc_rt_pinhole *cam, struct nc_pool *pool, int threads);
/* Closest hits, as nc_rt_intersect16's, of n packets of camera rays from
 * the pinhole of nc_rt_bin_camera (tnear 0), every lane in the 4x4 pixel
 * block at (px0, py0) (multiples of 4). */
void nc_rt_intersect_block(struct nc_rt *rt, int px0, int py0, const struct nc_ray16 *ray, struct nc_hit16 *hit,
                           int n);
/* What the lists say of the 4x4 pixel block at (px0, py0), in a pass that
 * nc_rt_bin_camera serves: 1 if they hold a triangle or a rock for it, 0
 * if no camera ray of it can hit anything, -1 if they cannot tell (rocks
 * are traced and their own lists do not serve the pass). */
int nc_rt_block_listed(const struct nc_rt *rt, int px0, int py0);
/* For a hit on an analytic body, recompute range t and unit normal n (scene
 * frame) in double precision for the exact camera-relative ray origin + t d (d unit):
 * the packet trace is float. Returns 1 if refined, 0 for meshes (the float
 * answer stands), and -1 when the exact ray misses the body: a float hit at
 * the limb that is not there, to be treated as a miss. */
int nc_rt_refine(const struct nc_rt *rt, int body, struct nc_vec3 origin, struct nc_vec3 d, double *t,
                 struct nc_vec3 *n);
/* Whether some mesh body is close enough this frame for its float geometry
 * to matter (its anchor near the camera): then nc_rt_refine_mesh16 serves. */
int nc_rt_refine_on(const struct nc_rt *rt);
/* For the lanes of hit on such a body's own triangles (not rocks) nearer
 * than 64 times its longest edge, where the float vertices (coordinates up
 * to an edge from the anchor) would err by more than 6e-8 of the range:
 * t[i] recomputed in double precision from the mesh's double vertices, for
 * the camera-relative ray orig[i] + t dir[i] (dir unit), and scale[i] (the
 * float error's scale, m: t[i] on entry) set to t plus that edge. Lanes not
 * refined keep t[i] and scale[i]. */
void nc_rt_refine_mesh16(const struct nc_rt *rt, const struct nc_hit16 *hit, const struct nc_vec3 *orig,
                         const struct nc_vec3 *dir, double *t, double *scale);
/* For body b's own triangles prim[i] met by the lanes of nonzero lanes[i]
 * (rays orig[i] + t[i] dir[i], dir unit, camera-relative scene frame), when
 * its shadow rays go in its far frame (nc_rt_far_frame): t[i] recomputed in
 * double precision from its double vertices, so that the point is known to
 * 1e-16 of the range instead of 1e-7, and done[i] set (0 where the double
 * ray misses that triangle: near an edge the float ray, the body placed
 * 6e-8 of the range off, can meet one the exact ray passes by; t[i] then
 * stands). Analytic shapes' hits are refined already (nc_rt_refine): left
 * as they are, done. */
void nc_rt_refine_far16(const struct nc_rt *rt, int b, const int *lanes, const uint32_t *prim,
                        const struct nc_vec3 *orig, const struct nc_vec3 *dir, double *t, int *done);
/* Occlusion: on return occluded[i] is nonzero for blocked active rays.
 * frame: -1, rays in the camera-relative scene frame; b >= 0, rays in body
 * b's far frame (nc_rt_far_frame). */
void nc_rt_occluded16(struct nc_rt *rt, const struct nc_ray16 *ray, int *occluded, int frame);
/* Whether the shadow rays leaving body b (its surface and its rocks; the
 * renderer keeps bounce points in the camera's frame) go in its far frame
 * at the last update: relative to its origin, scene axes, where float rays
 * and geometry carry 6e-8 of the body's size instead of the range (the
 * camera is farther than a bounding radius from its bounding sphere, and
 * where its rocks are traced, 2.4e-7 of the range is under 1 % of a pixel:
 * docs/validation.md; an analytic shape is left out of its own far frame:
 * a convex shape cannot shadow itself). The frame's origin is the body's,
 * at s->body[b].position_m - s->camera.position_m from the camera;
 * *scale_m: the scale of its float coordinates there (its bounding radius).
 * Hits on its mesh are known to 1e-7 of the range along the ray: enough
 * for nc_rt_shadow_cull16's proof, which takes no ray within the grid's
 * margin of the mesh, and refined by nc_rt_refine_far16 before a ray is
 * traced from there. */
int nc_rt_far_frame(const struct nc_rt *rt, int b, double *scale_m);
/* The same for n (at most NC_PACKET) rays from the camera along the unit
 * scene-frame directions dir, each to distance tfar_m (INFINITY: the whole
 * way): stars, the Sun's disk, a far body's line of sight. */
void nc_rt_occluded_dirs(struct nc_rt *rt, const struct nc_vec3 *dir, int n, double tfar_m, int *occluded);
/* Shadow rays that need no full trace: from[i] >= 0 says ray i leaves the
 * outer side of body from[i] (a surface point whose normal faces both
 * camera and ray). Rays proven clear of every mesh (shadow_grid.h for the
 * body's own, the bounding spheres for the others) are made inactive; where
 * boulders are traced they are traced through the rocks alone first, and
 * one that meets a rock is marked in blocked[i] (which the caller zeroes).
 * frame as for nc_rt_occluded16 (the rays leaving body b in its far frame).
 * Returns how many were proven to meet nothing. */
int nc_rt_shadow_cull16(struct nc_rt *rt, struct nc_ray16 *ray, const int *from, int *blocked, int frame);
/* Add to the shadow-ray counts of nc_rt_get_stats (callers add a tile's
 * worth at a time: the counters are shared by every render thread). */
void nc_rt_count_shadow_rays(struct nc_rt *rt, unsigned long culled, unsigned long traced);
void nc_rt_count_camera_hits(struct nc_rt *rt, unsigned long hits, unsigned long back_hits);
/* Whether back of a frame's hits camera samples that met a surface met its
 * back, inner side: most of them (a camera inside a body, or a mesh wound
 * inward), what render, batch and serve warn of. */
static inline int nc_rt_mostly_back(unsigned long hits, unsigned long back) { return back > hits / 2; }
/* The rock the camera is inside (st->camera_in_rock), the first of nbodies'
 * bodies: its index in the body's list with *body set, or -1. */
static inline long nc_rt_camera_in_rock(const struct nc_rt_stats *st, int nbodies, int *body)
{
    for (int b = 0; b < nbodies; b++)
        if (st->camera_in_rock[b] >= 0) {
            *body = b;
            return st->camera_in_rock[b];
        }
    return -1;
}
void nc_rt_get_stats(const struct nc_rt *rt, struct nc_rt_stats *st);
/* The largest error bound of the levels of detail shown at the last update,
 * metres (0: every body at full resolution). */
double nc_rt_lod_error_m(const struct nc_rt *rt);
/* The largest of the bodies' smallest boulder diameters traced at the last
 * update, metres (0: every rock of every body, or no boulders). */
double nc_rt_boulder_min_m(const struct nc_rt *rt);
/* The largest of the bodies' boulder_mesh_px at the last update (0: no rock
 * is traced as a detailed surface). */
double nc_rt_boulder_mesh_px(const struct nc_rt *rt);
/* Triangles of each detailed rock surface of body b (0: none). */
size_t nc_rt_rock_mesh_triangles(const struct nc_rt *rt, int b);

/* For benchmarks: Embree alone on pre-built native packets. The packets are
 * converted once (untimed); nc_rt_batch_trace() then only resets each packet
 * and calls rtcIntersect16 (coherent) or rtcOccluded16 (or, with single, the
 * same rays one by one through rtcIntersect1/rtcOccluded1), spread over
 * `threads` threads in chunks, and returns the wall time in ms. frames: each
 * packet's frame as nc_rt_occluded16 takes it (NULL: every one the
 * camera's). */
struct nc_rt_batch;
int nc_rt_batch_create(const struct nc_ray16 *rays, const int *frames, size_t npackets, int occlusion,
                       struct nc_rt_batch **out);
double nc_rt_batch_trace(struct nc_rt *rt, struct nc_rt_batch *b, int threads, int single);
void nc_rt_batch_destroy(struct nc_rt_batch *b);
void nc_rt_destroy(struct nc_rt *rt);

#endif
