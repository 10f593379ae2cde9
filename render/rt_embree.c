/* rt_embree.c - the Embree 3 back-end: device, per-body scenes, instances,
 * the exact analytic ellipsoid as user geometry, and packet tracing.
 *
 * Every Embree call in NavCam is in this file or the rocks' (rt_rocks.c,
 * rt_rocks_build.c, rt_rock_mesh.c; Embree 4 changes the API).
 * Nothing here knows about reflectance, cameras or images.
 */
#include "render/rt.h"

#include <embree3/rtcore.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/rt_bins.h"
#include "render/rt_rock_bins.h"
#include "render/rt_rocks.h"
#include "render/shadow_grid.h"

/* An ellipsoid's centre and radii in its geometry's frame, m. */
struct ell {
    double centre[3], radii[3];
};

struct rt_body {
    const struct nc_body *src;
    /* One Embree scene per level of detail (mesh_lod.c; analytic shapes and
     * meshes without levels have level 0 only), all sharing one vertex
     * buffer; the instance shows the level picked for the current pose. */
    RTCScene scene[NC_LOD_MAX_LEVELS];
    RTCGeometry geom[NC_LOD_MAX_LEVELS];
    size_t nt[NC_LOD_MAX_LEVELS];
    double error_m[NC_LOD_MAX_LEVELS];
    unsigned fitted[NC_LOD_MAX_LEVELS]; /* the anchor generation each level's tree was fitted to */
    int nlevels, level;
    float *verts; /* anchor-relative vertices of every level, padded for Embree's 16-byte loads */
    float *vnormal; /* smooth shading: unit normals at the vertices, body frame (NULL: flat) */
    const unsigned *tri[NC_LOD_MAX_LEVELS]; /* each level's triangles (Embree's index buffer) */
    float *facet_n[NC_LOD_MAX_LEVELS];      /* each level's facet normals, body frame (nc_rt_bin_camera) */
    struct nc__bins_cluster *cluster[NC_LOD_MAX_LEVELS]; /* and its triangles' clusters */
    unsigned inst_id;
    RTCGeometry inst;
    /* boulders (rt_rocks.h): tiles of their own, each instanced in the
     * top-level scene with the body's rotation */
    struct nc__rt_rocks rocks;
    int analytic;
    /* Shadow-ray culling (shadow_grid.h): which levels are closed outward
     * surfaces, and the grids of the level shown (body frame, body origin),
     * one for hard shadows and one for soft (wider: rays to the whole solar
     * disk), kept both so that frames alternating the two (auto's pilots)
     * do not rebuild them; grid is the one in use. */
    int closed[NC_LOD_MAX_LEVELS];
    struct nc_shadow_grid grids[2], *grid;
    int grid_levels[2], grid_level; /* -1: no valid grid */
    /* The grid's axes u, v, sun in the camera-relative scene frame, and the
     * offsets that give a point's grid coordinates from it: x . axis - off. */
    struct nc_vec3 grid_axis[3];
    double grid_off[3];
    double cull_radius_m; /* the bounding sphere padded for float rays, at the last update */
    struct nc_vec3 anchor_m; /* body frame; geometry is stored relative to it */
    int anchored;
    int refine;                             /* a mesh anchored near the camera: nc_rt_refine_mesh16 */
    double max_edge_m[NC_LOD_MAX_LEVELS];   /* each level's longest edge, m (0: not measured yet) */
    unsigned anchor_gen;
    /* Analytic ellipsoid in anchor-relative coordinates, and the same about
     * the body's origin (ell0: its geometry ell0_geom in scene ell0_scene,
     * what other bodies' far frames hold). */
    struct ell ell, ell0;
    RTCScene ell0_scene;
    RTCGeometry ell0_geom;
    /* Shadow rays leaving this body while the camera is farther than a
     * bounding radius from its bounding sphere (far) are traced relative to
     * its origin (scene axes), where float rays and geometry carry 6e-8 of
     * the body's size rather than of the range: far_top holds every body
     * (far_inst[k]: body k's instance, NULL for this body when it is
     * analytic: a convex shape cannot shadow itself) and every rock tile
     * (far_tile: 2 instances a tile, in far_top and in far_solo, the rocks
     * alone), placed from this body's origin. */
    int far;
    RTCScene far_top, far_solo;
    RTCGeometry far_inst[NC_MAX_BODIES];
    RTCGeometry *far_tile;
    float rot[9]; /* body -> scene, row-major, for normals */
    struct nc_mat3 R;        /* body -> scene, double */
    struct nc_vec3 origin_rel; /* body origin relative to the camera, scene frame, metres */
};

struct nc_rt {
    RTCDevice dev;
    RTCScene top;
    /* Every body's rock tiles alone (NULL: no boulders), and whether any
     * rock is traced at the last update. A shadow ray that a body's grid
     * proves clear of its mesh, and a camera ray whose mesh hit came from
     * the bins, need only test the rocks (rt_rocks.h). */
    RTCScene solo;
    int rocks_on;
    int refine_on; /* some body's refine, at the last update */
    struct rt_body body[NC_MAX_BODIES];
    int nbodies;
    /* Instance ID -> body (the body's own, or a tile of its rocks) and the
     * rock tile it is (NULL for the body's own). */
    unsigned *geom_to_body;
    const struct nc__rt_rock_tile **inst_tile;
    unsigned ninst, inst_cap;
    struct nc_rt_stats stats;
    atomic_ulong shadow_culled, shadow_traced, camera_hits, camera_back_hits;
    struct nc__bins bins; /* camera rays of this pass through bins (nc_rt_bin_camera) */
    /* ... and through the rocks' bins in front of the mesh hits (when
     * rock_binned; else through the rocks' trees) */
    struct nc__rock_bins rock_bins;
    int rock_binned;
    size_t far_ntiles; /* every body's rock tiles (rt_body.far_tile) */
};

static int rt_check(RTCDevice dev, const char *what)
{
    enum RTCError e = rtcGetDeviceError(dev);
    if (e == RTC_ERROR_NONE)
        return 0;
    static const char *const names[] = {"none", "unknown", "invalid argument", "invalid operation",
                                        "out of memory", "unsupported CPU", "cancelled"};
    return nc_error(NC_ERENDER, "embree: %s: %s", what, (unsigned)e < 7 ? names[e] : "error");
}

/* Instance id of the top-level scene -> body index and rock tile. */
static int register_inst(struct nc_rt *rt, unsigned id, int body, const struct nc__rt_rock_tile *tile)
{
    if (id >= rt->inst_cap) {
        unsigned cap = rt->inst_cap ? rt->inst_cap : 16;
        while (cap <= id)
            cap *= 2;
        unsigned *g = realloc(rt->geom_to_body, cap * sizeof *g);
        if (g)
            rt->geom_to_body = g;
        const struct nc__rt_rock_tile **t = realloc(rt->inst_tile, cap * sizeof *t);
        if (t)
            rt->inst_tile = t;
        if (!g || !t)
            return nc_error(-ENOMEM, "out of memory for %u instances", cap);
        memset(rt->inst_tile + rt->inst_cap, 0, (cap - rt->inst_cap) * sizeof *t);
        rt->inst_cap = cap;
    }
    rt->geom_to_body[id] = (unsigned)body;
    rt->inst_tile[id] = tile;
    rt->ninst = id + 1 > rt->ninst ? id + 1 : rt->ninst;
    return 0;
}

/* ---- analytic ellipsoid (user geometry) ---------------------------------- */

/* Lane i of an Embree ray packet of width N (RTCRayN: origin, tnear,
 * direction, time, tfar, ... by component), as a user geometry reads it. */
struct lane {
    float o[3], d[3], tnear, tfar;
};

static inline struct lane lane_of(const float *ray, unsigned N, unsigned i)
{
    return (struct lane){.o = {ray[0 * N + i], ray[1 * N + i], ray[2 * N + i]},
                         .d = {ray[4 * N + i], ray[5 * N + i], ray[6 * N + i]},
                         .tnear = ray[3 * N + i],
                         .tfar = ray[8 * N + i]};
}

static void ell_bounds(const struct RTCBoundsFunctionArguments *a)
{
    const struct ell *b = a->geometryUserPtr;
    /* Pad by a relative 1e-6 so float rounding never clips the shape. */
    for (int k = 0; k < 3; k++) {
        double pad = 1e-6 * (fabs(b->centre[k]) + b->radii[k]);
        (&a->bounds_o->lower_x)[k] = (float)(b->centre[k] - b->radii[k] - pad);
        (&a->bounds_o->upper_x)[k] = (float)(b->centre[k] + b->radii[k] + pad);
    }
}

/* The roots t1, t2 of |op + t dp| = 1 (an ellipsoid scaled to the unit
 * sphere); 0 where the line misses it. The discriminant B^2 - A C is taken
 * as A (1 - |l|^2), l the line's point nearest the centre, and C = |op|^2 -
 * 1 as (|op| - 1)(|op| + 1): B^2 - A C cancels for an origin many radii
 * away (a shadow ray passing 100 radii from a sphere 1e10 radii away met
 * it), |op|^2 - 1 for one at the surface. */
static int ell_roots(const double op[3], const double dp[3], double *t1, double *t2)
{
    const double A = dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2];
    const double B = op[0] * dp[0] + op[1] * dp[1] + op[2] * dp[2];
    if (!(A > 0))
        return 0;
    const double s = B / A, l[3] = {op[0] - s * dp[0], op[1] - s * dp[1], op[2] - s * dp[2]};
    const double ln = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]), disc = A * ((1.0 - ln) * (1.0 + ln));
    if (!(disc >= 0))
        return 0;
    const double on = sqrt(op[0] * op[0] + op[1] * op[1] + op[2] * op[2]), C = (on - 1.0) * (on + 1.0);
    /* Stable roots: q = -(B + sign(B) sqrt(disc)), t = q/A and C/q. */
    const double q = -(B + copysign(sqrt(disc), B));
    *t1 = q / A;
    *t2 = q != 0 ? C / q : *t1;
    return 1;
}

/* Nearest root of |(o + t d - c)/radii| = 1 in (tnear, tfar), or INFINITY. */
static double ell_hit(const struct ell *b, const float o[3], const float d[3], double tnear, double tfar)
{
    double op[3], dp[3], t1, t2;
    for (int k = 0; k < 3; k++) {
        op[k] = ((double)o[k] - b->centre[k]) / b->radii[k];
        dp[k] = (double)d[k] / b->radii[k];
    }
    if (!ell_roots(op, dp, &t1, &t2))
        return INFINITY;
    double lo = fmin(t1, t2), hi = fmax(t1, t2);
    if (lo > tnear && lo < tfar)
        return lo;
    if (hi > tnear && hi < tfar)
        return hi;
    return INFINITY;
}

static void ell_intersect(const struct RTCIntersectFunctionNArguments *a)
{
    const struct ell *b = a->geometryUserPtr;
    const float *ray = (const float *)a->rayhit;
    unsigned N = a->N;
    for (unsigned i = 0; i < N; i++) {
        if (a->valid[i] != -1)
            continue;
        struct lane l = lane_of(ray, N, i);
        double t = ell_hit(b, l.o, l.d, l.tnear, l.tfar);
        if (!(t < INFINITY))
            continue;
        float n[3];
        for (int k = 0; k < 3; k++) {
            double p = (double)l.o[k] + t * (double)l.d[k] - b->centre[k];
            n[k] = (float)(p / (b->radii[k] * b->radii[k]));
        }
        nc__rt_user_hit(a, i, (float)t, n);
    }
}

static void ell_occluded(const struct RTCOccludedFunctionNArguments *a)
{
    const struct ell *b = a->geometryUserPtr;
    float *ray = (float *)a->ray;
    unsigned N = a->N;
    for (unsigned i = 0; i < N; i++) {
        if (a->valid[i] != -1)
            continue;
        struct lane l = lane_of(ray, N, i);
        if (ell_hit(b, l.o, l.d, l.tnear, l.tfar) < INFINITY)
            ray[8 * N + i] = -INFINITY;
    }
}

/* ---- setup ---------------------------------------------------------------- */

/* An ellipsoid's user geometry over e, attached to a new scene *scene. */
static RTCGeometry ell_geometry(RTCDevice dev, struct ell *e, RTCScene *scene)
{
    *scene = rtcNewScene(dev);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, 1);
    rtcSetGeometryUserData(g, e);
    rtcSetGeometryBoundsFunction(g, ell_bounds, NULL);
    rtcSetGeometryIntersectFunction(g, ell_intersect);
    rtcSetGeometryOccludedFunction(g, ell_occluded);
    rtcAttachGeometry(*scene, g);
    return g;
}

/* A mesh level of detail: its triangles over the body's shared vertices. */
static int level_init(struct nc_rt *rt, struct rt_body *b, int k, const struct nc_mesh_lod_level *lv)
{
    const struct nc_mesh *m = &b->src->mesh;
    b->scene[k] = rtcNewScene(rt->dev);
    /* LOW makes Embree honour the per-geometry quality (a two-level index).
     * ROBUST: watertight triangle tests, so that a ray through a shared
     * edge or vertex (a pixel centre right over a DEM's grid line) meets
     * one of the triangles instead of slipping between them. */
    rtcSetSceneBuildQuality(b->scene[k], RTC_BUILD_QUALITY_LOW);
    rtcSetSceneFlags(b->scene[k], RTC_SCENE_FLAG_ROBUST);
    RTCGeometry g = b->geom[k] = rtcNewGeometry(rt->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    /* Anchors move by pure translation: a refit keeps the tree exact. */
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_REFIT);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, b->verts, 0, 3 * sizeof(float), m->nv);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), lv->nt);
    if (!ib)
        return rt_check(rt->dev, "allocating mesh buffers");
    memcpy(ib, lv->tri, lv->nt * 3 * sizeof(unsigned));
    b->tri[k] = ib;
    rtcAttachGeometry(b->scene[k], g);
    b->nt[k] = lv->nt;
    b->error_m[k] = lv->error_m;
    int closed = nc_shadow_grid_closed(m->v, m->nv, lv->tri, lv->nt);
    if (closed < 0)
        return closed;
    b->closed[k] = closed;
    /* The facets' normals and clusters for the camera-ray bins. */
    const size_t ncl = (lv->nt + NC_BINS_CLUSTER - 1) / NC_BINS_CLUSTER;
    if (!(b->facet_n[k] = malloc((3 * lv->nt + 3) * sizeof *b->facet_n[k])) ||
        !(b->cluster[k] = malloc((ncl + 1) * sizeof *b->cluster[k])))
        return nc_error(-ENOMEM, "out of memory for the normals of %zu facets", lv->nt);
    nc__bins_facets(m->v, lv->tri, lv->nt, b->facet_n[k], b->cluster[k]);
    return rt_check(rt->dev, "creating geometry");
}

/* Smooth shading: the mesh's vertex normals, in float (every level of
 * detail keeps a subset of the full mesh's vertices, so one set serves all). */
static int vertex_normals(struct rt_body *b, const struct nc_mesh *m)
{
    double *n = malloc(3 * m->nv * sizeof *n);
    if (!n || !(b->vnormal = malloc(3 * m->nv * sizeof *b->vnormal))) {
        free(n);
        return nc_error(-ENOMEM, "out of memory for %zu vertex normals", m->nv);
    }
    nc_mesh_vertex_normals(m, n);
    for (size_t i = 0; i < 3 * m->nv; i++)
        b->vnormal[i] = (float)n[i];
    free(n);
    return 0;
}

/* Levels of detail only pay where a mesh is much finer than the coarsest
 * level worth having. */
#define LOD_MIN_TRIANGLES 4096

static int body_init(struct nc_rt *rt, unsigned index, const struct nc_body *src, double lod_error_px)
{
    struct rt_body *b = &rt->body[index];
    b->src = src;
    b->grid_level = b->grid_levels[0] = b->grid_levels[1] = -1;
    b->grid = &b->grids[0];
    int rc = 0;
    if (src->shape == NC_SHAPE_SPHERE || src->shape == NC_SHAPE_ELLIPSOID) {
        b->analytic = 1;
        b->ell.radii[0] = b->ell0.radii[0] = src->radii_m.x;
        b->ell.radii[1] = b->ell0.radii[1] = src->radii_m.y;
        b->ell.radii[2] = b->ell0.radii[2] = src->radii_m.z;
        b->geom[0] = ell_geometry(rt->dev, &b->ell, &b->scene[0]);
        b->ell0_geom = ell_geometry(rt->dev, &b->ell0, &b->ell0_scene);
        rtcCommitGeometry(b->ell0_geom);
        rtcCommitScene(b->ell0_scene);
        b->nlevels = 1;
    } else {
        const struct nc_mesh *m = &src->mesh;
        if (!(b->verts = calloc(3 * m->nv + 1, sizeof *b->verts)))
            return nc_error(-ENOMEM, "out of memory for %zu vertices", m->nv);
        struct nc_mesh_lod lod;
        if ((rc = nc_mesh_lod_build(m, lod_error_px > 0 ? LOD_MIN_TRIANGLES : SIZE_MAX, &lod)) < 0)
            return rc;
        for (int k = 0; k < lod.nlevels && rc >= 0; k++) {
            rc = level_init(rt, b, k, &lod.level[k]);
            b->nlevels = k + 1;
        }
        nc_mesh_lod_free(&lod);
        if (rc < 0)
            return rc;
        if (src->smooth_normals && (rc = vertex_normals(b, m)) < 0)
            return rc;
        if (src->boulders.n) { /* the grid proves rays clear of the mesh; the rocks are traced */
            if ((rc = nc__rt_rocks_init(rt->dev, &src->boulders, &b->rocks)) < 0 ||
                (rc = nc__rt_rocks_attach(&b->rocks, rt->dev, rt->top, rt->solo)) < 0)
                return rc;
            for (size_t t = 0; t < b->rocks.ntiles && rc == 0; t++)
                rc = register_inst(rt, b->rocks.tile[t].inst_id, index, &b->rocks.tile[t]);
            if (rc < 0)
                return rc;
        }
    }
    b->inst = rtcNewGeometry(rt->dev, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(b->inst, b->scene[0]);
    b->inst_id = rtcAttachGeometry(rt->top, b->inst);
    if ((rc = register_inst(rt, b->inst_id, index, NULL)) < 0)
        return rc;
    return rt_check(rt->dev, "creating geometry");
}

/* Level k's tree fitted to the current anchor (a refit after a re-anchor;
 * a level not shown is refitted when it is next picked). */
static void fit_level(struct rt_body *b, int k)
{
    if (b->fitted[k] == b->anchor_gen)
        return;
    if (!b->analytic)
        rtcUpdateGeometryBuffer(b->geom[k], RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(b->geom[k]);
    rtcCommitScene(b->scene[k]);
    b->fitted[k] = b->anchor_gen;
}

/* Instance g placed by rotation R and translation T (float), committed. */
static void instance_at(RTCGeometry g, const struct nc_mat3 *R, struct nc_vec3 T)
{
    float xfm[12];
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++)
            xfm[3 * c + r] = (float)R->m[r][c];
    xfm[9] = (float)T.x;
    xfm[10] = (float)T.y;
    xfm[11] = (float)T.z;
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(g);
}

static RTCGeometry new_instance(RTCDevice dev, RTCScene of, RTCScene in)
{
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_INSTANCE);
    if (g) {
        rtcSetGeometryInstancedScene(g, of);
        rtcAttachGeometry(in, g);
    }
    return g;
}

/* Every body's far frame (rt_body.far_top): instances of the other bodies
 * and of every body's rock tiles. */
static int far_init(struct nc_rt *rt)
{
    size_t ntiles = 0;
    for (int k = 0; k < rt->nbodies; k++)
        ntiles += rt->body[k].rocks.ntiles;
    rt->far_ntiles = ntiles;
    for (int f = 0; f < rt->nbodies; f++) {
        struct rt_body *fb = &rt->body[f];
        fb->far_top = rtcNewScene(rt->dev);
        rtcSetSceneBuildQuality(fb->far_top, RTC_BUILD_QUALITY_LOW);
        if (ntiles) {
            fb->far_solo = rtcNewScene(rt->dev);
            rtcSetSceneBuildQuality(fb->far_solo, RTC_BUILD_QUALITY_LOW);
            if (!(fb->far_tile = calloc(2 * ntiles, sizeof *fb->far_tile)))
                return nc_error(-ENOMEM, "out of memory for %zu instances", 2 * ntiles);
        }
        RTCGeometry *tile = fb->far_tile;
        for (int k = 0; k < rt->nbodies; k++) {
            const struct rt_body *b = &rt->body[k];
            if ((k != f || !b->analytic) &&
                !(fb->far_inst[k] = new_instance(rt->dev, b->analytic ? b->ell0_scene : b->scene[0], fb->far_top)))
                return nc_error(NC_ERENDER, "embree: cannot create an instance");
            for (size_t t = 0; t < b->rocks.ntiles; t++, tile += 2)
                if (!(tile[0] = new_instance(rt->dev, b->rocks.tile[t].scene, fb->far_top)) ||
                    !(tile[1] = new_instance(rt->dev, b->rocks.tile[t].scene, fb->far_solo)))
                    return nc_error(NC_ERENDER, "embree: cannot create a boulder tile's instance");
        }
    }
    return rt_check(rt->dev, "creating the far frames");
}

/* Body f's far frame brought to the last update: every body (its level
 * shown) and every rock tile traced, placed from f's origin. */
static void far_place(struct nc_rt *rt, struct rt_body *fb)
{
    RTCGeometry *tile = fb->far_tile;
    for (int k = 0; k < rt->nbodies; k++) {
        const struct rt_body *b = &rt->body[k];
        const struct nc_vec3 rel = nc_v3_sub(b->origin_rel, fb->origin_rel); /* its origin from f's */
        if (fb->far_inst[k]) {
            if (!b->analytic)
                rtcSetGeometryInstancedScene(fb->far_inst[k], b->scene[b->level]);
            instance_at(fb->far_inst[k], &b->R, b->analytic ? rel : nc_v3_add(nc_mat_mul_v(&b->R, b->anchor_m), rel));
        }
        for (size_t t = 0; t < b->rocks.ntiles; t++, tile += 2) {
            const struct nc__rt_rock_tile *tl = &b->rocks.tile[t];
            for (int q = 0; q < 2; q++) {
                (tl->enabled ? rtcEnableGeometry : rtcDisableGeometry)(tile[q]);
                if (tl->enabled)
                    instance_at(tile[q], &b->R,
                                nc_v3_add(nc_mat_mul_v(&b->R, nc_v3(tl->origin_m[0], tl->origin_m[1], tl->origin_m[2])),
                                          rel));
            }
        }
    }
    rtcCommitScene(fb->far_top);
    if (fb->far_solo)
        rtcCommitScene(fb->far_solo);
}

int nc_rt_create(const struct nc_scene *s, int threads, struct nc_rt **out)
{
    struct nc_rt *rt = calloc(1, sizeof *rt);
    if (!rt)
        return nc_error(-ENOMEM, "out of memory");
    /* The rocks' trees (user geometry) with leaves of up to 2 rocks where
     * the builder finds it pays: 18 MB less a million rocks, frames within
     * 1-4 % (docs/terrain.md). NAVCAM_EMBREE: more device options, e.g.
     * isa=avx2 to run Embree's 8-wide kernels on a CPU that has 16-wide
     * ones (tests/CMakeLists.txt); later options override earlier ones. */
    char cfg[256];
    const char *extra = getenv("NAVCAM_EMBREE");
    snprintf(cfg, sizeof cfg, "threads=%d,set_affinity=0,object_accel_max_leaf_size=2%s%.140s",
             threads > 0 ? threads : 0, extra && *extra ? "," : "", extra ? extra : "");
    rt->dev = rtcNewDevice(cfg);
    if (!rt->dev) {
        free(rt);
        return nc_error(NC_ERENDER, "embree: cannot create a device (%s)", cfg);
    }
    rt->top = rtcNewScene(rt->dev);
    rtcSetSceneBuildQuality(rt->top, RTC_BUILD_QUALITY_LOW);
    for (int i = 0; i < s->nbodies && !rt->solo; i++)
        if (s->body[i].boulders.n) {
            rt->solo = rtcNewScene(rt->dev);
            rtcSetSceneBuildQuality(rt->solo, RTC_BUILD_QUALITY_LOW);
        }
    int rc = 0;
    for (int i = 0; i < s->nbodies && rc == 0; i++) {
        rc = body_init(rt, (unsigned)i, &s->body[i], s->render.lod_error_px);
        rt->nbodies = i + 1;
    }
    if (rc == 0)
        rc = far_init(rt);
    if (rc == 0)
        rc = nc_rt_update(rt, s);
    /* Every level's tree now, not when a frame first needs it. */
    for (int i = 0; i < rt->nbodies && rc == 0; i++)
        for (int k = 0; k < rt->body[i].nlevels; k++)
            fit_level(&rt->body[i], k);
    if (rc == 0)
        rc = rt_check(rt->dev, "building the levels of detail");
    if (rc < 0) {
        nc_rt_destroy(rt);
        return rc;
    }
    *out = rt;
    return 0;
}

/* The longest edge of nt triangles tri of mesh m, m. */
static double longest_edge(const struct nc_mesh *m, const unsigned *tri, size_t nt)
{
    double e2 = 0;
    for (size_t k = 0; k < 3 * nt; k++) {
        const double *a = m->v + 3 * (size_t)tri[k], *b = m->v + 3 * (size_t)tri[k % 3 == 2 ? k - 2 : k + 1];
        const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
        e2 = fmax(e2, dx * dx + dy * dy + dz * dz);
    }
    return sqrt(e2);
}

static void reanchor(struct rt_body *b, struct nc_vec3 a)
{
    b->anchor_m = a;
    b->anchored = 1;
    b->anchor_gen++;
    if (b->analytic) {
        b->ell.centre[0] = -a.x;
        b->ell.centre[1] = -a.y;
        b->ell.centre[2] = -a.z;
    } else {
        const struct nc_mesh *m = &b->src->mesh;
        float *vb = b->verts;
        for (size_t i = 0; i < m->nv; i++) {
            vb[3 * i + 0] = (float)(m->v[3 * i + 0] - a.x);
            vb[3 * i + 1] = (float)(m->v[3 * i + 1] - a.y);
            vb[3 * i + 2] = (float)(m->v[3 * i + 2] - a.z);
        }
    }
}

/* Rays within GRID_TOL_RAD of the direction a shadow grid was built for
 * use it; the Sun direction in the body frame is snapped to steps of half
 * that, so a turning body rebuilds its grid only when it has turned by a
 * step (a few tenths of a second for Bennu's 4.3 h rotation), and the grid is a function of
 * the pose, never of the path to it. */
#define GRID_TOL_RAD 2.5e-4

static int build_grid(struct rt_body *b, int slot, int k, struct nc_vec3 sun, double tol_rad, double margin_m)
{
    const unsigned *tri = rtcGetGeometryBufferData(b->geom[k], RTC_BUFFER_TYPE_INDEX, 0);
    int rc = nc_shadow_grid_build(&b->grids[slot], b->src->mesh.v, tri, b->nt[k], sun, tol_rad, nc_v3(0, 0, 0),
                                  b->src->bounding_radius_m, margin_m);
    b->grid_levels[slot] = rc < 0 ? -1 : k;
    return rc;
}

/* The shadow grid of the level shown, for the Sun direction the renderer
 * uses (the direction at bodies[0], or at this body for a Sun at a finite
 * position; rays in other directions are simply not culled). */
static int update_grid(struct rt_body *b, const struct nc_scene *s)
{
    const int k = b->level;
    if (b->analytic || !b->closed[k]) {
        b->grid_level = -1;
        return 0;
    }
    struct nc_vec3 sun;
    double irr;
    nc_scene_sun_at(s, s->sun.has_position ? b->src->position_m : s->body[0].position_m, &sun, &irr);
    sun = nc_mat_tmul_v(&b->R, sun);
    const double q = GRID_TOL_RAD / 2;
    sun = nc_v3_unit(nc_v3(q * round(sun.x / q), q * round(sun.y / q), q * round(sun.z / q)));
    /* The traced geometry's float vertices, instance transform and ray
     * origins are each within about 1e-7 of (anchor distance + radius) of
     * the double mesh; the margin is 1e-6 of it rounded up to a power of
     * two, so that re-anchoring rarely changes it. */
    const double margin = exp2(ceil(log2(1e-6 * (nc_v3_norm(b->anchor_m) + b->src->bounding_radius_m))));
    /* Soft shadows aim anywhere on the solar disk: the grid serves rays
     * within its angular radius more (rounded up to 1e-4 rad, so that a
     * slowly changing distance rarely rebuilds it). */
    const double tol = GRID_TOL_RAD + (s->render.soft_shadows ? 1e-4 * ceil(nc_scene_sun_radius_rad(s) / 1e-4) : 0);
    const int slot = s->render.soft_shadows;
    const struct nc_shadow_grid *g = &b->grids[slot];
    int rc = 0;
    if (b->grid_levels[slot] != k || g->margin_m != margin || g->tol_rad != tol || g->sun.x != sun.x ||
        g->sun.y != sun.y || g->sun.z != sun.z)
        rc = build_grid(b, slot, k, sun, tol, margin);
    b->grid = &b->grids[slot];
    b->grid_level = b->grid_levels[slot];
    /* body coordinates: R^T (x - origin_rel) */
    const struct nc_vec3 ax[3] = {b->grid->u, b->grid->v, b->grid->sun};
    for (int c = 0; c < 3; c++) {
        b->grid_axis[c] = nc_mat_mul_v(&b->R, ax[c]);
        b->grid_off[c] = nc_v3_dot(b->origin_rel, b->grid_axis[c]);
    }
    return rc;
}

int nc_rt_update(struct nc_rt *rt, const struct nc_scene *s)
{
    const struct nc_vec3 cam = s->camera.position_m;
    int rc;
    rt->rocks_on = 0;
    rt->refine_on = 0;
    for (int i = 0; i < NC_MAX_BODIES; i++)
        rt->stats.camera_in_rock[i] = -1;
    for (int i = 0; i < rt->nbodies; i++) {
        struct rt_body *b = &rt->body[i];
        const struct nc_body *src = &s->body[i];
        struct nc_mat3 R = nc_quat_to_mat(src->attitude_q);
        struct nc_vec3 cam_body = nc_mat_tmul_v(&R, nc_v3_sub(cam, src->position_m));
        /* Geometry is stored relative to an anchor a; the float instance
         * translation T = a - camera costs |T| * 6e-8 of position error. For an
         * analytic shape re-anchoring is free, so a is the camera itself. For a
         * mesh (re-anchoring rewrites vertices and refits the BVH), a is the
         * camera position snapped to a power-of-two grid of about 1/8 of the
         * smallest possible range (distance to the bounding sphere): the error
         * stays below 1e-8 of every range (1e-3 px for an IFOV down to 1e-5
         * rad), re-anchors happen only when the camera leaves its cell, and a
         * (hence every pixel) is a function of the pose alone, never of the
         * path taken. Inside the bounding sphere a is the camera itself.
         * Farther than one bounding radius from the sphere, a is the body's
         * origin and never moves: vertices then carry 6e-8 * R <= 6e-8 of
         * every range, T 6e-8 * (dmin + R) <= 1.2e-7 of it (1e-3 px at an
         * IFOV of 1e-4 rad), and the tree is never refitted on approach
         * (a refit costs 40 ms at 327 680 triangles: a latency spike). */
        struct nc_vec3 a = cam_body;
        double dmin = nc_v3_norm(cam_body) - src->bounding_radius_m;
        if (!b->analytic) {
            if (dmin >= src->bounding_radius_m) {
                a = nc_v3(0, 0, 0);
            } else if (dmin > 0) {
                double cell = exp2(floor(log2(dmin / 8)));
                a = nc_v3(cell * floor(cam_body.x / cell + 0.5), cell * floor(cam_body.y / cell + 0.5),
                          cell * floor(cam_body.z / cell + 0.5));
            }
        }
        if (!b->anchored || a.x != b->anchor_m.x || a.y != b->anchor_m.y || a.z != b->anchor_m.z) {
            reanchor(b, a);
            rt->stats.reanchors++;
        }
        /* anchored at the origin, every vertex carries at most 6e-8 R of
         * every range (above); near the camera, an edge's length can exceed
         * the range */
        b->refine = !b->analytic && (a.x != 0 || a.y != 0 || a.z != 0);
        b->far = dmin >= src->bounding_radius_m; /* its shadow rays in its far frame (below, where rocks are) */
        /* Level of detail: the coarsest whose surface error stays within
         * render.lod_error_px pixels at the nearest possible range (the
         * bounding sphere; the finest pixel axis). A function of the pose. */
        int k = 0;
        const double px_m = dmin > 0 ? dmin / fmax(s->camera.fx_px, s->camera.fy_px) : 0;
        if (b->nlevels > 1 && dmin > 0)
            k = nc_mesh_lod_pick_error(b->error_m, b->nlevels, s->render.lod_error_px * px_m);
        fit_level(b, k);
        if (k != b->level) {
            rtcSetGeometryInstancedScene(b->inst, b->scene[k]);
            b->level = k;
        }
        if (!b->analytic && (b->refine || b->far) && b->max_edge_m[k] == 0)
            b->max_edge_m[k] = longest_edge(&b->src->mesh, b->tri[k], b->nt[k]);
        rt->refine_on |= b->refine;
        rt->stats.lod_level[i] = k;
        rt->stats.lod_triangles[i] = b->nt[k];
        rt->stats.lod_error_m[i] = b->error_m[k];
        for (int e = 0; e < 9; e++)
            b->rot[e] = (float)R.m[e / 3][e % 3];
        b->R = R;
        b->origin_rel = nc_v3_sub(src->position_m, cam);
        b->cull_radius_m = src->bounding_radius_m * (1 + 1e-5) + 1e-5 * nc_v3_norm(b->origin_rel);
        instance_at(b->inst, &R, nc_v3_sub(nc_v3_add(nc_mat_mul_v(&R, b->anchor_m), src->position_m), cam));
        if (b->rocks.ntiles) {
            /* Boulders: those spanning render.boulder_min_px pixels at the
             * nearest possible range (every one from inside the bounding
             * sphere), like the level of detail a function of the pose. */
            nc__rt_rocks_cut(&b->rocks, nc_scene_boulder_min_px(s, i) * px_m);
            nc__rt_rocks_place(&b->rocks, &R, b->origin_rel);
            nc__rt_rocks_mesh_px(&b->rocks, s->render.boulder_mesh_px, 1 / fmax(s->camera.fx_px, s->camera.fy_px));
            /* recorded as 0 when the cut leaves no rock out (it lies below
             * the smallest): every rock traced */
            rt->stats.boulder_min_m[i] = b->rocks.traced < src->boulders.n ? b->rocks.min_d_m : 0;
            /* recorded where a rock can have its detailed surface: the
             * largest spans the pixels asked for at the nearest possible range */
            const int can_mesh = b->rocks.mesh_k2 > 0 && b->rocks.traced &&
                                 (dmin <= 0 || 2 * src->boulders.rock[0].half_m >= s->render.boulder_mesh_px * px_m);
            rt->stats.boulder_mesh_px[i] = can_mesh ? s->render.boulder_mesh_px : 0;
            rt->stats.boulders_traced[i] = b->rocks.traced;
            rt->stats.boulder_cut_cover[i] = b->rocks.cut_cover;
            rt->stats.camera_in_rock[i] = nc__rt_rocks_camera_inside(&b->rocks);
            rt->rocks_on |= b->rocks.traced > 0;
            /* The camera's frame places the body and each rock tile by a float translation of its own, and
             * Embree takes a ray into each instance in float: the camera sees the rocks up to about 2.4e-7 of
             * the range off the ground they stand on, where the far frame puts them right. A ground point seen
             * beside a rock can then lie behind it there: a shadow ray along the line of sight (near zero
             * phase) meets it (an outside check at 2e7 m, fx 4e6 px: a black rim around every rock, 12 % of
             * the body). So a body with rocks traced goes in its far frame only while that is under 1 % of a
             * pixel. */
            b->far &= !b->rocks.traced || 2.4e-7 * fmax(s->camera.fx_px, s->camera.fy_px) < 0.01;
        }
        if ((rc = update_grid(b, s)) < 0)
            return rc;
    }
    for (int i = 0; i < rt->nbodies; i++)
        if (rt->body[i].far)
            far_place(rt, &rt->body[i]);
    rtcCommitScene(rt->top);
    if (rt->solo)
        rtcCommitScene(rt->solo);
    return rt_check(rt->dev, "committing the scene");
}

/* ---- tracing -------------------------------------------------------------- */

static void load_ray(struct RTCRay16 *r, const struct nc_ray16 *in)
{
    memcpy(r->org_x, in->ox, sizeof in->ox);
    memcpy(r->org_y, in->oy, sizeof in->oy);
    memcpy(r->org_z, in->oz, sizeof in->oz);
    memcpy(r->dir_x, in->dx, sizeof in->dx);
    memcpy(r->dir_y, in->dy, sizeof in->dy);
    memcpy(r->dir_z, in->dz, sizeof in->dz);
    memcpy(r->tnear, in->tnear, sizeof in->tnear);
    memcpy(r->tfar, in->tfar, sizeof in->tfar);
    for (int i = 0; i < NC_PACKET; i++) {
        r->time[i] = 0;
        r->mask[i] = 0xffffffffu;
        r->id[i] = (unsigned)i;
        r->flags[i] = 0;
        if (in->valid[i] != -1) {
            /* Where the CPU has no 16-wide kernels (no AVX-512), Embree
             * traces a 16-ray packet as a ray stream that ignores the valid
             * mask and skips only rays with tnear > tfar: an inactive lane
             * (left over from a miss, or culled) must be a finite empty ray. */
            r->org_x[i] = r->org_y[i] = r->org_z[i] = 0.0f;
            r->dir_x[i] = r->dir_y[i] = 0.0f;
            r->dir_z[i] = 1.0f;
            r->tnear[i] = 1.0f;
            r->tfar[i] = 0.0f;
        }
    }
}

/* The shading normal of primitive prim of tile tl, hit at t along lane i of ray:
 * its face's normal n (x, y, z: unnormalised, body frame) tilted by the
 * relief's gradient along the face (nc_boulder_relief's octaves from
 * first on), kept only where it faces the ray as n does (a shading normal
 * never shows a face the geometry hides). */
static void rock_relief(const struct rt_body *b, const struct nc__rt_rock_tile *tl, unsigned prim, int first, float t,
                        const struct nc_ray16 *ray, int i, float *x, float *y, float *z)
{
    const float *R = b->rot, *M = tl->rec[prim].M, *c = tl->rec[prim].c;
    const size_t k = tl->rec[prim].rank;
    /* the hit from the tile's origin (scene frame), into the body frame
     * (R^T), from the rock's centre, into the rock's frame (M) */
    const double h[3] = {ray->ox[i] + (double)t * ray->dx[i] - tl->place_m[0],
                         ray->oy[i] + (double)t * ray->dy[i] - tl->place_m[1],
                         ray->oz[i] + (double)t * ray->dz[i] - tl->place_m[2]};
    double rel[3], p[3], g[3], gb[3], n[3] = {*x, *y, *z}, db[3];
    for (int j = 0; j < 3; j++) {
        rel[j] = R[j] * h[0] + R[3 + j] * h[1] + R[6 + j] * h[2] - c[j];
        db[j] = R[j] * ray->dx[i] + R[3 + j] * ray->dy[i] + R[6 + j] * ray->dz[i];
    }
    for (int j = 0; j < 3; j++)
        p[j] = M[3 * j] * rel[0] + M[3 * j + 1] * rel[1] + M[3 * j + 2] * rel[2];
    /* the gradient, with a pixel's footprint at the hit's distance along
     * the ray, turned into the body frame: M^T over its scale */
    const double half = 1 / sqrt((double)M[0] * M[0] + (double)M[1] * M[1] + (double)M[2] * M[2]);
    const double dist = t * sqrt((double)ray->dx[i] * ray->dx[i] + (double)ray->dy[i] * ray->dy[i] +
                                 (double)ray->dz[i] * ray->dz[i]);
    nc_boulder_relief(&b->src->boulders, k, p, dist * tl->rocks->px_rad / half, first, g);
    const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double gn = 0, nd = 0;
    for (int j = 0; j < 3; j++) {
        gb[j] = half * (M[j] * g[0] + M[3 + j] * g[1] + M[6 + j] * g[2]);
        n[j] /= nn;
        gn += gb[j] * n[j];
    }
    for (int j = 0; j < 3; j++) {
        n[j] -= gb[j] - gn * n[j]; /* the height field's normal: n minus the gradient along the face */
        nd += n[j] * db[j];
    }
    if (nd < 0)
        *x = (float)n[0], *y = (float)n[1], *z = (float)n[2];
}

/* Lane i of hit: body bi's ground at ray parameter t, its body-frame
 * normal (x, y, z) turned into the scene frame, albedo factor alb (put_hit
 * then names the rock where one was hit). */
static inline void put_surface(const struct rt_body *b, int bi, float t, float x, float y, float z, float alb,
                               struct nc_hit16 *hit, int i)
{
    const float *R = b->rot;
    hit->albedo[i] = alb;
    hit->rock[i] = -1;
    hit->body[i] = bi;
    hit->t[i] = t;
    hit->fnx[i] = hit->nx[i] = R[0] * x + R[1] * y + R[2] * z;
    hit->fny[i] = hit->ny[i] = R[3] * x + R[4] * y + R[5] * z;
    hit->fnz[i] = hit->nz[i] = R[6] * x + R[7] * y + R[8] * z;
}

/* Lane i of hit: instance inst's primitive prim (a body's own triangle, or a
 * rock of a tile) met at t, barycentric (u, v), geometric normal (x, y, z)
 * unnormalised in the instanced geometry's frame (the body's): a body's own
 * triangle takes its facet normal from the mesh's double vertices instead
 * (Embree's comes from float vertices relative to the ray's origin: its
 * error grows with the range, 2e-3 in a 67P frame's shading at 6000 km in
 * an outside check; the bins' hits had the double one already). */
static void put_hit(const struct nc_rt *rt, unsigned inst, unsigned prim, float t, float u, float v, float x, float y,
                    float z, const struct nc_ray16 *ray, struct nc_hit16 *hit, int i)
{
    const struct rt_body *b = &rt->body[rt->geom_to_body[inst]];
    const float *R = b->rot;
    if (inst == b->inst_id && b->facet_n[b->level]) { /* a mesh's (an analytic body has none) */
        const float *fn = b->facet_n[b->level] + 3 * (size_t)prim;
        x = fn[0], y = fn[1], z = fn[2];
    }
    const float fx = x, fy = y, fz = z; /* the facet's */
    if (b->vnormal && inst == b->inst_id) {
        /* Smooth: the vertex normals at the hit's barycentric point, kept
         * only where they face the ray as the facet does (else the facet's:
         * a shading normal never shows a face the geometry hides). */
        const unsigned *tr = b->tri[b->level] + 3 * (size_t)prim;
        const float *n0 = b->vnormal + 3 * (size_t)tr[0], *n1 = b->vnormal + 3 * (size_t)tr[1],
                    *n2 = b->vnormal + 3 * (size_t)tr[2];
        float w = 1 - u - v;
        float sx = w * n0[0] + u * n1[0] + v * n2[0], sy = w * n0[1] + u * n1[1] + v * n2[1],
              sz = w * n0[2] + u * n1[2] + v * n2[2];
        /* the ray in the body frame: R^T d */
        float dx = R[0] * ray->dx[i] + R[3] * ray->dy[i] + R[6] * ray->dz[i],
              dy = R[1] * ray->dx[i] + R[4] * ray->dy[i] + R[7] * ray->dz[i],
              dz = R[2] * ray->dx[i] + R[5] * ray->dy[i] + R[8] * ray->dz[i];
        float gd = x * dx + y * dy + z * dz, sd = sx * dx + sy * dy + sz * dz;
        if ((gd < 0) == (sd < 0) && sx * x + sy * y + sz * z > 0)
            x = sx, y = sy, z = sz;
    }
    /* Albedo variation: interpolated from the vertices on the ground,
     * one factor per rock. */
    float alb = 1.0f;
    int32_t rock = -1;
    if (inst == b->inst_id && b->src->albedo_vertex) {
        const unsigned *tr = b->tri[b->level] + 3 * (size_t)prim;
        const float *a = b->src->albedo_vertex;
        alb = (1 - u - v) * a[tr[0]] + u * a[tr[1]] + v * a[tr[2]];
    } else if (rt->inst_tile[inst]) {
        const struct nc__rt_rock_tile *tl = rt->inst_tile[inst];
        size_t k = tl->rec[prim].rank;
        alb = nc_albedo_var_rock(&b->src->albedo_var, k);
        rock = (int32_t)k;
        if (b->src->boulders.relief[0] > 0) /* u 1: a detailed surface's hit, the coarse relief in geometry */
            rock_relief(b, tl, prim, u != 0 ? NC_ROCK_MESH_OCTAVES : 0, t, ray, i, &x, &y, &z);
    }
    put_surface(b, (int)rt->geom_to_body[inst], t, x, y, z, alb, hit, i);
    if (b->vnormal && inst == b->inst_id) { /* the facet's normal beside the shading normal */
        hit->fnx[i] = R[0] * fx + R[1] * fy + R[2] * fz;
        hit->fny[i] = R[3] * fx + R[4] * fy + R[5] * fz;
        hit->fnz[i] = R[6] * fx + R[7] * fy + R[8] * fz;
    }
    hit->rock[i] = rock;
    hit->prim[i] = prim;
}

static void put_miss(struct nc_hit16 *hit, int i)
{
    hit->body[i] = -1;
    hit->nx[i] = hit->ny[i] = hit->nz[i] = 0.0f; /* defined for the packet-wide loops */
    hit->fnx[i] = hit->fny[i] = hit->fnz[i] = 0.0f;
}

void nc_rt_intersect16(struct nc_rt *rt, const struct nc_ray16 *ray, struct nc_hit16 *hit, int coherent)
{
    struct RTCRayHit16 rh __attribute__((aligned(64)));
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    load_ray(&rh.ray, ray);
    for (int i = 0; i < NC_PACKET; i++) {
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(ray->valid, rt->top, &ctx, &rh);
    for (int i = 0; i < NC_PACKET; i++) {
        unsigned inst = rh.hit.instID[0][i];
        if (!ray->valid[i] || rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID || inst >= rt->ninst)
            put_miss(hit, i);
        else
            put_hit(rt, inst, rh.hit.primID[i], rh.ray.tfar[i], rh.hit.u[i], rh.hit.v[i], rh.hit.Ng_x[i],
                    rh.hit.Ng_y[i], rh.hit.Ng_z[i], ray, hit, i);
    }
}

int nc_rt_bin_camera(struct nc_rt *rt, const struct nc_rt_pinhole *cam, struct nc_pool *pool, int threads)
{
    rt->rock_binned = rt->stats.camera_bins = 0;
    if (!cam)
        return 0;
    struct nc__bins_body bd[NC_MAX_BODIES];
    /* Samples that can reach the bodies: each bounding sphere's image (a
     * disk of its angular radius), at most the frame. */
    const double frame = (double)cam->width_px * cam->height_px, px_per_rad = 1.0 / nc_v3_norm(cam->ex);
    double samples = 0, triangles = 0;
    for (int i = 0; i < rt->nbodies; i++) {
        const struct rt_body *b = &rt->body[i];
        if (b->analytic)
            return 0;
        const struct nc_vec3 o = nc_v3_sub(b->origin_rel, cam->o);
        const double d = nc_v3_norm(o), R = b->src->bounding_radius_m;
        const double r_px = d > R ? asin(R / d) * px_per_rad : INFINITY;
        samples += fmin(frame, M_PI * r_px * r_px) * cam->samples_per_pixel;
        triangles += (double)b->nt[b->level];
        bd[i] = (struct nc__bins_body){.v = b->src->mesh.v,
                                       .tri = b->tri[b->level],
                                       .ng = b->facet_n[b->level],
                                       .cl = b->cluster[b->level],
                                       .nv = b->src->mesh.nv,
                                       .nt = b->nt[b->level],
                                       .R = b->R,
                                       .origin = o,
                                       .front_only = b->closed[b->level] && nc_v3_norm(o) > b->cull_radius_m};
    }
    if (triangles > samples)
        return 0; /* Embree's tree is cheaper than listing them */
    const struct nc__bins_view v = {cam->d00, cam->ex, cam->ey, cam->width_px, cam->height_px};
    /* Four parts a thread: a thread that loses its core for a while (in
     * serve, the camera model of the frame before runs beside the render)
     * leaves its share of the build to the others. */
    int rc = nc__bins_build(&rt->bins, &v, bd, rt->nbodies, pool, 4 * threads);
    rt->stats.camera_bins = rc > 0;
    if (rc > 0 && rt->rocks_on) {
        struct nc__rock_bins_body rb[NC_MAX_BODIES];
        for (int i = 0; i < rt->nbodies; i++)
            rb[i] = (struct nc__rock_bins_body){rt->body[i].src->boulders.n ? &rt->body[i].rocks : NULL,
                                                rt->body[i].rot};
        /* two parts a thread: each part's counts take 4 bytes a block */
        const int r2 = nc__rock_bins_build(&rt->rock_bins, &rt->bins, cam->o, rb, rt->nbodies, pool, 2 * threads);
        if (r2 < 0)
            return r2;
        rt->rock_binned = r2;
    }
    return rc;
}

int nc_rt_block_listed(const struct nc_rt *rt, int px0, int py0)
{
    const struct nc__bins *b = &rt->bins;
    if (rt->rocks_on && !rt->rock_binned)
        return -1;
    const size_t k = (size_t)(py0 / NC_BINS_BLOCK) * (size_t)b->bw + (size_t)(px0 / NC_BINS_BLOCK);
    return b->start[k + 1] > b->start[k] || (rt->rocks_on && nc__rock_bins_listed(&rt->rock_bins, px0, py0));
}

/* The rocks in front of a packet of camera rays whose meshes the bins
 * traced: each lane through the rocks alone, up to its mesh hit. */
static void rocks_over(struct nc_rt *rt, const struct nc_ray16 *ray, struct nc_hit16 *hit)
{
    struct RTCRayHit16 rh __attribute__((aligned(64)));
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    load_ray(&rh.ray, ray);
    for (int i = 0; i < NC_PACKET; i++) {
        if (ray->valid[i] == -1 && hit->body[i] >= 0)
            rh.ray.tfar[i] = hit->t[i];
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(ray->valid, rt->solo, &ctx, &rh);
    for (int i = 0; i < NC_PACKET; i++) {
        const unsigned inst = rh.hit.instID[0][i];
        if (ray->valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID && inst < rt->ninst)
            put_hit(rt, inst, rh.hit.primID[i], rh.ray.tfar[i], rh.hit.u[i], rh.hit.v[i], rh.hit.Ng_x[i],
                    rh.hit.Ng_y[i], rh.hit.Ng_z[i], ray, hit, i);
    }
}

/* The same for the npk packets of the block at (px0, py0), through the
 * rocks' bins. */
static void rocks_binned(struct nc_rt *rt, int px0, int py0, const struct nc_ray16 *ray, struct nc_hit16 *hit, int npk)
{
    struct nc__rock_bins_hits h;
    for (int q = 0; q < NC_BINS_GROUP; q++) /* (lanes past npk's packets are off) */
        for (int i = 0; i < NC_PACKET; i++)
            h.t[q * NC_PACKET + i] = q >= npk ? 0.0f : hit[q].body[i] >= 0 ? hit[q].t[i] : ray[q].tfar[i];
    nc__rock_bins_intersect(&rt->rock_bins, px0, py0, ray, npk, &h);
    for (int q = 0; q < npk; q++)
        for (int i = 0; i < NC_PACKET; i++) {
            const int k = q * NC_PACKET + i;
            if (h.tile[k] >= 0)
                put_hit(rt, rt->rock_bins.tile[h.tile[k]]->inst_id, h.prim[k], h.t[k], h.detailed[k] ? 1.0f : 0.0f, 0,
                        h.n[k][0], h.n[k][1], h.n[k][2], &ray[q], &hit[q], i);
        }
}

void nc_rt_intersect_block(struct nc_rt *rt, int px0, int py0, const struct nc_ray16 *ray, struct nc_hit16 *hit,
                           int n)
{
    for (int q0 = 0; q0 < n; q0 += NC_BINS_GROUP) {
        const int m = n - q0 < NC_BINS_GROUP ? n - q0 : NC_BINS_GROUP;
        int32_t slot[NC_BINS_GROUP][NC_PACKET];
        float t[NC_BINS_GROUP][NC_PACKET];
        nc__bins_intersect(&rt->bins, px0, py0, ray + q0, m, slot, t);
        for (int q = 0; q < m; q++)
            for (int i = 0; i < NC_PACKET; i++) {
                struct nc_hit16 *h = &hit[q0 + q];
                if (slot[q][i] < 0) {
                    put_miss(h, i);
                    continue;
                }
                const struct nc__bins_tri *ct = &rt->bins.cand[slot[q][i]];
                uint32_t prim = 0; /* put_hit reads it for vertex normals and albedos only */
                const int bi = nc__bins_which(&rt->bins, slot[q][i], NULL);
                const struct rt_body *b = &rt->body[bi];
                if (!b->vnormal && !b->src->albedo_vertex) { /* put_hit's steps for a flat, uniform facet */
                    put_surface(b, bi, t[q][i], ct->ng[0], ct->ng[1], ct->ng[2], 1.0f, h, i);
                    if (b->refine || b->far)
                        nc__bins_which(&rt->bins, slot[q][i], &h->prim[i]);
                    continue;
                }
                float u = 0, v = 0;
                const float d[3] = {ray[q0 + q].dx[i], ray[q0 + q].dy[i], ray[q0 + q].dz[i]};
                nc__bins_uv(ct, d, &u, &v);
                nc__bins_which(&rt->bins, slot[q][i], &prim);
                put_hit(rt, b->inst_id, prim, t[q][i], u, v, ct->ng[0], ct->ng[1], ct->ng[2], &ray[q0 + q], h, i);
            }
        if (rt->rocks_on && rt->rock_binned)
            rocks_binned(rt, px0, py0, ray + q0, hit + q0, m);
        else if (rt->rocks_on)
            for (int q = 0; q < m; q++)
                rocks_over(rt, &ray[q0 + q], &hit[q0 + q]);
    }
}

int nc_rt_refine_on(const struct nc_rt *rt) { return rt->refine_on; }

int nc_rt_far_frame(const struct nc_rt *rt, int b, double *scale_m)
{
    *scale_m = rt->body[b].src->bounding_radius_m;
    return rt->body[b].far;
}

/* nc_rt_refine_far16 on a mesh: each ray met in double precision, in the
 * body frame, by the triangle the float ray met (its double vertices,
 * relative to its first), and taken only where it meets it (the float hit
 * can be on a triangle the exact ray passes by, the body placed 6e-8 of
 * the range off in the camera's frame: refined onto that triangle's plane
 * past a concave edge, a point lay under its neighbour and shadowed itself,
 * found by an outside check at 2e7 m). */
static void refine_far16(const struct rt_body *b, const int *lanes, const uint32_t *prim, const struct nc_vec3 *orig,
                         const struct nc_vec3 *dir, double *t, int *done)
{
    const double edge = b->max_edge_m[b->level], *vs = b->src->mesh.v;
    for (int i = 0; i < NC_PACKET; i++) {
        done[i] = 0;
        if (!lanes[i])
            continue;
        const unsigned *tr = b->tri[b->level] + 3 * (size_t)prim[i];
        const double *v0 = vs + 3 * (size_t)tr[0], *v1 = vs + 3 * (size_t)tr[1], *v2 = vs + 3 * (size_t)tr[2];
        const struct nc_vec3 o = nc_mat_tmul_v(&b->R, nc_v3_sub(orig[i], b->origin_rel)),
                             d = nc_mat_tmul_v(&b->R, dir[i]);
        const struct nc_vec3 e1 = nc_v3(v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]),
                             e2 = nc_v3(v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]),
                             w = nc_v3(o.x - v0[0], o.y - v0[1], o.z - v0[2]);
        const struct nc_vec3 pv = nc_v3_cross(d, e2), q = nc_v3_cross(w, e1);
        const double det = nc_v3_dot(e1, pv);
        if (!(fabs(det) > 0))
            continue;
        const double u = nc_v3_dot(w, pv) / det, v = nc_v3_dot(d, q) / det, tt = nc_v3_dot(e2, q) / det;
        if (u >= 0 && v >= 0 && u + v <= 1 && tt > 0 && fabs(tt - t[i]) <= 1e-4 * t[i] + 1e-3 * edge)
            t[i] = tt, done[i] = 1;
    }
}

void nc_rt_refine_far16(const struct nc_rt *rt, int b, const int *lanes, const uint32_t *prim,
                        const struct nc_vec3 *orig, const struct nc_vec3 *dir, double *t, int *done)
{
    if (!rt->body[b].analytic)
        refine_far16(&rt->body[b], lanes, prim, orig, dir, t, done);
    else
        for (int i = 0; i < NC_PACKET; i++)
            done[i] = lanes[i] != 0;
}

void nc_rt_refine_mesh16(const struct nc_rt *rt, const struct nc_hit16 *hit, const struct nc_vec3 *orig,
                         const struct nc_vec3 *dir, double *t, double *scale)
{
    for (int i = 0; i < NC_PACKET; i++) {
        const int bi = hit->body[i];
        if (bi < 0 || hit->rock[i] >= 0)
            continue;
        const struct rt_body *b = &rt->body[bi];
        const double edge = b->max_edge_m[b->level];
        if (!b->refine || !(t[i] < 64 * edge))
            continue;
        /* body frame: o = R^T (origin - origin_rel), d' = R^T d; the plane
         * through the triangle's double vertices, taken relative to its
         * first vertex (no cancellation between a Moon's radius and a metre) */
        const unsigned *tr = b->tri[b->level] + 3 * (size_t)hit->prim[i];
        const double *v0 = b->src->mesh.v + 3 * (size_t)tr[0], *v1 = b->src->mesh.v + 3 * (size_t)tr[1],
                     *v2 = b->src->mesh.v + 3 * (size_t)tr[2];
        const struct nc_vec3 o = nc_mat_tmul_v(&b->R, nc_v3_sub(orig[i], b->origin_rel)),
                             d = nc_mat_tmul_v(&b->R, dir[i]);
        const struct nc_vec3 e1 = nc_v3(v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]),
                             e2 = nc_v3(v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]),
                             w = nc_v3(v0[0] - o.x, v0[1] - o.y, v0[2] - o.z), n = nc_v3_cross(e1, e2);
        const double nd = nc_v3_dot(n, d), tt = nc_v3_dot(n, w) / nd;
        /* a plane seen edge-on, or a float hit on another triangle than
         * the double ray meets (at an edge): the float answer stands */
        if (!(fabs(tt - t[i]) <= 1e-4 * t[i] + 1e-3 * edge) || !(tt > 0))
            continue;
        t[i] = tt;
        scale[i] = tt + edge;
    }
}

int nc_rt_refine(const struct nc_rt *rt, int body, struct nc_vec3 origin, struct nc_vec3 d, double *t,
                 struct nc_vec3 *n)
{
    const struct rt_body *b = &rt->body[body];
    if (!b->analytic)
        return 0;
    /* Body frame, body origin at zero: o = R^T (origin - origin_rel), d' = R^T d. */
    struct nc_vec3 o = nc_mat_tmul_v(&b->R, nc_v3_sub(origin, b->origin_rel)), db = nc_mat_tmul_v(&b->R, d);
    const double *r = b->ell.radii;
    double op[3] = {o.x / r[0], o.y / r[1], o.z / r[2]}, dp[3] = {db.x / r[0], db.y / r[1], db.z / r[2]}, t1, t2;
    if (!ell_roots(op, dp, &t1, &t2))
        return -1;
    double tt = fmin(t1, t2) > 0 ? fmin(t1, t2) : fmax(t1, t2);
    if (!(tt > 0))
        return -1;
    struct nc_vec3 p = nc_v3_add(o, nc_v3_scale(db, tt));
    *t = tt;
    *n = nc_v3_unit(nc_mat_mul_v(&b->R, nc_v3(p.x / (r[0] * r[0]), p.y / (r[1] * r[1]), p.z / (r[2] * r[2]))));
    return 1;
}

/* Whether ray o + t d (t >= 0) can come within r of c. */
static int ray_near_sphere(struct nc_vec3 o, struct nc_vec3 d, struct nc_vec3 c, double r)
{
    struct nc_vec3 oc = nc_v3_sub(c, o);
    double tc = nc_v3_dot(oc, d), cc = nc_v3_dot(oc, oc);
    return tc <= 0 ? cc <= r * r : cc - tc * tc / nc_v3_dot(d, d) <= r * r;
}

/* The grid's offsets (rt_body.grid_off) for origins in a frame at shift
 * from the camera. */
static void grid_offsets(const struct rt_body *b, struct nc_vec3 shift, double *off)
{
    for (int c = 0; c < 3; c++)
        off[c] = b->grid_off[c] - nc_v3_dot(shift, b->grid_axis[c]);
}

/* Proof that lane i, leaving the outside of body `from`, meets nothing: its
 * own body's shadow grid (a convex analytic shape cannot shadow itself) and
 * every other body's bounding sphere, padded for float rays; the ray's
 * frame is at shift from the camera. dir_ok: the lane's direction suits the
 * body's grid (nc_shadow_grid_dir_ok). */
static int proven_lit(const struct nc_rt *rt, int from, int dir_ok, const struct nc_ray16 *ray, int i,
                      struct nc_vec3 shift)
{
    const struct rt_body *b = &rt->body[from];
    struct nc_vec3 o = nc_v3(ray->ox[i], ray->oy[i], ray->oz[i]), d = nc_v3(ray->dx[i], ray->dy[i], ray->dz[i]);
    if (!b->analytic) {
        if (!dir_ok)
            return 0;
        double off[3];
        grid_offsets(b, shift, off);
        if (!nc_shadow_grid_lit_in(b->grid, b->grid_axis, off, o))
            return 0;
    }
    for (int k = 0; k < rt->nbodies; k++)
        if (k != from && ray_near_sphere(o, d, nc_v3_sub(rt->body[k].origin_rel, shift), rt->body[k].cull_radius_m))
            return 0;
    return 1;
}

/* proven_lit lane by lane: proven[i] = -1 where proven; returns how many. */
static int proven_lanes(const struct nc_rt *rt, const struct nc_ray16 *ray, const int *from, int *proven,
                        struct nc_vec3 shift)
{
    int culled = 0, last = -1, ok = 0; /* the direction test, redone when body or direction changes */
    float ld[3] = {0, 0, 0};
    for (int i = 0; i < NC_PACKET; i++) {
        if (ray->valid[i] && from[i] >= 0) {
            const struct rt_body *b = &rt->body[from[i]];
            if (from[i] != last || ray->dx[i] != ld[0] || ray->dy[i] != ld[1] || ray->dz[i] != ld[2]) {
                last = from[i];
                ld[0] = ray->dx[i];
                ld[1] = ray->dy[i];
                ld[2] = ray->dz[i];
                ok = !b->analytic && b->grid_level == b->level &&
                     nc_shadow_grid_dir_ok(b->grid, nc_mat_tmul_v(&b->R, nc_v3_unit(nc_v3(ld[0], ld[1], ld[2]))));
            }
            if (proven_lit(rt, from[i], ok, ray, i, shift))
                proven[i] = -1, culled++;
        }
    }
    return culled;
}

/* A shadow ray frame's origin from the camera (scene frame, m): -1 the
 * camera's, else that body's far frame. */
static struct nc_vec3 frame_shift(const struct nc_rt *rt, int frame)
{
    return frame < 0 ? nc_v3(0, 0, 0) : rt->body[frame].origin_rel;
}

/* ... and its scene: everything, or with solo the rocks alone. */
static RTCScene frame_scene(const struct nc_rt *rt, int frame, int solo)
{
    if (frame < 0)
        return solo ? rt->solo : rt->top;
    return solo ? rt->body[frame].far_solo : rt->body[frame].far_top;
}

int nc_rt_shadow_cull16(struct nc_rt *rt, struct nc_ray16 *ray, const int *from, int *blocked, int frame)
{
    int culled = 0, proven[NC_PACKET] = {0};
    const struct nc_vec3 shift = frame_shift(rt, frame);
    /* One mesh body and one direction (hard shadows): proven_lit for the
     * whole packet in one grid query. */
    int want[NC_PACKET], f = -1, alike = rt->nbodies == 1;
    for (int i = 0; i < NC_PACKET; i++) {
        want[i] = ray->valid[i] && from[i] >= 0;
        if (want[i] && f < 0)
            f = i;
        else if (want[i])
            alike &= ray->dx[i] == ray->dx[f] && ray->dy[i] == ray->dy[f] && ray->dz[i] == ray->dz[f];
    }
    if (f < 0)
        return 0;
    const struct rt_body *b = &rt->body[from[f]];
    if (alike && !b->analytic) {
        const struct nc_vec3 d = nc_v3(ray->dx[f], ray->dy[f], ray->dz[f]);
        if (b->grid_level == b->level && nc_shadow_grid_dir_ok(b->grid, nc_mat_tmul_v(&b->R, nc_v3_unit(d)))) {
            double off[3];
            grid_offsets(b, shift, off);
            nc_shadow_grid_lit16(b->grid, b->grid_axis, off, ray->ox, ray->oy, ray->oz, want, proven);
        }
        for (int i = 0; i < NC_PACKET; i++)
            culled -= proven[i];
    } else {
        culled = proven_lanes(rt, ray, from, proven, shift);
    }
    if (culled && rt->rocks_on) {
        /* Clear of every mesh, but rocks may stand in the way: the proven
         * rays through the rocks alone. */
        struct RTCRay16 r __attribute__((aligned(64)));
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        struct nc_ray16 pr = *ray;
        memcpy(pr.valid, proven, sizeof proven);
        load_ray(&r, &pr);
        rtcOccluded16(proven, frame_scene(rt, frame, 1), &ctx, &r);
        for (int i = 0; i < NC_PACKET; i++)
            if (proven[i] && r.tfar[i] == -INFINITY)
                blocked[i] = 1, culled--;
    }
    for (int i = 0; i < NC_PACKET; i++)
        if (proven[i])
            ray->valid[i] = 0;
    return culled;
}

void nc_rt_occluded16(struct nc_rt *rt, const struct nc_ray16 *ray, int *occluded, int frame)
{
    int any = 0;
    for (int i = 0; i < NC_PACKET; i++)
        any |= ray->valid[i];
    if (!any) {
        memset(occluded, 0, NC_PACKET * sizeof *occluded);
        return;
    }
    struct RTCRay16 r __attribute__((aligned(64)));
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    load_ray(&r, ray);
    rtcOccluded16(ray->valid, frame_scene(rt, frame, 0), &ctx, &r);
    for (int i = 0; i < NC_PACKET; i++)
        occluded[i] = ray->valid[i] && r.tfar[i] == -INFINITY;
}

void nc_rt_occluded_dirs(struct nc_rt *rt, const struct nc_vec3 *dir, int n, double tfar_m, int *occluded)
{
    struct nc_ray16 ray;
    memset(&ray, 0, sizeof ray);
    for (int i = 0; i < n && i < NC_PACKET; i++) {
        ray.dx[i] = (float)dir[i].x, ray.dy[i] = (float)dir[i].y, ray.dz[i] = (float)dir[i].z;
        ray.tfar[i] = (float)tfar_m;
        ray.valid[i] = -1;
    }
    nc_rt_occluded16(rt, &ray, occluded, -1);
}

void nc_rt_count_shadow_rays(struct nc_rt *rt, unsigned long culled, unsigned long traced)
{
    atomic_fetch_add_explicit(&rt->shadow_culled, culled, memory_order_relaxed);
    atomic_fetch_add_explicit(&rt->shadow_traced, traced, memory_order_relaxed);
}

void nc_rt_count_camera_hits(struct nc_rt *rt, unsigned long hits, unsigned long back_hits)
{
    atomic_fetch_add_explicit(&rt->camera_hits, hits, memory_order_relaxed);
    atomic_fetch_add_explicit(&rt->camera_back_hits, back_hits, memory_order_relaxed);
}

void nc_rt_get_stats(const struct nc_rt *rt, struct nc_rt_stats *st)
{
    *st = rt->stats;
    st->shadow_rays_culled = atomic_load(&rt->shadow_culled);
    st->shadow_rays_traced = atomic_load(&rt->shadow_traced);
    st->camera_hits = atomic_load(&rt->camera_hits);
    st->camera_back_hits = atomic_load(&rt->camera_back_hits);
}

double nc_rt_lod_error_m(const struct nc_rt *rt)
{
    double e = 0;
    for (int i = 0; i < rt->nbodies; i++)
        e = fmax(e, rt->stats.lod_error_m[i]);
    return e;
}

double nc_rt_boulder_min_m(const struct nc_rt *rt)
{
    double d = 0;
    for (int i = 0; i < rt->nbodies; i++)
        d = fmax(d, rt->stats.boulder_min_m[i]);
    return d;
}

double nc_rt_boulder_mesh_px(const struct nc_rt *rt)
{
    double d = 0;
    for (int i = 0; i < rt->nbodies; i++)
        d = fmax(d, rt->stats.boulder_mesh_px[i]);
    return d;
}

size_t nc_rt_rock_mesh_triangles(const struct nc_rt *rt, int b)
{
    return b >= 0 && b < rt->nbodies ? rt->body[b].rocks.mesh_triangles : 0;
}

/* ---- raw batches (benchmarks) --------------------------------------------- */

struct nc_rt_batch {
    struct RTCRayHit16 *tmpl; /* 64-byte aligned templates */
    int (*valid)[NC_PACKET];
    int *frame; /* each packet's (nc_rt_occluded16) */
    size_t n;
    int occlusion;
};

struct batch_job {
    struct nc_rt *rt;
    struct nc_rt_batch *b;
    int single;
    atomic_size_t next;
};

/* Lane k of a packet as a single ray. */
static void lane_trace(RTCScene scene, const struct RTCRayHit16 *p, int k, int occlusion,
                       struct RTCIntersectContext *ctx)
{
    struct RTCRayHit r;
    r.ray.org_x = p->ray.org_x[k];
    r.ray.org_y = p->ray.org_y[k];
    r.ray.org_z = p->ray.org_z[k];
    r.ray.dir_x = p->ray.dir_x[k];
    r.ray.dir_y = p->ray.dir_y[k];
    r.ray.dir_z = p->ray.dir_z[k];
    r.ray.tnear = p->ray.tnear[k];
    r.ray.tfar = p->ray.tfar[k];
    r.ray.time = 0;
    r.ray.mask = 0xffffffffu;
    r.ray.id = (unsigned)k;
    r.ray.flags = 0;
    r.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    r.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    if (occlusion)
        rtcOccluded1(scene, ctx, &r.ray);
    else
        rtcIntersect1(scene, ctx, &r);
}

static void *batch_worker(void *arg)
{
    struct batch_job *j = arg;
    struct nc_rt_batch *b = j->b;
    struct RTCRayHit16 rh __attribute__((aligned(64)));
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    if (!b->occlusion)
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    const size_t chunk = 64;
    for (;;) {
        size_t start = atomic_fetch_add(&j->next, chunk);
        if (start >= b->n)
            break;
        size_t end = start + chunk < b->n ? start + chunk : b->n;
        for (size_t i = start; i < end; i++) {
            RTCScene scene = b->frame[i] < 0 ? j->rt->top : j->rt->body[b->frame[i]].far_top;
            if (j->single) {
                for (int k = 0; k < NC_PACKET; k++)
                    if (b->valid[i][k])
                        lane_trace(scene, &b->tmpl[i], k, b->occlusion, &ctx);
                continue;
            }
            rh = b->tmpl[i];
            if (b->occlusion)
                rtcOccluded16(b->valid[i], scene, &ctx, &rh.ray);
            else
                rtcIntersect16(b->valid[i], scene, &ctx, &rh);
        }
    }
    return NULL;
}

int nc_rt_batch_create(const struct nc_ray16 *rays, const int *frames, size_t n, int occlusion,
                       struct nc_rt_batch **out)
{
    struct nc_rt_batch *b = calloc(1, sizeof *b);
    if (!b || !(b->tmpl = aligned_alloc(64, (n ? n : 1) * sizeof *b->tmpl)) ||
        !(b->valid = aligned_alloc(64, (n ? n : 1) * sizeof *b->valid)) ||
        !(b->frame = malloc((n ? n : 1) * sizeof *b->frame))) {
        nc_rt_batch_destroy(b);
        return nc_error(-ENOMEM, "out of memory for %zu packets", n);
    }
    for (size_t i = 0; i < n; i++)
        b->frame[i] = frames ? frames[i] : -1;
    b->n = n;
    b->occlusion = occlusion;
    for (size_t i = 0; i < n; i++) {
        load_ray(&b->tmpl[i].ray, &rays[i]);
        for (int k = 0; k < NC_PACKET; k++) {
            b->tmpl[i].hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            b->tmpl[i].hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        memcpy(b->valid[i], rays[i].valid, sizeof b->valid[i]);
    }
    *out = b;
    return 0;
}

double nc_rt_batch_trace(struct nc_rt *rt, struct nc_rt_batch *b, int threads, int single)
{
    struct batch_job j = {.rt = rt, .b = b, .single = single};
    atomic_init(&j.next, 0);
    pthread_t tid[64];
    int started = 0;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int i = 1; i < threads && i < 64; i++)
        if (pthread_create(&tid[started], NULL, batch_worker, &j) == 0)
            started++;
    batch_worker(&j);
    for (int i = 0; i < started; i++)
        pthread_join(tid[i], NULL);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    return (t1.tv_sec - t0.tv_sec) * 1e3 + (t1.tv_nsec - t0.tv_nsec) * 1e-6;
}

void nc_rt_batch_destroy(struct nc_rt_batch *b)
{
    if (!b)
        return;
    free(b->tmpl);
    free(b->valid);
    free(b->frame);
    free(b);
}

void nc_rt_destroy(struct nc_rt *rt)
{
    if (!rt)
        return;
    for (int i = 0; i < rt->nbodies; i++) {
        struct rt_body *b = &rt->body[i];
        if (b->inst)
            rtcReleaseGeometry(b->inst);
        for (int k = 0; k < rt->nbodies; k++)
            if (b->far_inst[k])
                rtcReleaseGeometry(b->far_inst[k]);
        for (size_t k = 0; b->far_tile && k < 2 * rt->far_ntiles; k++)
            if (b->far_tile[k])
                rtcReleaseGeometry(b->far_tile[k]);
        free(b->far_tile);
        if (b->far_top)
            rtcReleaseScene(b->far_top);
        if (b->far_solo)
            rtcReleaseScene(b->far_solo);
        if (b->ell0_geom)
            rtcReleaseGeometry(b->ell0_geom);
        if (b->ell0_scene)
            rtcReleaseScene(b->ell0_scene);
        nc__rt_rocks_free(&b->rocks);
        for (int k = 0; k < NC_LOD_MAX_LEVELS; k++) {
            if (b->geom[k])
                rtcReleaseGeometry(b->geom[k]);
            if (b->scene[k])
                rtcReleaseScene(b->scene[k]);
        }
    }
    if (rt->top)
        rtcReleaseScene(rt->top);
    if (rt->solo)
        rtcReleaseScene(rt->solo);
    if (rt->dev)
        rtcReleaseDevice(rt->dev);
    nc__bins_free(&rt->bins);
    nc__rock_bins_free(&rt->rock_bins);
    for (int i = 0; i < rt->nbodies; i++) {
        free(rt->body[i].verts);
        free(rt->body[i].vnormal);
        for (int k = 0; k < NC_LOD_MAX_LEVELS; k++) {
            free(rt->body[i].facet_n[k]);
            free(rt->body[i].cluster[k]);
        }
        for (int g = 0; g < 2; g++)
            nc_shadow_grid_free(&rt->body[i].grids[g]);
    }
    free(rt->geom_to_body);
    free(rt->inst_tile);
    free(rt);
}
