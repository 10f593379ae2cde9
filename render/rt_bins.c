/* rt_bins.c - camera rays against binned triangles (rt_bins.h).
 *
 * With the rays' origin at 0, ray direction d meets triangle (v0, v1, v2)
 * where the three edge functions w_k = d . e_k, e_0 = v1 x v2, e_1 = v2 x v0,
 * e_2 = v0 x v1, share a sign; w_k over their sum are the barycentric
 * weights. A shared edge has the same e in both triangles up to an exact
 * negation (each e is one double rounding of products exact in double,
 * then one float rounding), so a ray on the edge is inside both or, for
 * either sign of w, inside one: no ray slips between triangles. The range
 * is t = (n . v0) / (n . d), n = (v1 - v0) x (v2 - v0), from the plane, whose
 * error is a few ulps of t (the edge functions of a far triangle carry
 * errors of about float epsilon times its distance, in position on it: as
 * the float vertices themselves). This file is compiled without
 * floating-point contraction: every clone of the test gives the same bits.
 */
#include "render/rt_bins.h"

#include <errno.h>
#include <immintrin.h>
#include <math.h>
#include <stdlib.h>
#include <stdatomic.h>
#include <string.h>

#include "core/error.h"
#include "core/grow.h"
#include "core/pool.h"

/* nc_grow, reported. */
static int grow(void **p, size_t *cap, size_t n, size_t size)
{
    return nc_grow(p, cap, n, size) < 0 ? nc_error(-ENOMEM, "out of memory for %zu camera-ray bin entries", n) : 0;
}

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double len2(const double *a) { return a[0] * a[0] + a[1] * a[1] + a[2] * a[2]; }
static inline double min3(double a, double b, double c) { return a < b ? (a < c ? a : c) : (b < c ? b : c); }
static inline double max3(double a, double b, double c) { return a > b ? (a > c ? a : c) : (b > c ? b : c); }

/* The blocks [lo, hi] whose samples can meet the image interval [x0, x1]
 * (pixels), clamped to [0, n - 1] (lo > hi: none). Block k holds samples
 * in [4k - 1/2, 4k + 3.5]. */
static void block_span(double x0, double x1, double pad, int n, int *lo, int *hi)
{
    const double B = NC_BINS_BLOCK;
    double a = (x0 - (B - 0.5) - pad) / B, b = (x1 + 0.5 + pad) / B;
    a = a < -2 ? -2 : a > n + 2 ? n + 2 : a;
    b = b < -2 ? -2 : b > n + 2 ? n + 2 : b;
    int ia = (int)a, ib = (int)b; /* truncation, then ceil(a), floor(b) */
    ia += ia < a;
    ib -= ib > b;
    *lo = ia < 0 ? 0 : ia;
    *hi = ib > n - 1 ? n - 1 : ib;
}

static size_t part_begin(size_t n, int p, int nparts) { return n * (size_t)p / (size_t)nparts; }

void nc__bins_facets(const double *v, const unsigned *tri, size_t nt, float *ng, struct nc__bins_cluster *out)
{
    for (size_t t0 = 0; t0 < nt; t0 += NC_BINS_CLUSTER) {
        const int m = nt - t0 < NC_BINS_CLUSTER ? (int)(nt - t0) : NC_BINS_CLUSTER;
        struct nc__bins_cluster *o = &out[t0 / NC_BINS_CLUSTER];
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, a[3] = {0, 0, 0};
        double un[NC_BINS_CLUSTER][3], alt = INFINITY, r2 = 0, cmin = 1; /* unit normals; smallest altitude */
        for (int t = 0; t < m; t++) {
            const double *p[3];
            double e[3][3], n[3]; /* v1 - v0, v2 - v0, v2 - v1 */
            for (int k = 0; k < 3; k++)
                p[k] = &v[3 * (size_t)tri[3 * (t0 + t) + k]];
            for (int q = 0; q < 3; q++) {
                e[0][q] = p[1][q] - p[0][q], e[1][q] = p[2][q] - p[0][q], e[2][q] = p[2][q] - p[1][q];
                lo[q] = fmin(lo[q], min3(p[0][q], p[1][q], p[2][q])), hi[q] = fmax(hi[q], max3(p[0][q], p[1][q], p[2][q]));
            }
            cross(e[0], e[1], n);
            const double len = sqrt(len2(n));
            alt = fmin(alt, len > 0 ? len / sqrt(max3(len2(e[0]), len2(e[1]), len2(e[2]))) : 0.0);
            for (int q = 0; q < 3; q++) {
                ng[3 * (t0 + t) + q] = (float)n[q];
                a[q] += un[t][q] = len > 0 ? n[q] / len : 0.0;
            }
        }
        for (int q = 0; q < 3; q++)
            o->c[q] = 0.5 * (lo[q] + hi[q]);
        const double al = sqrt(len2(a));
        for (int t = 0; t < m; t++) {
            for (int k = 0; k < 3; k++) {
                const double *p = &v[3 * (size_t)tri[3 * (t0 + t) + k]];
                const double dx = p[0] - o->c[0], dy = p[1] - o->c[1], dz = p[2] - o->c[2];
                r2 = fmax(r2, dx * dx + dy * dy + dz * dz);
            }
            cmin = fmin(cmin, al > 0 ? (un[t][0] * a[0] + un[t][1] * a[1] + un[t][2] * a[2]) / al : -1.0);
        }
        o->r = sqrt(r2) * (1 + 1e-12);
        /* The cone: the mean direction opened to the widest normal; none if
         * a triangle is degenerate (cluster_live divides by its altitude). */
        const double th = acos(fmax(-1.0, fmin(1.0, cmin))) + 1e-9;
        for (int q = 0; q < 3; q++)
            o->a[q] = al > 0 ? a[q] / al : 0.0;
        o->cos_t = alt > 0 ? cos(th) : -1.0;
        o->sin_t = sin(th);
        o->alt = alt;
    }
}

/* Whether cluster cl of body bd can hold a triangle the build lists: its
 * sphere reaches into the image's planes, and, where only front faces count,
 * some triangle of it may face the origin. A triangle faces away when the
 * origin is on the back of its plane; with the float vertices (rounded by
 * up to 2^-24 relative, at distance L) the build's sign test moves that
 * plane by at most 3 x 2^-24 L^2 / altitude (the triple product
 * det(v0, v1, v2) = 2 area x distance, each vertex's error times the cross
 * product of the other two, at most L x the longest edge): the cone must
 * put the whole sphere further than twice that behind the planes. */
static int cluster_live(const struct nc__bins *b, const struct nc__bins_body *bd, const struct nc__bins_cluster *cl)
{
    const struct nc_vec3 c = nc_v3_add(nc_mat_mul_v(&bd->R, nc_v3(cl->c[0], cl->c[1], cl->c[2])), bd->origin);
    const double L = nc_v3_norm(c);
    for (int k = 0; k < 4; k++)
        if (b->side[k][0] * c.x + b->side[k][1] * c.y + b->side[k][2] * c.z < -(cl->r + 1e-6 * (L + cl->r)))
            return 0;
    if (!bd->front_only || !(cl->cos_t > 0) || !(L > cl->r))
        return 1;
    const struct nc_vec3 a = nc_mat_mul_v(&bd->R, nc_v3(cl->a[0], cl->a[1], cl->a[2]));
    const double cphi = nc_v3_dot(a, c) / L, sphi = sqrt(fmax(0.0, 1.0 - cphi * cphi));
    const double h = L * (cphi * cl->cos_t - sphi * cl->sin_t) - cl->r; /* the planes' least distance in front of the origin */
    return !(h > 6.0 * 0x1p-24 * (L + cl->r) * (L + cl->r) / cl->alt + 1e-3);
}

/* The body holding global index i of a table of offsets. */
static int body_of(const size_t *off, int nbodies, size_t i)
{
    int k = 0;
    while (k + 1 < nbodies && i >= off[k + 1])
        k++;
    return k;
}

/* Part p's vertices: positions from the rays' origin and image points;
 * and its share of the clusters. */
static void vertices(struct nc__bins *b, int p)
{
    const size_t cend = part_begin(b->c_off[b->nbodies], p + 1, b->nparts);
    for (size_t g = part_begin(b->c_off[b->nbodies], p, b->nparts); g < cend; g++) {
        const int k = body_of(b->c_off, b->nbodies, g);
        b->cl_live[g] = !b->body[k].cl || cluster_live(b, &b->body[k], &b->body[k].cl[g - b->c_off[k]]);
    }
    const size_t end = part_begin(b->v_off[b->nbodies], p + 1, b->nparts);
    for (size_t g = part_begin(b->v_off[b->nbodies], p, b->nparts); g < end; g++) {
        const int k = body_of(b->v_off, b->nbodies, g);
        const struct nc__bins_body *bd = &b->body[k];
        const double *v = &bd->v[3 * (g - b->v_off[k])];
        const struct nc_vec3 q = nc_v3_add(nc_mat_mul_v(&bd->R, nc_v3(v[0], v[1], v[2])), bd->origin);
        const float f[3] = {(float)q.x, (float)q.y, (float)q.z};
        double m[3];
        for (int r = 0; r < 3; r++)
            m[r] = b->Mi[r][0] * f[0] + b->Mi[r][1] * f[1] + b->Mi[r][2] * f[2];
        float *o = b->vp[g];
        const double inv = m[2] > 0 ? 1.0 / m[2] : 0.0;
        o[0] = f[0], o[1] = f[1], o[2] = f[2];
        o[3] = (float)(m[0] * inv);
        o[4] = (float)(m[1] * inv);
        o[5] = m[2] > 0 ? 1.0f : -1.0f;
    }
}

/* Part p's triangles: those that can be hit first and show in the image,
 * listed from slot part_begin on, with how many blocks each part fills. */
static void triangles(struct nc__bins *b, int p)
{
    const size_t T = b->t_off[b->nbodies], end = part_begin(T, p + 1, b->nparts);
    size_t slot = part_begin(T, p, b->nparts);
    uint32_t *count = b->count + (size_t)p * b->nblocks;
    memset(count, 0, b->nblocks * sizeof *count);
    for (size_t g = slot; g < end; g++) {
        const int k = body_of(b->t_off, b->nbodies, g);
        const struct nc__bins_body *bd = &b->body[k];
        const size_t t = g - b->t_off[k];
        if (!b->cl_live[b->c_off[k] + t / NC_BINS_CLUSTER]) { /* to the cluster's last triangle */
            const size_t last = b->t_off[k] + (t / NC_BINS_CLUSTER + 1) * NC_BINS_CLUSTER - 1;
            g = last < b->t_off[k + 1] - 1 ? last : b->t_off[k + 1] - 1;
            continue;
        }
        const unsigned *f = &bd->tri[3 * t];
        const float *A = b->vp[b->v_off[k] + f[0]], *B = b->vp[b->v_off[k] + f[1]], *C = b->vp[b->v_off[k] + f[2]];
        const double a[3] = {A[0], A[1], A[2]}, bb[3] = {B[0], B[1], B[2]}, c[3] = {C[0], C[1], C[2]};
        const double ab[3] = {bb[0] - a[0], bb[1] - a[1], bb[2] - a[2]}, ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3];
        cross(ab, ac, n);
        const double nv0 = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
        /* nv0 = 0: the plane holds the origin, every ray grazes it; nv0 > 0:
         * the origin is behind the triangle */
        if (!(nv0 != 0) || (bd->front_only && nv0 > 0))
            continue;
        const int ahead = (A[5] > 0) + (B[5] > 0) + (C[5] > 0);
        if (ahead == 0)
            continue; /* wholly behind the plane through the origin parallel to the image */
        if (ahead < 3) {
            atomic_store(&b->straddle, 1);
            return;
        }
        int x0, x1, y0, y1;
        block_span(min3(A[3], B[3], C[3]), max3(A[3], B[3], C[3]), b->pad_px, b->bw, &x0, &x1);
        block_span(min3(A[4], B[4], C[4]), max3(A[4], B[4], C[4]), b->pad_px, b->bh, &y0, &y1);
        if (x0 > x1 || y0 > y1)
            continue; /* out of the image */
        struct nc__bins_tri *ct = &b->cand[slot];
        double e[3][3];
        cross(bb, c, e[0]);
        cross(c, a, e[1]);
        cross(a, bb, e[2]);
        const double len = sqrt(len2(n));
        for (int r = 0; r < 3; r++) {
            for (int q = 0; q < 3; q++)
                ct->e[r][q] = (float)e[r][q];
            ct->n[r] = (float)(n[r] / len);
        }
        ct->nv0 = (float)(nv0 / len);
        memcpy(ct->ng, &bd->ng[3 * t], sizeof ct->ng);
        b->tri[slot] = (uint32_t)g;
        int16_t *rg = b->range[slot++];
        rg[0] = (int16_t)x0, rg[1] = (int16_t)x1, rg[2] = (int16_t)y0, rg[3] = (int16_t)y1;
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++)
                count[(size_t)y * (size_t)b->bw + (size_t)x]++;
    }
    b->kept[p] = slot - part_begin(T, p, b->nparts);
}

/* Part p's entries into the lists, at its cursors. */
static void fill(struct nc__bins *b, int p)
{
    const size_t first = part_begin(b->t_off[b->nbodies], p, b->nparts), end = first + b->kept[p];
    uint32_t *cur = b->count + (size_t)p * b->nblocks;
    for (size_t slot = first; slot < end; slot++) {
        const int16_t *rg = b->range[slot];
        for (int y = rg[2]; y <= rg[3]; y++)
            for (int x = rg[0]; x <= rg[1]; x++)
                b->list[cur[(size_t)y * (size_t)b->bw + (size_t)x]++] = (uint32_t)slot;
    }
}

enum { PHASE_VERTICES, PHASE_TRIANGLES, PHASE_FILL };

static void *build_worker(void *arg)
{
    struct nc__bins *b = arg;
    for (int p; (p = atomic_fetch_add(&b->next, 1)) < b->nparts;) {
        if (b->phase == PHASE_VERTICES)
            vertices(b, p);
        else if (b->phase == PHASE_TRIANGLES)
            triangles(b, p);
        else
            fill(b, p);
    }
    return NULL;
}

static void run(struct nc__bins *b, struct nc_pool *pool, int phase)
{
    b->phase = phase;
    atomic_store(&b->next, 0);
    nc_pool_run(pool, build_worker, b);
}

int nc__bins_build(struct nc__bins *b, const struct nc__bins_view *view, const struct nc__bins_body *bodies,
                   int nbodies, struct nc_pool *pool, int nparts)
{
    const int bw = (view->width_px + NC_BINS_BLOCK - 1) / NC_BINS_BLOCK,
              bh = (view->height_px + NC_BINS_BLOCK - 1) / NC_BINS_BLOCK;
    if (bw > INT16_MAX || bh > INT16_MAX || nbodies < 1 || nbodies > NC_MAX_BODIES)
        return 0;
    b->bw = bw;
    b->bh = bh;
    b->nblocks = (size_t)bw * (size_t)bh;
    b->nparts = nparts < 1 ? 1 : nparts;
    b->avx512 = __builtin_cpu_supports("avx512f");
    b->nbodies = nbodies;
    /* Image point of a point q: q = s (d00 + x ex + y ey), so (x s, y s, s)
     * = M^-1 q with M's columns ex, ey, d00. */
    const struct nc_vec3 c0 = view->ex, c1 = view->ey, c2 = view->d00;
    const double M[3][3] = {{c0.x, c1.x, c2.x}, {c0.y, c1.y, c2.y}, {c0.z, c1.z, c2.z}};
    const double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                       M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                       M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
    if (!(fabs(det) > 0))
        return nc_error(NC_ERANGE, "camera-ray bins: degenerate image axes");
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, k1 = (r + 1) % 3, k2 = (r + 2) % 3;
            b->Mi[r][c] = (M[r1][k1] * M[r2][k2] - M[r1][k2] * M[r2][k1]) / det;
        }
    /* Padding for the float rays: a float direction is within about 1e-7
     * rad of the exact one; 1e-6 rad in pixels (the finest axis), plus
     * 0.01 pixel for the float image points. */
    const double px_per_rad = fmax(1.0 / nc_v3_norm(view->ex), 1.0 / nc_v3_norm(view->ey));
    b->pad_px = 0.01 + 1e-6 * px_per_rad;
    /* The planes bounding every block's samples (one more pixel each way),
     * normals inwards: no camera ray meets a point behind one. */
    const double xa = -1.5 - b->pad_px, xb = NC_BINS_BLOCK * bw + 0.5 + b->pad_px, ya = xa,
                 yb = NC_BINS_BLOCK * bh + 0.5 + b->pad_px, corner[5][2] = {{xa, ya}, {xb, ya}, {xb, yb}, {xa, yb}, {xa, ya}};
    struct nc_vec3 ray[5], mid = nc_v3(0, 0, 0); /* the corners' rays; inside every plane */
    for (int k = 0; k < 5; k++)
        ray[k] = nc_v3_add(view->d00, nc_v3_add(nc_v3_scale(view->ex, corner[k][0]), nc_v3_scale(view->ey, corner[k][1])));
    for (int k = 0; k < 4; k++)
        mid = nc_v3_add(mid, ray[k]);
    for (int k = 0; k < 4; k++) {
        struct nc_vec3 n = nc_v3_unit(nc_v3_cross(ray[k], ray[k + 1]));
        n = nc_v3_scale(n, nc_v3_dot(n, mid) < 0 ? -1.0 : 1.0);
        b->side[k][0] = n.x, b->side[k][1] = n.y, b->side[k][2] = n.z;
    }
    b->v_off[0] = b->t_off[0] = b->c_off[0] = 0;
    for (int k = 0; k < nbodies; k++) {
        b->body[k] = bodies[k];
        b->v_off[k + 1] = b->v_off[k] + bodies[k].nv;
        b->t_off[k + 1] = b->t_off[k] + bodies[k].nt;
        b->c_off[k + 1] = b->c_off[k] + (bodies[k].nt + NC_BINS_CLUSTER - 1) / NC_BINS_CLUSTER;
    }
    const size_t T = b->t_off[nbodies];
    if (T > UINT32_MAX)
        return 0;
    int rc = 0;
    if ((rc = grow((void **)&b->cand, &b->cand_cap, T, sizeof *b->cand)) < 0 ||
        (rc = grow((void **)&b->tri, &b->tri_cap, T, sizeof *b->tri)) < 0 ||
        (rc = grow((void **)&b->range, &b->range_cap, T, sizeof *b->range)) < 0)
        return rc;
    if ((rc = grow((void **)&b->vp, &b->vp_cap, b->v_off[nbodies], sizeof *b->vp)) < 0 ||
        (rc = grow((void **)&b->kept, &b->kept_cap, (size_t)b->nparts, sizeof *b->kept)) < 0 ||
        (rc = grow((void **)&b->count, &b->count_cap, (size_t)b->nparts * b->nblocks, sizeof *b->count)) < 0 ||
        (rc = grow((void **)&b->start, &b->start_cap, b->nblocks + 1, sizeof *b->start)) < 0 ||
        (rc = grow((void **)&b->cl_live, &b->cl_live_cap, b->c_off[nbodies], sizeof *b->cl_live)) < 0)
        return rc;
    atomic_store(&b->straddle, 0);
    run(b, pool, PHASE_VERTICES);
    run(b, pool, PHASE_TRIANGLES);
    if (atomic_load(&b->straddle))
        return 0;
    /* Block k's entries: part 0's, part 1's, ... each in slot order. The
     * counts become each part's cursors. */
    size_t total = 0;
    for (size_t k = 0; k < b->nblocks; k++) {
        b->start[k] = (uint32_t)total;
        for (int p = 0; p < b->nparts; p++) {
            uint32_t *c = &b->count[(size_t)p * b->nblocks + k];
            const size_t n = *c;
            *c = (uint32_t)total;
            total += n;
        }
        if (total > UINT32_MAX)
            return 0;
    }
    b->start[b->nblocks] = (uint32_t)total;
    if ((rc = grow((void **)&b->list, &b->list_cap, total, sizeof *b->list)) < 0)
        return rc;
    run(b, pool, PHASE_FILL);
    return 1;
}

/* The candidates list[0 .. n) against NC_BINS_GROUP packets of rays from
 * the origin (d: each packet's directions by axis). Lane i of packet q has
 * its closest hit so far at t = bn / bd (bn = -inf: lane off), from
 * candidate bc; a candidate at t = N / D (N, D > 0) is closer when
 * N bd < bn D: no division per test. Ties go to the earlier candidate.
 * Plain C, vectorised by the compiler (AVX2 where the CPU has it). */
__attribute__((target_clones("avx2", "default"))) static void
test_list(const struct nc__bins_tri *restrict cand, const uint32_t *restrict list, uint32_t n,
          const float (*restrict d)[3][NC_PACKET], float (*restrict bn)[NC_PACKET], float (*restrict bd)[NC_PACKET],
          int32_t (*restrict bc)[NC_PACKET])
{
    for (uint32_t k = 0; k < n; k++) {
        const struct nc__bins_tri *c = &cand[list[k]];
        const float a0 = c->e[0][0], a1 = c->e[0][1], a2 = c->e[0][2];
        const float b0 = c->e[1][0], b1 = c->e[1][1], b2 = c->e[1][2];
        const float c0 = c->e[2][0], c1 = c->e[2][1], c2 = c->e[2][2];
        /* the plane's normal turned so that a hit has D = d . n > 0 (exact) */
        const float sg = c->nv0 < 0 ? -1.0f : 1.0f, N = sg * c->nv0;
        const float n0 = sg * c->n[0], n1 = sg * c->n[1], n2 = sg * c->n[2];
        const int32_t id = (int32_t)list[k];
        for (int q = 0; q < NC_BINS_GROUP; q++)
            for (int i = 0; i < NC_PACKET; i++) {
                const float dx = d[q][0][i], dy = d[q][1][i], dz = d[q][2][i];
                const float wa = dx * a0 + dy * a1 + dz * a2;
                const float wb = dx * b0 + dy * b1 + dz * b2;
                const float wc = dx * c0 + dy * c1 + dz * c2;
                const float D = dx * n0 + dy * n1 + dz * n2;
                const int in = ((wa <= 0) & (wb <= 0) & (wc <= 0)) | ((wa >= 0) & (wb >= 0) & (wc >= 0));
                const int ok = in & (D > 0) & (N * bd[q][i] < bn[q][i] * D);
                bn[q][i] = ok ? N : bn[q][i];
                bd[q][i] = ok ? D : bd[q][i];
                bc[q][i] = ok ? id : bc[q][i];
            }
    }
}

/* test_list in AVX-512 registers, the state kept in them: the same
 * operations in the same order, so the same bits. */
__attribute__((target("avx512f"))) static void
test_list_avx512(const struct nc__bins_tri *restrict cand, const uint32_t *restrict list, uint32_t n,
                 const float (*restrict d)[3][NC_PACKET], float (*restrict bn_io)[NC_PACKET],
                 float (*restrict bd_io)[NC_PACKET], int32_t (*restrict bc_io)[NC_PACKET])
{
    __m512 dx[NC_BINS_GROUP], dy[NC_BINS_GROUP], dz[NC_BINS_GROUP], bn[NC_BINS_GROUP], bd[NC_BINS_GROUP];
    __m512i bc[NC_BINS_GROUP];
    for (int q = 0; q < NC_BINS_GROUP; q++) {
        dx[q] = _mm512_loadu_ps(d[q][0]);
        dy[q] = _mm512_loadu_ps(d[q][1]);
        dz[q] = _mm512_loadu_ps(d[q][2]);
        bn[q] = _mm512_loadu_ps(bn_io[q]);
        bd[q] = _mm512_loadu_ps(bd_io[q]);
        bc[q] = _mm512_loadu_si512(bc_io[q]);
    }
    const __m512 zero = _mm512_setzero_ps();
    for (uint32_t k = 0; k < n; k++) {
        if (k + 2 < n) /* candidates are scattered: fetch ahead */
            _mm_prefetch((const char *)&cand[list[k + 2]], _MM_HINT_T0);
        const struct nc__bins_tri *c = &cand[list[k]];
        const __m512 a0 = _mm512_set1_ps(c->e[0][0]), a1 = _mm512_set1_ps(c->e[0][1]), a2 = _mm512_set1_ps(c->e[0][2]);
        const __m512 b0 = _mm512_set1_ps(c->e[1][0]), b1 = _mm512_set1_ps(c->e[1][1]), b2 = _mm512_set1_ps(c->e[1][2]);
        const __m512 c0 = _mm512_set1_ps(c->e[2][0]), c1 = _mm512_set1_ps(c->e[2][1]), c2 = _mm512_set1_ps(c->e[2][2]);
        const float sg = c->nv0 < 0 ? -1.0f : 1.0f;
        const __m512 N = _mm512_set1_ps(sg * c->nv0), n0 = _mm512_set1_ps(sg * c->n[0]),
                     n1 = _mm512_set1_ps(sg * c->n[1]), n2 = _mm512_set1_ps(sg * c->n[2]);
        const __m512i id = _mm512_set1_epi32((int32_t)list[k]);
        for (int q = 0; q < NC_BINS_GROUP; q++) {
#define DOT3(x, y, z) \
    _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx[q], x), _mm512_mul_ps(dy[q], y)), _mm512_mul_ps(dz[q], z))
            const __m512 wa = DOT3(a0, a1, a2), wb = DOT3(b0, b1, b2), wc = DOT3(c0, c1, c2), D = DOT3(n0, n1, n2);
#undef DOT3
            __mmask16 neg = _mm512_cmp_ps_mask(wa, zero, _CMP_LE_OQ);
            neg = _mm512_mask_cmp_ps_mask(neg, wb, zero, _CMP_LE_OQ);
            neg = _mm512_mask_cmp_ps_mask(neg, wc, zero, _CMP_LE_OQ);
            __mmask16 pos = _mm512_cmp_ps_mask(wa, zero, _CMP_GE_OQ);
            pos = _mm512_mask_cmp_ps_mask(pos, wb, zero, _CMP_GE_OQ);
            pos = _mm512_mask_cmp_ps_mask(pos, wc, zero, _CMP_GE_OQ);
            __mmask16 ok = _mm512_mask_cmp_ps_mask(neg | pos, D, zero, _CMP_GT_OQ);
            ok = _mm512_mask_cmp_ps_mask(ok, _mm512_mul_ps(N, bd[q]), _mm512_mul_ps(bn[q], D), _CMP_LT_OQ);
            bn[q] = _mm512_mask_blend_ps(ok, bn[q], N);
            bd[q] = _mm512_mask_blend_ps(ok, bd[q], D);
            bc[q] = _mm512_mask_blend_epi32(ok, bc[q], id);
        }
    }
    for (int q = 0; q < NC_BINS_GROUP; q++) {
        _mm512_storeu_ps(bn_io[q], bn[q]);
        _mm512_storeu_ps(bd_io[q], bd[q]);
        _mm512_storeu_si512(bc_io[q], bc[q]);
    }
}

void nc__bins_intersect(const struct nc__bins *b, int px0, int py0, const struct nc_ray16 *ray, int npk,
                        int32_t (*slot)[NC_PACKET], float (*t)[NC_PACKET])
{
    const size_t k = (size_t)(py0 / NC_BINS_BLOCK) * (size_t)b->bw + (size_t)(px0 / NC_BINS_BLOCK);
    const uint32_t *list = b->list + b->start[k], n = b->start[k + 1] - b->start[k];
    for (int q0 = 0; q0 < npk; q0 += NC_BINS_GROUP) {
        float d[NC_BINS_GROUP][3][NC_PACKET], bn[NC_BINS_GROUP][NC_PACKET], bd[NC_BINS_GROUP][NC_PACKET];
        int32_t bc[NC_BINS_GROUP][NC_PACKET];
        for (int q = 0; q < NC_BINS_GROUP; q++) {
            const struct nc_ray16 *r = q0 + q < npk ? &ray[q0 + q] : NULL;
            for (int i = 0; i < NC_PACKET; i++) {
                d[q][0][i] = r ? r->dx[i] : 0.0f;
                d[q][1][i] = r ? r->dy[i] : 0.0f;
                d[q][2][i] = r ? r->dz[i] : 0.0f;
                bn[q][i] = r && r->valid[i] ? r->tfar[i] : -INFINITY;
                bd[q][i] = 1.0f;
                bc[q][i] = -1;
            }
        }
        if (b->avx512)
            test_list_avx512(b->cand, list, n, d, bn, bd, bc);
        else
            test_list(b->cand, list, n, d, bn, bd, bc);
        for (int q = 0; q < NC_BINS_GROUP && q0 + q < npk; q++)
            for (int i = 0; i < NC_PACKET; i++) {
                slot[q0 + q][i] = bc[q][i];
                t[q0 + q][i] = bc[q][i] >= 0 ? bn[q][i] / bd[q][i] : 0.0f;
            }
    }
}

void nc__bins_uv(const struct nc__bins_tri *c, const float *d, float *u, float *v)
{
    float w[3];
    for (int k = 0; k < 3; k++)
        w[k] = d[0] * c->e[k][0] + d[1] * c->e[k][1] + d[2] * c->e[k][2];
    const float s = w[0] + w[1] + w[2];
    *u = s != 0 ? w[1] / s : 0.0f;
    *v = s != 0 ? w[2] / s : 0.0f;
}

int nc__bins_which(const struct nc__bins *b, int32_t slot, uint32_t *prim)
{
    const size_t g = b->tri[slot];
    if (b->nbodies == 1) {
        *prim = (uint32_t)g;
        return 0;
    }
    const int k = body_of(b->t_off, b->nbodies, g);
    *prim = (uint32_t)(g - b->t_off[k]);
    return k;
}

void nc__bins_free(struct nc__bins *b)
{
    free(b->cand);
    free(b->tri);
    free(b->range);
    free(b->kept);
    free(b->count);
    free(b->start);
    free(b->list);
    free(b->vp);
    free(b->cl_live);
    memset(b, 0, sizeof *b);
}
