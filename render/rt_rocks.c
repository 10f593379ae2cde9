/* rt_rocks.c - rocks as Embree user geometry (rt_rocks.h): a ray in the
 * body's anchor frame is taken into the rock's own frame (rotation, scale)
 * and clipped by the shape's planes (a convex polyhedron: the entry point
 * is the largest entering plane crossing, if it lies before every exit). */
#include "render/rt_rocks.h"

#include <math.h>

#include "core/error.h"

struct rock_frame {
    float c[3];    /* centre, anchor-relative */
    float R[3][3]; /* rock -> body */
    float s;       /* half_m */
};

static void frame_of(const struct nc__rt_rocks *r, unsigned i, struct rock_frame *f)
{
    const struct nc_boulder *b = &r->field->rock[i];
    const double *a = &r->anchor_m->x;
    for (int k = 0; k < 3; k++)
        f->c[k] = (float)(b->centre_m[k] - a[k]);
    float w = b->q[0], x = b->q[1], y = b->q[2], z = b->q[3];
    float n = 1 / sqrtf(w * w + x * x + y * y + z * z);
    w *= n, x *= n, y *= n, z *= n;
    f->R[0][0] = 1 - 2 * (y * y + z * z), f->R[0][1] = 2 * (x * y - w * z), f->R[0][2] = 2 * (x * z + w * y);
    f->R[1][0] = 2 * (x * y + w * z), f->R[1][1] = 1 - 2 * (x * x + z * z), f->R[1][2] = 2 * (y * z - w * x);
    f->R[2][0] = 2 * (x * z - w * y), f->R[2][1] = 2 * (y * z + w * x), f->R[2][2] = 1 - 2 * (x * x + y * y);
    f->s = b->half_m;
}

static void rock_bounds(const struct RTCBoundsFunctionArguments *a)
{
    const struct nc__rt_rocks *r = a->geometryUserPtr;
    const struct nc_boulder *b = &r->field->rock[a->primID];
    const float *h = r->field->shape[b->shape].half;
    struct rock_frame f;
    frame_of(r, a->primID, &f);
    for (int k = 0; k < 3; k++) {
        double e = f.s * (fabsf(f.R[k][0]) * h[0] + fabsf(f.R[k][1]) * h[1] + fabsf(f.R[k][2]) * h[2]);
        double c = b->centre_m[k] - (&r->anchor_m->x)[k];
        double pad = 1e-6 * (fabs(c) + f.s) + 1e-3 * e; /* float rounding and the rotation's */
        (&a->bounds_o->lower_x)[k] = (float)(c - e - pad);
        (&a->bounds_o->upper_x)[k] = (float)(c + e + pad);
    }
}

/* The entry of ray (o, d) into rock i within (tnear, tfar): t and the
 * entering plane's normal in the anchor frame; 0 if none (a ray from inside
 * the rock sees nothing of it: rocks are closed and one-sided). */
static int rock_hit(const struct nc__rt_rocks *r, unsigned i, const float o[3], const float d[3], float tnear,
                    float tfar, float *t_out, float n_out[3])
{
    struct rock_frame f;
    frame_of(r, i, &f);
    const struct nc_rock_shape *sh = &r->field->shape[r->field->rock[i].shape];
    float ol[3], dl[3], rel[3] = {o[0] - f.c[0], o[1] - f.c[1], o[2] - f.c[2]};
    for (int k = 0; k < 3; k++) { /* R^T, then / s: t is unchanged */
        ol[k] = (f.R[0][k] * rel[0] + f.R[1][k] * rel[1] + f.R[2][k] * rel[2]) / f.s;
        dl[k] = (f.R[0][k] * d[0] + f.R[1][k] * d[1] + f.R[2][k] * d[2]) / f.s;
    }
    float t0 = -INFINITY, t1 = INFINITY;
    int enter = -1;
    for (int k = 0; k < sh->nplanes; k++) {
        const float *p = sh->plane[k];
        float den = p[0] * dl[0] + p[1] * dl[1] + p[2] * dl[2];
        float num = p[3] - (p[0] * ol[0] + p[1] * ol[1] + p[2] * ol[2]);
        if (den < 0) {
            float t = num / den;
            if (t > t0)
                t0 = t, enter = k;
        } else if (den > 0) {
            float t = num / den;
            if (t < t1)
                t1 = t;
        } else if (num < 0) {
            return 0; /* parallel to a plane, outside it */
        }
        if (t0 > t1)
            return 0;
    }
    if (enter < 0 || !(t0 > tnear) || !(t0 < tfar))
        return 0;
    const float *p = sh->plane[enter];
    for (int k = 0; k < 3; k++)
        n_out[k] = f.R[k][0] * p[0] + f.R[k][1] * p[1] + f.R[k][2] * p[2];
    *t_out = t0;
    return 1;
}

static void rock_intersect(const struct RTCIntersectFunctionNArguments *a)
{
    const struct nc__rt_rocks *r = a->geometryUserPtr;
    const float *ray = (const float *)a->rayhit;
    unsigned N = a->N;
    for (unsigned i = 0; i < N; i++) {
        if (a->valid[i] != -1)
            continue;
        float o[3] = {ray[0 * N + i], ray[1 * N + i], ray[2 * N + i]};
        float d[3] = {ray[4 * N + i], ray[5 * N + i], ray[6 * N + i]};
        float t, n[3];
        if (rock_hit(r, a->primID, o, d, ray[3 * N + i], ray[8 * N + i], &t, n))
            nc__rt_user_hit(a, i, t, n);
    }
}

static void rock_occluded(const struct RTCOccludedFunctionNArguments *a)
{
    const struct nc__rt_rocks *r = a->geometryUserPtr;
    float *ray = (float *)a->ray;
    unsigned N = a->N;
    for (unsigned i = 0; i < N; i++) {
        if (a->valid[i] != -1)
            continue;
        float o[3] = {ray[0 * N + i], ray[1 * N + i], ray[2 * N + i]};
        float d[3] = {ray[4 * N + i], ray[5 * N + i], ray[6 * N + i]};
        float t, n[3];
        if (rock_hit(r, a->primID, o, d, ray[3 * N + i], ray[8 * N + i], &t, n))
            ray[8 * N + i] = -INFINITY;
    }
}

RTCGeometry nc__rt_rocks_geometry(RTCDevice dev, struct nc__rt_rocks *r)
{
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_USER);
    if (!g)
        return NULL;
    rtcSetGeometryUserPrimitiveCount(g, (unsigned)r->field->n);
    rtcSetGeometryUserData(g, r);
    rtcSetGeometryBoundsFunction(g, rock_bounds, NULL);
    rtcSetGeometryIntersectFunction(g, rock_intersect);
    rtcSetGeometryOccludedFunction(g, rock_occluded);
    /* the anchor moves the rocks by pure translation: a refit is exact */
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_REFIT);
    rtcCommitGeometry(g);
    return g;
}
