/* rt_rocks.c - rocks as Embree user geometry in tiles (rt_rocks.h): a ray
 * in the tile's frame is taken into the rock's own frame (rotation, scale)
 * and clipped by the shape's planes (a convex polyhedron: the entry point
 * is the largest entering plane crossing, if it lies before every exit). */
#include "render/rt_rocks.h"

#include <math.h>
#include <string.h>

static void rock_bounds(const struct RTCBoundsFunctionArguments *a)
{
    const struct nc__rt_rock_tile *tl = a->geometryUserPtr;
    const struct nc__rt_rock *k = &tl->rec[a->primID];
    for (int i = 0; i < 3; i++) {
        double c = k->c[i], e = tl->ext[a->primID][i];
        double pad = 1e-6 * (fabs(c) + e) + 1e-3 * e; /* float rounding and the rotation's */
        (&a->bounds_o->lower_x)[i] = (float)(c - e - pad);
        (&a->bounds_o->upper_x)[i] = (float)(c + e + pad);
    }
}

#define LANES NC__RT_LANES
typedef nc__rt_vlf vlf;
typedef nc__rt_vli vli;

static inline int any_lane(const vli *m)
{
    int x[LANES], a = 0;
    memcpy(x, m, sizeof x);
    for (int i = 0; i < LANES; i++)
        a |= x[i];
    return a;
}

/* m ? a : b, lane by lane */
#define SELECT(m, a, b) ((vlf)(((vli)(a) & (m)) | ((vli)(b) & ~(m))))

/* The entries of the lanes of p into rock k (list index i) within (tnear,
 * tfar): for lane l hit (bit l of the result), t[l] and the entering plane
 * (its index in the shape) plane[l]. None if the rock is below the cut; a
 * lane from inside the rock sees nothing of it (rocks are closed and
 * one-sided). Each lane first meets the sphere through the box's corners
 * (the ray's point nearest the centre, relative to it: no cancellation of
 * two large squares when the origin is kilometres away), then the planes
 * clip it (the box's six first), and the test stops when no lane's
 * interval is left. With mesh set (a rock traced as its detailed surface,
 * which lies within the planes), a lane from inside counts from tnear, and
 * t_out[l] is where the lane leaves. */
__attribute__((target_clones("avx2", "default"))) static unsigned
rock_hit(const struct nc__rt_rocks *r, const struct nc__rt_rock *k, size_t i, const struct nc__rt_lanes *p, int mesh,
         float *t, float *t_out, int *plane)
{
    if (i >= r->traced) /* the list is sorted by size: below the cut */
        return 0;
    const float *M = k->M;
    const struct nc_rock_shape *sh = &r->field->shape[k->shape];
    const vlf rel[3] = {p->o[0] - k->c[0], p->o[1] - k->c[1], p->o[2] - k->c[2]};
    const vlf dd = p->d[0] * p->d[0] + p->d[1] * p->d[1] + p->d[2] * p->d[2];
    const vlf tc = -(rel[0] * p->d[0] + rel[1] * p->d[1] + rel[2] * p->d[2]) / dd;
    const vlf q[3] = {rel[0] + tc * p->d[0], rel[1] + tc * p->d[1], rel[2] + tc * p->d[2]};
    const float m2 = M[0] * M[0] + M[1] * M[1] + M[2] * M[2];
    const float h2 = sh->half[0] * sh->half[0] + sh->half[1] * sh->half[1] + sh->half[2] * sh->half[2];
    vli live = (p->valid == -1) & ~((q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) * m2 > 1.01f * h2);
    if (!any_lane(&live))
        return 0;
    vlf ol[3], dl[3]; /* in the rock's frame: t is unchanged by the scale */
    for (int j = 0; j < 3; j++) {
        ol[j] = M[3 * j] * rel[0] + M[3 * j + 1] * rel[1] + M[3 * j + 2] * rel[2];
        dl[j] = M[3 * j] * p->d[0] + M[3 * j + 1] * p->d[1] + M[3 * j + 2] * p->d[2];
    }
    vlf t0 = p->tnear, t1 = p->tfar;
    vli enter = {0}; /* the plane t0 came from */
    for (int g = 0; g < sh->nplanes; g++) {
        const vlf den = sh->nx[g] * dl[0] + sh->ny[g] * dl[1] + sh->nz[g] * dl[2];
        const vlf num = sh->d[g] - (sh->nx[g] * ol[0] + sh->ny[g] * ol[1] + sh->nz[g] * ol[2]);
        const vlf tg = num / den;
        const vli in = (den < 0) & (tg > t0), out = (den > 0) & (tg < t1);
        live &= ~((den == 0) & (num < 0)); /* parallel, outside */
        t0 = SELECT(in, tg, t0);
        enter = (in & g) | (enter & ~in);
        t1 = SELECT(out, tg, t1);
        if (g % 4 == 3 && (live &= t0 < t1, !any_lane(&live)))
            return 0;
    }
    live &= t0 < t1;
    if (!mesh)
        live &= t0 > p->tnear; /* no plane entered past tnear: the lane starts inside */
    int lv[LANES], en[LANES];
    float tt[LANES], te[LANES];
    memcpy(lv, &live, sizeof lv);
    memcpy(en, &enter, sizeof en);
    memcpy(tt, &t0, sizeof tt);
    memcpy(te, &t1, sizeof te);
    unsigned hit = 0;
    for (int l = 0; l < LANES; l++)
        if (lv[l]) {
            hit |= 1u << l;
            t[l] = tt[l];
            t_out[l] = te[l];
            plane[l] = en[l];
        }
    return hit;
}

unsigned nc__rt_rock_lanes(const struct nc__rt_rock_tile *tl, unsigned prim, const struct nc__rt_lanes *p, float *t,
                           float (*n)[3], int *detailed)
{
    const size_t i = tl->rec[prim].rank;
    const struct nc__rt_rocks *r = tl->rocks;
    const struct nc__rt_rock *k = &tl->rec[prim];
    const struct nc_rock_shape *sh = &r->field->shape[k->shape];
    int mesh = 0;
    if (r->mesh_k2 > 0) { /* (2 half)^2 >= k2 dist^2, half = 1 / |M's row| */
        const float *M = k->M, dx = k->c[0] - tl->cam_m[0], dy = k->c[1] - tl->cam_m[1], dz = k->c[2] - tl->cam_m[2];
        mesh = 4.0f >= r->mesh_k2 * (dx * dx + dy * dy + dz * dz) * (M[0] * M[0] + M[1] * M[1] + M[2] * M[2]);
    }
    float t1[LANES];
    int plane[LANES];
    unsigned lanes = rock_hit(r, k, i, p, mesh, t, t1, plane);
    for (unsigned l = 0; l < LANES && lanes >> l; l++) {
        if (!(lanes >> l & 1))
            continue;
        float nr[3];
        if (mesh) {
            const float o[3] = {p->o[0][l], p->o[1][l], p->o[2][l]}, d[3] = {p->d[0][l], p->d[1][l], p->d[2][l]};
            if (!nc__rt_rock_mesh_hit(r, k, o, d, p->tnear[l], p->tfar[l], t[l], t1[l], &t[l], n ? nr : NULL)) {
                lanes &= ~(1u << l);
                continue;
            }
        } else if (n)
            nr[0] = sh->nx[plane[l]], nr[1] = sh->ny[plane[l]], nr[2] = sh->nz[plane[l]];
        if (!n)
            continue;
        const float *M = k->M; /* R n, up to the scale: the tile's frame */
        for (int j = 0; j < 3; j++)
            n[l][j] = M[j] * nr[0] + M[3 + j] * nr[1] + M[6 + j] * nr[2];
    }
    *detailed = mesh;
    return lanes;
}

/* The rocks' packet callbacks: prim against the valid lanes of ray (width
 * N), LANES at a time; a hit is written through hit (intersection) or,
 * without it, ends the lane (occlusion: tfar = -inf). A rock resolved by
 * enough pixels at its distance from the camera (the same for every ray of
 * a frame: camera, shadow) is traced as its detailed surface, its hits
 * marked by u = 1 (their shading takes only the relief's octaves the
 * geometry does not carry). */
static void rock_packet(const struct nc__rt_rock_tile *tl, unsigned prim, const int *valid, float *ray, unsigned N,
                        const struct RTCIntersectFunctionNArguments *hit)
{
    static const int comp[8] = {0, 1, 2, 3, 4, 5, 6, 8}; /* RTCRayN: org, tnear, dir, time, tfar */
    for (unsigned l0 = 0; l0 < N; l0 += LANES) {
        struct nc__rt_lanes p;
        float *f[8] = {(float *)&p.o[0], (float *)&p.o[1], (float *)&p.o[2], (float *)&p.tnear,
                       (float *)&p.d[0], (float *)&p.d[1], (float *)&p.d[2], (float *)&p.tfar};
        int *v = (int *)&p.valid, any = 0;
        const unsigned m = N - l0 < LANES ? N - l0 : LANES;
        if (m == LANES) { /* fixed sizes: vector moves */
            memcpy(v, valid + l0, LANES * sizeof *v);
            any = any_lane(&p.valid);
        } else {
            memset(&p, 0, sizeof p);
            memcpy(v, valid + l0, m * sizeof *v);
            for (unsigned l = 0; l < m; l++)
                any |= v[l];
        }
        if (!any)
            continue;
        for (int c = 0; c < 8; c++)
            if (m == LANES)
                memcpy(f[c], ray + comp[c] * N + l0, LANES * sizeof *ray);
            else
                memcpy(f[c], ray + comp[c] * N + l0, m * sizeof *ray);
        float t[LANES], n[LANES][3];
        int detailed;
        const unsigned lanes = nc__rt_rock_lanes(tl, prim, &p, t, hit ? n : NULL, &detailed);
        for (unsigned l = 0; l < LANES && lanes >> l; l++) {
            if (!(lanes >> l & 1))
                continue;
            if (!hit) {
                ray[8 * N + l0 + l] = -INFINITY;
                continue;
            }
            nc__rt_user_hit(hit, l0 + l, t[l], n[l]);
            if (detailed)
                ((float *)hit->rayhit)[12 * N + 3 * N + l0 + l] = 1.0f; /* u: a detailed surface's hit */
        }
    }
}

static void rock_intersect(const struct RTCIntersectFunctionNArguments *a)
{
    rock_packet(a->geometryUserPtr, a->primID, a->valid, (float *)a->rayhit, a->N, a);
}

static void rock_occluded(const struct RTCOccludedFunctionNArguments *a)
{
    rock_packet(a->geometryUserPtr, a->primID, a->valid, (float *)a->ray, a->N, NULL);
}

void nc__rt_rock_callbacks(RTCGeometry g)
{
    rtcSetGeometryBoundsFunction(g, rock_bounds, NULL);
    rtcSetGeometryIntersectFunction(g, rock_intersect);
    rtcSetGeometryOccludedFunction(g, rock_occluded);
}
