/* rt_rocks.h - boulders (boulders.h) for the Embree back-end. Each octave
 * of diameter is split into tiles, cubes of the body frame 1024 times the
 * octave's largest diameter on a side; a tile is an Embree scene of its own
 * (one user geometry whose primitives are its rocks, each referring to its
 * shared shape: 48 bytes in the list and 64 here, plus the tree's share)
 * with its rocks stored relative to the tile's own origin in Morton order
 * of their centres (a tree's leaves, visited by nearby rays, read records
 * near each other in memory), and two instances: in the top-level scene,
 * and in the scene of the rocks alone (rt_embree.c: rays proven clear of
 * the meshes, or whose mesh hits came from the bins, test only the rocks;
 * where the rocks' own bins, rt_rock_bins.h, serve a pass, its camera rays
 * test only the rocks listed in their block). The tiles' trees are built once:
 * a pose only moves their instances (the float translation from the camera
 * to a tile's origin, the middle of its rocks, costs 6e-8 of that distance,
 * a record 6e-8 of its distance from the origin), so nothing
 * is rebuilt when the camera moves. Rocks smaller than a cut are not traced: tiles of
 * octaves wholly below it are disabled, and the rest of the rocks below it
 * are refused in the intersection test by their rank in the list (the list
 * is sorted by size). An Embree instance per rock would cost about 390
 * bytes (measured with Embree 3.13: a million instances take 368 MiB); per
 * tile, it is a few per thousand rocks. Rough-faced rocks resolved by
 * render.boulder_mesh_px pixels are traced through their shape's detailed
 * surface (rt_rock_mesh.c), which lies within their planes. Internal to
 * the Embree back-end (rt_embree.c). */
#ifndef NC_RT_ROCKS_H
#define NC_RT_ROCKS_H

#include <embree3/rtcore.h>

#include "core/vec.h"
#include "render/boulders.h"

struct nc__rt_rocks;

/* A shape's detailed surface: its Embree scene, and for its shading normals
 * (interpolated over each triangle) the normals at its triangles' corners,
 * smooth within the polyhedron's faces and sharp across its edges. */
struct nc__rt_rock_surface {
    RTCScene scene;
    int16_t *cn; /* 9 a triangle: its corners' unit normals, rock frame, times 32767 */
};

struct nc__rt_rock_tile {
    struct nc__rt_rocks *rocks;
    double origin_m[3];    /* body frame: its rocks' records are relative to it */
    const struct nc__rt_rock *rec; /* each primitive's record, in Morton order of their centres */
    const float (*ext)[3];         /* while its tree is built: each primitive's extent (nc__rt_rocks_init) */
    unsigned n;
    int octave; /* in the field's octave table */
    RTCScene scene;
    RTCGeometry geom, inst, inst_solo; /* its instances in the top-level scene and in the rocks' alone */
    unsigned inst_id;                  /* in both */
    float place_m[3];                  /* the instances' translation: its origin from the camera, scene frame */
    float cam_m[3];                    /* the camera from its origin, body frame */
    int enabled;
};

/* What the intersection test reads of a rock: one cache line. */
struct nc__rt_rock {
    float c[3];    /* centre relative to its tile's origin, body frame, m */
    float M[9];    /* body frame -> rock frame over half_m: R^T / half_m, row-major */
    uint32_t rank; /* its index in the field's list (the larger the rock, the lower) */
    uint32_t shape;
    uint32_t spare[2];
};

_Static_assert(sizeof(struct nc__rt_rock) == 64, "a rock record is one cache line");

struct nc__rt_rocks {
    const struct nc_boulder_field *field;
    struct nc__rt_rock *rock; /* the tiles' records, end to end (tile[k].rec) */
    struct nc__rt_rock_tile *tile;
    size_t ntiles;
    double min_d_m;   /* the cut: the smallest diameter traced */
    size_t traced;    /* rocks at or above the cut: rock[0 .. traced) */
    double cut_cover; /* nc_boulders_cover() of the rocks below the cut */
    double px_rad;    /* the camera's pixel, rad (the finest axis): the relief's footprint */
    /* Rocks resolved by render.boulder_mesh_px pixels or more at their
     * centre's distance from the camera are traced as their shape's
     * detailed surface (nc_rock_shape_mesh: the coarse relief in geometry,
     * within the planes), the others as flat-faced polyhedra. surf[] is
     * NULL for flat-faced rocks (roughness_deg 0). */
    struct nc__rt_rock_surface *surf;
    size_t mesh_triangles; /* each shape's surface */
    float mesh_k2;         /* (boulder_mesh_px * px_rad)^2, 0: no rock is */
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

/* Rays for the rocks' test, eight lanes at a time (GCC/Clang vector
 * extensions: one AVX2 register where the CPU has it, two SSE or NEON ones
 * otherwise; no FMA, so the same bits on any): origin, tnear, direction,
 * tfar, valid (-1: on), in a tile's frame. */
#define NC__RT_LANES 8
typedef float nc__rt_vlf __attribute__((vector_size(4 * NC__RT_LANES)));
typedef int nc__rt_vli __attribute__((vector_size(4 * NC__RT_LANES)));
struct nc__rt_lanes {
    nc__rt_vlf o[3], tnear, d[3], tfar;
    nc__rt_vli valid;
};

/* The lanes of p against primitive prim of tile tl, a rock above the cut:
 * bit l of the result set where lane l meets it within (tnear, tfar), at
 * t[l], with the normal there in n[l] (the tile's frame, unnormalised;
 * occlusion only if n is NULL). *detailed: the rock is traced as its
 * detailed surface (its hits take only the relief's octaves the geometry
 * does not carry). A lane from inside the rock sees nothing of it. */
unsigned nc__rt_rock_lanes(const struct nc__rt_rock_tile *tl, unsigned prim, const struct nc__rt_lanes *p, float *t,
                           float (*n)[3], int *detailed);

/* The rocks' bounds, intersection and occlusion callbacks on tile geometry g
 * (its user data the tile). */
void nc__rt_rock_callbacks(RTCGeometry g);

/* The tiles of field f, every rock traced until the first cut. */
int nc__rt_rocks_init(RTCDevice dev, const struct nc_boulder_field *f, struct nc__rt_rocks *r);
/* Each tile's instances, attached to top (tile[k].inst_id) and under the
 * same ID to solo, the scene of every body's rocks alone (shadow rays a
 * body's grid proves clear of its mesh; camera rays whose mesh hits come
 * from the bins). */
int nc__rt_rocks_attach(struct nc__rt_rocks *r, RTCDevice dev, RTCScene top, RTCScene solo);
/* Rocks spanning mesh_px pixels (of px_rad) or more at their distance from
 * the camera are traced as detailed surfaces (0: none). */
static inline void nc__rt_rocks_mesh_px(struct nc__rt_rocks *r, double mesh_px, double px_rad)
{
    r->px_rad = px_rad;
    r->mesh_k2 = r->surf ? (float)(mesh_px * px_rad * mesh_px * px_rad) : 0.0f;
}
/* Trace only rocks of diameter min_d_m or more (0: all). */
void nc__rt_rocks_cut(struct nc__rt_rocks *r, double min_d_m);
/* The enabled tiles' instances for the body's pose: R body -> scene,
 * origin_rel the body origin relative to the camera (scene frame). */
void nc__rt_rocks_place(struct nc__rt_rocks *r, const struct nc_mat3 *R, struct nc_vec3 origin_rel);
/* The traced rock the camera is inside at the last place (its index in the
 * field's list), or -1. */
long nc__rt_rocks_camera_inside(const struct nc__rt_rocks *r);
void nc__rt_rocks_free(struct nc__rt_rocks *r);

/* rt_rock_mesh.c: each shape's detailed surface (r->surf), built when the
 * rocks' faces are rough; and their release. */
int nc__rt_rock_meshes(RTCDevice dev, struct nc__rt_rocks *r);
void nc__rt_rock_meshes_free(struct nc__rt_rocks *r);
/* The ray o + t d (tile frame) through rock k's detailed surface within
 * [t0, t1], its interval in the rock's planes, widened by 1e-3 of the
 * rock's half size (where the surface lies on a plane, the float rays
 * through the two may part by a few ulps) and kept within (tnear, tfar):
 * whether it meets it, and where (*t) with which shading normal n (rock
 * frame, unnormalised: its corners' normals interpolated, or the
 * triangle's where they would face the ray otherwise); occlusion only if n
 * is NULL. */
int nc__rt_rock_mesh_hit(const struct nc__rt_rocks *r, const struct nc__rt_rock *k, const float o[3],
                         const float d[3], float tnear, float tfar, float t0, float t1, float *t, float *n);

#endif
