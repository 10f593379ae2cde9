/* rt_bins_build.c - the camera-ray bins' lists (rt_bins.h): per pass, each
 * triangle that can be a ray's first hit, with the numbers of its exact
 * test, listed in the 4x4-pixel blocks its image can meet. Built in parts
 * on the render threads, in triangle order whatever their number. Compiled
 * without floating-point contraction, like rt_bins.c: the AVX-512 and plain
 * setups give the same bits. */
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

/* Vertices [a, e) of body bd into vp (rows of 6): each position from the
 * rays' origin in float, its image point and depth sign. One branch-free
 * loop the compiler vectorises (this file is compiled without contraction:
 * every clone gives the same bits). */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void
project(const struct nc__bins *b, const struct nc__bins_body *bd, size_t a, size_t e, float (*restrict vp)[6])
{
    const double(*R)[3] = bd->R.m, (*Mi)[3] = b->Mi, ox = bd->origin.x, oy = bd->origin.y, oz = bd->origin.z;
    const double *restrict v = bd->v;
    for (size_t i = a; i < e; i++) {
        const double x = v[3 * i], y = v[3 * i + 1], z = v[3 * i + 2];
        const float f0 = (float)(R[0][0] * x + R[0][1] * y + R[0][2] * z + ox),
                    f1 = (float)(R[1][0] * x + R[1][1] * y + R[1][2] * z + oy),
                    f2 = (float)(R[2][0] * x + R[2][1] * y + R[2][2] * z + oz);
        const double m0 = Mi[0][0] * f0 + Mi[0][1] * f1 + Mi[0][2] * f2,
                     m1 = Mi[1][0] * f0 + Mi[1][1] * f1 + Mi[1][2] * f2,
                     m2 = Mi[2][0] * f0 + Mi[2][1] * f1 + Mi[2][2] * f2;
        const double inv = m2 > 0 ? 1.0 / m2 : 0.0;
        float *o = vp[i - a];
        o[0] = f0, o[1] = f1, o[2] = f2;
        o[3] = (float)(m0 * inv);
        o[4] = (float)(m1 * inv);
        o[5] = m2 > 0 ? 1.0f : -1.0f;
    }
}

/* Part p's vertices (project) and its share of the clusters. */
static void vertices(struct nc__bins *b, int p)
{
    const size_t cend = part_begin(b->c_off[b->nbodies], p + 1, b->nparts);
    for (size_t g = part_begin(b->c_off[b->nbodies], p, b->nparts); g < cend; g++) {
        const int k = nc__bins_body_of(b->c_off, b->nbodies, g);
        b->cl_live[g] = !b->body[k].cl || cluster_live(b, &b->body[k], &b->body[k].cl[g - b->c_off[k]]);
    }
    const size_t end = part_begin(b->v_off[b->nbodies], p + 1, b->nparts);
    for (size_t g = part_begin(b->v_off[b->nbodies], p, b->nparts); g < end;) {
        const int k = nc__bins_body_of(b->v_off, b->nbodies, g);
        const size_t e = end < b->v_off[k + 1] ? end : b->v_off[k + 1]; /* the rest of the part in this body */
        project(b, &b->body[k], g - b->v_off[k], e - b->v_off[k], &b->vp[g]);
        g = e;
    }
}

/* What the build keeps of a triangle it lists: the blocks its image can
 * meet (x0..x1, y0..y1) and its test's numbers (nc__bins_tri). */
struct setup {
    int x0, x1, y0, y1;
    float e[3][3], n[3], nv0;
};

enum { SKIP = 0, KEEP = 1, STRADDLE = -1 };

/* Triangle (A, B, C) (rows of vp): KEEP, with o filled, if it can be hit
 * first and shows in the image; SKIP; STRADDLE if it crosses the plane
 * through the origin parallel to the image. */
static int setup1(const struct nc__bins *b, int front_only, const float *A, const float *B, const float *C,
                  struct setup *o)
{
    const double a[3] = {A[0], A[1], A[2]}, bb[3] = {B[0], B[1], B[2]}, c[3] = {C[0], C[1], C[2]};
    const double ab[3] = {bb[0] - a[0], bb[1] - a[1], bb[2] - a[2]}, ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3];
    cross(ab, ac, n);
    const double nv0 = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
    /* nv0 = 0: the plane holds the origin, every ray grazes it; nv0 > 0:
     * the origin is behind the triangle */
    if (!(nv0 != 0) || (front_only && nv0 > 0))
        return SKIP;
    const int ahead = (A[5] > 0) + (B[5] > 0) + (C[5] > 0);
    if (ahead == 0)
        return SKIP; /* wholly behind the plane through the origin parallel to the image */
    if (ahead < 3)
        return STRADDLE;
    block_span(min3(A[3], B[3], C[3]), max3(A[3], B[3], C[3]), b->pad_px, b->bw, &o->x0, &o->x1);
    block_span(min3(A[4], B[4], C[4]), max3(A[4], B[4], C[4]), b->pad_px, b->bh, &o->y0, &o->y1);
    if (o->x0 > o->x1 || o->y0 > o->y1)
        return SKIP; /* out of the image */
    double e[3][3];
    cross(bb, c, e[0]);
    cross(c, a, e[1]);
    cross(a, bb, e[2]);
    const double len = sqrt(len2(n));
    for (int r = 0; r < 3; r++) {
        for (int q = 0; q < 3; q++)
            o->e[r][q] = (float)e[r][q];
        o->n[r] = (float)(n[r] / len);
    }
    o->nv0 = (float)(nv0 / len);
    return KEEP;
}

/* setup1 for the 8 triangles tri[0 .. 24) of vertices vp, in AVX-512
 * registers: the same operations in the same order, so the same bits.
 * Returns the mask of those kept; *straddle set if one straddles. */
__attribute__((target("avx512f,avx512vl"))) static unsigned setup8_avx512(const struct nc__bins *b, int front_only,
                                                                 const unsigned *tri, const float (*vp)[6],
                                                                 struct setup *o, int *straddle)
{
    typedef __m512d V;
    const __m256i three = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    V p[3][6]; /* vertex k's component q, per lane */
    for (int k = 0; k < 3; k++) {
        const __m256i row = _mm256_mullo_epi32(_mm256_i32gather_epi32((const int *)tri + k, three, 4),
                                               _mm256_set1_epi32(6));
        for (int q = 0; q < 6; q++)
            p[k][q] = _mm512_cvtps_pd(_mm256_i32gather_ps(&vp[0][q], row, 4));
    }
#define SUB(x, y) _mm512_sub_pd(x, y)
#define MUL(x, y) _mm512_mul_pd(x, y)
#define CROSS(u, v, w)                                              \
    do {                                                            \
        w[0] = SUB(MUL(u[1], v[2]), MUL(u[2], v[1]));               \
        w[1] = SUB(MUL(u[2], v[0]), MUL(u[0], v[2]));               \
        w[2] = SUB(MUL(u[0], v[1]), MUL(u[1], v[0]));               \
    } while (0)
    const V *a = p[0], *bb = p[1], *c = p[2];
    const V ab[3] = {SUB(bb[0], a[0]), SUB(bb[1], a[1]), SUB(bb[2], a[2])},
            ac[3] = {SUB(c[0], a[0]), SUB(c[1], a[1]), SUB(c[2], a[2])};
    V n[3];
    CROSS(ab, ac, n);
    const V zero = _mm512_setzero_pd(),
            nv0 = _mm512_add_pd(_mm512_add_pd(MUL(n[0], a[0]), MUL(n[1], a[1])), MUL(n[2], a[2]));
    __mmask8 keep = _mm512_cmp_pd_mask(nv0, zero, _CMP_NEQ_UQ);
    if (front_only)
        keep &= (__mmask8)~_mm512_cmp_pd_mask(nv0, zero, _CMP_GT_OQ);
    const __mmask8 fa = _mm512_cmp_pd_mask(a[5], zero, _CMP_GT_OQ), fb = _mm512_cmp_pd_mask(bb[5], zero, _CMP_GT_OQ),
                   fc = _mm512_cmp_pd_mask(c[5], zero, _CMP_GT_OQ);
    if (keep & (fa | fb | fc) & (__mmask8) ~(fa & fb & fc))
        *straddle = 1;
    keep &= fa & fb & fc;
    /* block_span over x (q = 3) and y (q = 4) */
    int lo[2][8], hi[2][8];
    for (int ax = 0; ax < 2; ax++) {
        const int q = 3 + ax, nb = ax ? b->bh : b->bw;
        const V pad = _mm512_set1_pd(b->pad_px), m2 = _mm512_set1_pd(-2.0), mn = _mm512_set1_pd(nb + 2);
        V mn3 = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(a[q], bb[q], _CMP_LT_OQ), bb[q], a[q]);
        mn3 = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(mn3, c[q], _CMP_LT_OQ), c[q], mn3);
        V mx3 = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(a[q], bb[q], _CMP_GT_OQ), bb[q], a[q]);
        mx3 = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(mx3, c[q], _CMP_GT_OQ), c[q], mx3);
        const V B = _mm512_set1_pd(NC_BINS_BLOCK);
        V lf = _mm512_div_pd(SUB(SUB(mn3, _mm512_set1_pd(NC_BINS_BLOCK - 0.5)), pad), B);
        V hf = _mm512_div_pd(_mm512_add_pd(_mm512_add_pd(mx3, _mm512_set1_pd(0.5)), pad), B);
        V *f[2] = {&lf, &hf};
        for (int k = 0; k < 2; k++) {
            const __mmask8 below = _mm512_cmp_pd_mask(*f[k], m2, _CMP_LT_OQ),
                           above = _mm512_cmp_pd_mask(*f[k], mn, _CMP_GT_OQ);
            *f[k] = _mm512_mask_blend_pd(below, _mm512_mask_blend_pd(above, *f[k], mn), m2);
        }
        /* truncation, then ceil(lf), floor(hf), clamped to the blocks */
        const __m256i il = _mm512_cvttpd_epi32(lf), ih = _mm512_cvttpd_epi32(hf);
        const __mmask8 up = _mm512_cmp_pd_mask(_mm512_cvtepi32_pd(il), lf, _CMP_LT_OQ),
                       down = _mm512_cmp_pd_mask(_mm512_cvtepi32_pd(ih), hf, _CMP_GT_OQ);
        __m256i l = _mm256_mask_add_epi32(il, up, il, _mm256_set1_epi32(1));
        __m256i h = _mm256_mask_sub_epi32(ih, down, ih, _mm256_set1_epi32(1));
        l = _mm256_max_epi32(l, _mm256_setzero_si256());
        h = _mm256_min_epi32(h, _mm256_set1_epi32(nb - 1));
        keep &= (__mmask8)~_mm256_cmpgt_epi32_mask(l, h);
        _mm256_storeu_si256((__m256i *)lo[ax], l);
        _mm256_storeu_si256((__m256i *)hi[ax], h);
    }
    if (!keep)
        return 0;
    V e[3][3];
    CROSS(bb, c, e[0]);
    CROSS(c, a, e[1]);
    CROSS(a, bb, e[2]);
    const V len = _mm512_sqrt_pd(_mm512_add_pd(_mm512_add_pd(MUL(n[0], n[0]), MUL(n[1], n[1])), MUL(n[2], n[2])));
    float out[13][8];
    for (int r = 0; r < 3; r++) {
        for (int q = 0; q < 3; q++)
            _mm256_storeu_ps(out[3 * r + q], _mm512_cvtpd_ps(e[r][q]));
        _mm256_storeu_ps(out[9 + r], _mm512_cvtpd_ps(_mm512_div_pd(n[r], len)));
    }
    _mm256_storeu_ps(out[12], _mm512_cvtpd_ps(_mm512_div_pd(nv0, len)));
#undef CROSS
#undef MUL
#undef SUB
    for (int i = 0; i < 8; i++) {
        if (!(keep >> i & 1))
            continue;
        o[i].x0 = lo[0][i], o[i].x1 = hi[0][i], o[i].y0 = lo[1][i], o[i].y1 = hi[1][i];
        for (int r = 0; r < 3; r++) {
            for (int q = 0; q < 3; q++)
                o[i].e[r][q] = out[3 * r + q][i];
            o[i].n[r] = out[9 + r][i];
        }
        o[i].nv0 = out[12][i];
    }
    return keep;
}

/* Count a triangle in the blocks it can meet. Most span one or two blocks
 * each way: those add 0 or 1 to four counters without a branch on the
 * span (the loops' varying lengths were mispredicted). */
static inline void count_blocks(uint32_t *count, int bw, const struct setup *o)
{
    if (o->x1 - o->x0 <= 1 && o->y1 - o->y0 <= 1) {
        const size_t r0 = (size_t)o->y0 * (size_t)bw, r1 = (size_t)o->y1 * (size_t)bw;
        const uint32_t dx = o->x1 > o->x0, dy = o->y1 > o->y0;
        count[r0 + (size_t)o->x0]++;
        count[r0 + (size_t)o->x1] += dx;
        count[r1 + (size_t)o->x0] += dy;
        count[r1 + (size_t)o->x1] += dx & dy;
        return;
    }
    for (int y = o->y0; y <= o->y1; y++)
        for (int x = o->x0; x <= o->x1; x++)
            count[(size_t)y * (size_t)bw + (size_t)x]++;
}

/* Part p's triangles: those that can be hit first and show in the image,
 * listed from slot part_begin on, with how many blocks each part fills. */
static void triangles(struct nc__bins *b, int p)
{
    const size_t T = b->t_off[b->nbodies], end = part_begin(T, p + 1, b->nparts);
    size_t slot = part_begin(T, p, b->nparts);
    uint32_t *count = b->count + (size_t)p * b->nblocks;
    memset(count, 0, b->nblocks * sizeof *count);
    for (size_t g = slot; g < end;) {
        const int k = nc__bins_body_of(b->t_off, b->nbodies, g);
        const struct nc__bins_body *bd = &b->body[k];
        const size_t t = g - b->t_off[k];
        /* the rest of the cluster, the body and the part */
        size_t run = NC_BINS_CLUSTER - t % NC_BINS_CLUSTER;
        run = run < b->t_off[k + 1] - g ? run : b->t_off[k + 1] - g;
        run = run < end - g ? run : end - g;
        if (!b->cl_live[b->c_off[k] + t / NC_BINS_CLUSTER]) {
            g += run;
            continue;
        }
        const float(*vp)[6] = (const float(*)[6])b->vp[b->v_off[k]];
        struct setup o[8];
        unsigned keep;
        int m = 1, straddle = 0;
        if (b->avx512 && run >= 8 && bd->nv <= INT32_MAX / 6) { /* the gathers' offsets */
            m = 8;
            if (run >= 16) /* the next group's vertices, which lie scattered: fetch ahead */
                for (int i = 24; i < 48; i++)
                    _mm_prefetch((const char *)vp[bd->tri[3 * t + (size_t)i]], _MM_HINT_T0);
            keep = setup8_avx512(b, bd->front_only, &bd->tri[3 * t], vp, o, &straddle);
        } else {
            const unsigned *f = &bd->tri[3 * t];
            const int r = setup1(b, bd->front_only, vp[f[0]], vp[f[1]], vp[f[2]], o);
            straddle = r == STRADDLE;
            keep = r == KEEP;
        }
        if (straddle) {
            atomic_store(&b->straddle, 1);
            return;
        }
        for (int i = 0; i < m; i++) {
            if (!(keep >> i & 1))
                continue;
            struct nc__bins_tri *ct = &b->cand[slot];
            memcpy(ct->e, o[i].e, sizeof ct->e);
            memcpy(ct->n, o[i].n, sizeof ct->n);
            ct->nv0 = o[i].nv0;
            memcpy(ct->ng, &bd->ng[3 * (t + (size_t)i)], sizeof ct->ng);
            b->tri[slot] = (uint32_t)(g + (size_t)i);
            int16_t *rg = b->range[slot++];
            rg[0] = (int16_t)o[i].x0, rg[1] = (int16_t)o[i].x1, rg[2] = (int16_t)o[i].y0, rg[3] = (int16_t)o[i].y1;
            count_blocks(count, b->bw, &o[i]);
        }
        g += (size_t)m;
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
    b->avx512 = !b->plain && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
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
