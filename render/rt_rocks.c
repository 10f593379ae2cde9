/* rt_rocks.c - rocks as Embree user geometry (rt_rocks.h): a ray in the
 * body's anchor frame is taken into the rock's own frame (rotation, scale)
 * and clipped by the shape's planes (a convex polyhedron: the entry point
 * is the largest entering plane crossing, if it lies before every exit). */
#include "render/rt_rocks.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

static void rock_bounds(const struct RTCBoundsFunctionArguments *a)
{
    const struct nc__rt_rock_octave *oc = a->geometryUserPtr;
    const struct nc__rt_rock *k = &oc->rocks->rock[oc->first + a->primID];
    for (int i = 0; i < 3; i++) {
        double c = k->c[i], e = k->ext[i];
        double pad = 1e-6 * (fabs(c) + e) + 1e-3 * e; /* float rounding and the rotation's */
        (&a->bounds_o->lower_x)[i] = (float)(c - e - pad);
        (&a->bounds_o->upper_x)[i] = (float)(c + e + pad);
    }
}

/* Four planes at a time (GCC/Clang vector extensions: SSE on x86-64, NEON
 * on arm64, plain code elsewhere). */
typedef float v4f __attribute__((vector_size(16)));
typedef int v4i __attribute__((vector_size(16)));

static inline v4f load4(const float *p)
{
    v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}

static inline v4f select4(v4i m, v4f a, v4f b)
{
    return (v4f)(((v4i)a & m) | ((v4i)b & ~m));
}

static inline float hmax4(v4f v)
{
    float x[4];
    memcpy(x, &v, sizeof x);
    float a = x[0] > x[1] ? x[0] : x[1], b = x[2] > x[3] ? x[2] : x[3];
    return a > b ? a : b;
}

static inline float hmin4(v4f v)
{
    float x[4];
    memcpy(x, &v, sizeof x);
    float a = x[0] < x[1] ? x[0] : x[1], b = x[2] < x[3] ? x[2] : x[3];
    return a < b ? a : b;
}

/* The entry of ray (o, d) into rock i within (tnear, tfar): t and the
 * entering plane's normal in the anchor frame; 0 if none (a ray from inside
 * the rock sees nothing of it: rocks are closed and one-sided), or if the
 * rock is below the cut. Planes go four at a time, the box's six first, and
 * the test stops as soon as the ray's interval in the rock is empty. */
static int rock_hit(const struct nc__rt_rocks *r, size_t i, const float o[3], const float d[3], float tnear,
                    float tfar, float *t_out, float n_out[3])
{
    if (i >= r->traced) /* the list is sorted by size: below the cut */
        return 0;
    const struct nc__rt_rock *k = &r->rock[i];
    const float *M = k->M;
    const float rel[3] = {o[0] - k->c[0], o[1] - k->c[1], o[2] - k->c[2]};
    float ol[3], dl[3];
    for (int j = 0; j < 3; j++) { /* t is unchanged by the scale */
        ol[j] = M[3 * j] * rel[0] + M[3 * j + 1] * rel[1] + M[3 * j + 2] * rel[2];
        dl[j] = M[3 * j] * d[0] + M[3 * j + 1] * d[1] + M[3 * j + 2] * d[2];
    }
    const struct nc_rock_shape *sh = &r->field->shape[k->shape];
    const v4f ninf = {-INFINITY, -INFINITY, -INFINITY, -INFINITY}, pinf = -ninf;
    v4f t0 = {tnear, tnear, tnear, tnear}, t1 = {tfar, tfar, tfar, tfar};
    v4f tk[NC_ROCK_PLANES / 4];
    v4i enters[NC_ROCK_PLANES / 4];
    for (int g = 0; g < NC_ROCK_PLANES / 4; g++) {
        v4f nx = load4(sh->nx + 4 * g), ny = load4(sh->ny + 4 * g), nz = load4(sh->nz + 4 * g);
        v4f den = nx * dl[0] + ny * dl[1] + nz * dl[2];
        v4f num = load4(sh->d + 4 * g) - (nx * ol[0] + ny * ol[1] + nz * ol[2]);
        v4f t = num / den;
        v4i in = den < 0, out = den > 0, miss = (den == 0) & (num < 0); /* parallel, outside */
        v4f te = select4(in, t, ninf), tx = select4(out, t, pinf);
        t0 = select4(te > t0, te, t0);
        t1 = select4(tx < t1, tx, t1);
        tk[g] = t;
        enters[g] = in;
        if ((miss[0] | miss[1] | miss[2] | miss[3]) || !(hmax4(t0) < hmin4(t1)))
            return 0;
    }
    const float te = hmax4(t0);
    if (!(te > tnear))
        return 0; /* no plane entered past tnear: the ray starts inside */
    int enter = 0;
    while (!(enters[enter / 4][enter % 4] && tk[enter / 4][enter % 4] == te))
        enter++;
    const float p[3] = {sh->nx[enter], sh->ny[enter], sh->nz[enter]};
    for (int j = 0; j < 3; j++) /* R p, up to the scale */
        n_out[j] = M[j] * p[0] + M[3 + j] * p[1] + M[6 + j] * p[2];
    *t_out = te;
    return 1;
}

/* The rocks' packet callbacks: prim against the valid lanes of ray (width
 * N); a hit is written through hit (intersection) or, without it, ends the
 * lane (occlusion: tfar = -inf). */
static void rock_packet(const struct nc__rt_rock_octave *oc, unsigned prim, const int *valid, float *ray, unsigned N,
                        const struct RTCIntersectFunctionNArguments *hit)
{
    for (unsigned i = 0; i < N; i++) {
        if (valid[i] != -1)
            continue;
        struct nc__rt_lane l = nc__rt_lane(ray, N, i);
        float t, n[3];
        if (!rock_hit(oc->rocks, oc->first + prim, l.o, l.d, l.tnear, l.tfar, &t, n))
            continue;
        if (hit)
            nc__rt_user_hit(hit, i, t, n);
        else
            ray[8 * N + i] = -INFINITY;
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

/* The corners of shape sh (rock units): every point where three of its
 * planes meet inside the others. Returns how many (at most max). */
static int corners(const struct nc_rock_shape *sh, float (*v)[3], int max)
{
    int n = 0, P = sh->nplanes;
    for (int a = 0; a < P; a++)
        for (int b = a + 1; b < P; b++)
            for (int c = b + 1; c < P && n < max; c++) {
                const int id[3] = {a, b, c};
                double m[3][4];
                for (int i = 0; i < 3; i++)
                    m[i][0] = sh->nx[id[i]], m[i][1] = sh->ny[id[i]], m[i][2] = sh->nz[id[i]], m[i][3] = sh->d[id[i]];
                double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                             m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                             m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
                if (fabs(det) < 1e-9)
                    continue;
                double x[3]; /* Cramer's rule */
                for (int k = 0; k < 3; k++) {
                    double q[3][3];
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++)
                            q[i][j] = j == k ? m[i][3] : m[i][j];
                    x[k] = (q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) -
                            q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
                            q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0])) / det;
                }
                int inside = 1;
                for (int k = 0; k < P && inside; k++)
                    inside = sh->nx[k] * x[0] + sh->ny[k] * x[1] + sh->nz[k] * x[2] <= sh->d[k] + 1e-5;
                if (inside) {
                    for (int k = 0; k < 3; k++)
                        v[n][k] = (float)x[k];
                    n++;
                }
            }
    return n;
}

#define MAX_CORNERS 256

/* The traced record of rock b, whose shape has the nv corners v: R^T / s
 * for its rotation q (renormalised, as the generator placed it) and half
 * size s, and its extent along the body axes (the corners turned); the
 * centre comes with the anchor (place). */
static void record(const struct nc_boulder *b, const float (*v)[3], int nv, struct nc__rt_rock *k)
{
    double w = b->q[0], x = b->q[1], y = b->q[2], z = b->q[3];
    double n = sqrt(w * w + x * x + y * y + z * z);
    w /= n, x /= n, y /= n, z /= n;
    const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    memset(k, 0, sizeof *k);
    for (int i = 0; i < 3; i++) {
        double e = 0;
        for (int j = 0; j < nv; j++)
            e = fmax(e, fabs(R[i][0] * v[j][0] + R[i][1] * v[j][1] + R[i][2] * v[j][2]));
        k->ext[i] = (float)(e * b->half_m);
        for (int c = 0; c < 3; c++)
            k->M[3 * i + c] = (float)(R[c][i] / b->half_m);
    }
    k->shape = b->shape;
}

/* Every rock's centre relative to the anchor. */
static void place(struct nc__rt_rocks *r)
{
    const double *a = &r->anchor_m->x;
    for (size_t i = 0; i < r->field->n; i++)
        for (int c = 0; c < 3; c++)
            r->rock[i].c[c] = (float)(r->field->rock[i].centre_m[c] - a[c]);
}

int nc__rt_rocks_init(RTCDevice dev, const struct nc_boulder_field *f, const struct nc_vec3 *anchor_m,
                      struct nc__rt_rocks *r)
{
    memset(r, 0, sizeof *r);
    r->field = f;
    r->anchor_m = anchor_m;
    if (!(r->rock = aligned_alloc(64, (f->n ? f->n : 1) * sizeof *r->rock)))
        return nc_error(-ENOMEM, "out of memory for %zu boulders", f->n);
    float(*v)[3] = malloc((size_t)f->nshapes * MAX_CORNERS * sizeof *v);
    int *nv = malloc((size_t)f->nshapes * sizeof *nv);
    if (!v || !nv) {
        free(v);
        free(nv);
        return nc_error(-ENOMEM, "out of memory");
    }
    for (int i = 0; i < f->nshapes; i++) {
        float(*c)[3] = v + (size_t)i * MAX_CORNERS;
        nv[i] = corners(&f->shape[i], c, MAX_CORNERS);
        if (nv[i] < 4 || nv[i] == MAX_CORNERS) { /* not a proper solid: its box's corners bound it */
            const float *h = f->shape[i].half;
            for (int j = 0; j < 8; j++)
                c[j][0] = j & 1 ? h[0] : -h[0], c[j][1] = j & 2 ? h[1] : -h[1], c[j][2] = j & 4 ? h[2] : -h[2];
            nv[i] = 8;
        }
    }
    for (size_t i = 0; i < f->n; i++)
        record(&f->rock[i], v + (size_t)f->rock[i].shape * MAX_CORNERS, nv[f->rock[i].shape], &r->rock[i]);
    free(v);
    free(nv);
    if (!(r->scene = rtcNewScene(dev)))
        return nc_error(NC_ERENDER, "embree: cannot create a boulder scene");
    /* MEDIUM (one SAH tree, rebuilt when the anchor moves) traces the
     * default scene's million rocks in half the time of LOW (a tree per
     * octave, refitted), and a refit saves only a third of a rebuild
     * (bench/rubble.c; docs/terrain.md). */
    rtcSetSceneBuildQuality(r->scene, RTC_BUILD_QUALITY_MEDIUM);
    for (int k = 0; k < f->noctaves; k++) {
        struct nc__rt_rock_octave *oc = &r->octave[k];
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_USER);
        if (!g)
            return nc_error(NC_ERENDER, "embree: cannot create a boulder geometry");
        *oc = (struct nc__rt_rock_octave){.rocks = r, .first = f->octave[k].first, .geom = g, .enabled = 1};
        r->noctaves = k + 1;
        rtcSetGeometryUserPrimitiveCount(g, (unsigned)f->octave[k].n);
        rtcSetGeometryUserData(g, oc);
        rtcSetGeometryBoundsFunction(g, rock_bounds, NULL);
        rtcSetGeometryIntersectFunction(g, rock_intersect);
        rtcSetGeometryOccludedFunction(g, rock_occluded);
        rtcAttachGeometryByID(r->scene, g, (unsigned)k); /* geomID k: octave k (nc__rt_rock_index) */
    }
    r->traced = f->n;
    r->dirty = 1;
    return 0;
}

void nc__rt_rocks_cut(struct nc__rt_rocks *r, double min_d_m)
{
    if (min_d_m == r->min_d_m)
        return;
    r->min_d_m = min_d_m;
    size_t traced = nc_boulders_at_least(r->field, min_d_m);
    if (traced != r->traced)
        r->cut_cover = nc_boulders_cover(r->field, traced);
    r->traced = traced;
    for (int k = 0; k < r->noctaves; k++) {
        struct nc__rt_rock_octave *oc = &r->octave[k];
        int on = 2.0 * r->field->rock[oc->first].half_m >= min_d_m; /* its largest rock */
        if (on != oc->enabled) {
            (on ? rtcEnableGeometry : rtcDisableGeometry)(oc->geom);
            oc->enabled = on;
            r->dirty = 1;
        }
    }
}

void nc__rt_rocks_commit(struct nc__rt_rocks *r, int moved)
{
    if (moved)
        place(r);
    for (int k = 0; k < r->noctaves; k++)
        if (moved || r->dirty)
            rtcCommitGeometry(r->octave[k].geom);
    if (moved || r->dirty)
        rtcCommitScene(r->scene);
    r->dirty = 0;
}

void nc__rt_rocks_free(struct nc__rt_rocks *r)
{
    for (int k = 0; k < r->noctaves; k++)
        rtcReleaseGeometry(r->octave[k].geom);
    if (r->scene)
        rtcReleaseScene(r->scene);
    free(r->rock);
    memset(r, 0, sizeof *r);
}
