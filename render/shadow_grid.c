/* shadow_grid.c - the Sun-column height grid of shadow_grid.h: a proof of
 * "nothing above this point toward the Sun", never an approximation of a
 * shadow. Built once per Sun direction, level and anchor; queried per ray. */
#include "render/shadow_grid.h"

#include <errno.h>
#include <immintrin.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

static int cmp_u32(const void *pa, const void *pb)
{
    const uint32_t a = *(const uint32_t *)pa, b = *(const uint32_t *)pb;
    return (a > b) - (a < b);
}

int nc_shadow_grid_closed(const double *v, size_t nv, const uint32_t *tri, size_t nt)
{
    /* Each edge goes into the bucket of its lower vertex as (the other
     * vertex << 1 | direction): a counting sort, whose writes follow the
     * mesh's own vertex order (a hash table of edges made every one a cache
     * miss: 2.0 s for 5.2 million triangles). Closed: in every bucket, each
     * other vertex comes as often with one direction as with the other.
     * Subdivision sorts half-edges the same way (mesh_geom.c) but needs each
     * one's index, in 64-bit entries; through that one function this check
     * took 1.1-1.2 s against 0.52-0.59 s with its 32-bit entries (5.2
     * million triangles, three runs each), so it keeps its own. */
    if (nt == 0 || nv == 0 || nv > (size_t)INT32_MAX || nt > (size_t)UINT32_MAX / 3)
        return 0; /* not proven: such a mesh is traced without the grid */
    uint32_t *start = calloc(nv + 1, sizeof *start), *at = malloc(nv * sizeof *at), *e = malloc(3 * nt * sizeof *e);
    if (!start || !at || !e) {
        free(start);
        free(at);
        free(e);
        return nc_error(-ENOMEM, "out of memory for the edges of %zu triangles", nt);
    }
    int closed = 1;
    double vol = 0;
    for (size_t t = 0; t < nt && closed; t++) {
        const uint32_t *f = &tri[3 * t];
        if (f[0] >= nv || f[1] >= nv || f[2] >= nv) {
            closed = 0;
            break;
        }
        for (int k = 0; k < 3; k++) {
            const uint32_t a = f[k], b = f[(k + 1) % 3];
            start[(a < b ? a : b) + 1]++;
        }
        const double *p = &v[3 * (size_t)f[0]], *q = &v[3 * (size_t)f[1]], *r = &v[3 * (size_t)f[2]];
        /* 6 x the signed volume of the tetrahedron (0, p, q, r) */
        vol += p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
               p[2] * (q[0] * r[1] - q[1] * r[0]);
    }
    for (size_t i = 0; i < nv && closed; i++) {
        start[i + 1] += start[i];
        at[i] = start[i];
    }
    for (size_t t = 0; t < nt && closed; t++)
        for (int k = 0; k < 3; k++) {
            const uint32_t a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
            if (a < b)
                e[at[a]++] = b << 1 | 1;
            else
                e[at[b]++] = a << 1;
        }
    for (size_t i = 0; i < nv && closed; i++) {
        uint32_t *x = e + start[i];
        const size_t n = start[i + 1] - start[i];
        if (n > 16)
            qsort(x, n, sizeof *x, cmp_u32);
        else
            for (size_t j = 1; j < n; j++) /* insertion sort: a vertex has about 6 */
                for (size_t k = j; k > 0 && x[k - 1] > x[k]; k--) {
                    const uint32_t tmp = x[k];
                    x[k] = x[k - 1];
                    x[k - 1] = tmp;
                }
        for (size_t j = 0; j < n && closed;) { /* a run of one other vertex: 0s, then as many 1s */
            size_t k = j;
            while (k < n && x[k] >> 1 == x[j] >> 1)
                k++;
            size_t ones = 0;
            for (size_t q = j; q < k; q++)
                ones += x[q] & 1;
            closed = 2 * ones == k - j;
            j = k;
        }
    }
    free(start);
    free(at);
    free(e);
    return closed && vol > 0;
}

int nc_shadow_grid_build(struct nc_shadow_grid *g, const double *v, const uint32_t *tri, size_t nt, struct nc_vec3 sun,
                         double tol_rad, struct nc_vec3 centre, double radius_m, double margin_m)
{
    /* Cells about the size of a face: n^2 ~ nt / 2 over the disk. */
    int n = (int)ceil(sqrt((double)nt / 2.0));
    n = n < 16 ? 16 : n > 2048 ? 2048 : n;
    if (n != g->n) {
        float *h = malloc((size_t)n * (size_t)n * sizeof *h);
        if (!h)
            return nc_error(-ENOMEM, "out of memory for a %dx%d shadow grid", n, n);
        free(g->hmax);
        g->hmax = h;
        g->n = n;
    }
    g->sun = sun;
    /* Any axes perpendicular to the Sun. */
    struct nc_vec3 t = fabs(sun.x) < 0.6 ? nc_v3(1, 0, 0) : nc_v3(0, 1, 0);
    g->u = nc_v3_unit(nc_v3_cross(sun, t));
    g->v = nc_v3_cross(sun, g->u);
    /* A ray within tol_rad of sun drifts off its column by at most
     * 2 radius_m tol_rad inside the sphere; with the geometry's own margin,
     * every face's footprint grows by `grow`. */
    const double grow = 2 * margin_m + 2 * radius_m * tol_rad, half = radius_m + 2 * grow;
    g->margin_m = margin_m;
    g->tol_rad = tol_rad;
    g->cell_m = 2 * half / n;
    g->u0 = nc_v3_dot(centre, g->u) - half;
    g->v0 = nc_v3_dot(centre, g->v) - half;
    for (size_t i = 0; i < (size_t)n * (size_t)n; i++)
        g->hmax[i] = -INFINITY;
    const double inv = 1.0 / g->cell_m;
    for (size_t f = 0; f < nt; f++) {
        struct nc_vec3 p[3];
        for (int k = 0; k < 3; k++) {
            const double *q = &v[3 * (size_t)tri[3 * f + k]];
            p[k] = nc_v3(q[0], q[1], q[2]);
        }
        struct nc_vec3 nrm = nc_v3_cross(nc_v3_sub(p[1], p[0]), nc_v3_sub(p[2], p[0]));
        double len = nc_v3_norm(nrm);
        /* A ray that enters through a face has n . d < 0, so n . sun < |sun - d|,
         * under 2 tol_rad for a direction d within tol_rad of sun. */
        if (nc_v3_dot(nrm, sun) >= 2 * tol_rad * len)
            continue; /* faces the Sun: a ray from outside cannot enter through it */
        double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY, h = -INFINITY;
        for (int k = 0; k < 3; k++) {
            double a = nc_v3_dot(p[k], g->u), b = nc_v3_dot(p[k], g->v);
            umin = fmin(umin, a);
            umax = fmax(umax, a);
            vmin = fmin(vmin, b);
            vmax = fmax(vmax, b);
            h = fmax(h, nc_v3_dot(p[k], sun));
        }
        int i0 = (int)floor((umin - grow - g->u0) * inv), i1 = (int)floor((umax + grow - g->u0) * inv);
        int j0 = (int)floor((vmin - grow - g->v0) * inv), j1 = (int)floor((vmax + grow - g->v0) * inv);
        i0 = i0 < 0 ? 0 : i0;
        j0 = j0 < 0 ? 0 : j0;
        i1 = i1 >= n ? n - 1 : i1;
        j1 = j1 >= n ? n - 1 : j1;
        /* A point of the ray is higher than its start: no tilt allowance.
         * Rounded up so the float never understates the height. */
        float hf = nextafterf((float)(h + 2 * margin_m), INFINITY);
        for (int j = j0; j <= j1; j++)
            for (int i = i0; i <= i1; i++)
                if (g->hmax[(size_t)j * n + i] < hf)
                    g->hmax[(size_t)j * n + i] = hf;
    }
    return 0;
}

int nc_shadow_grid_dir_ok(const struct nc_shadow_grid *g, struct nc_vec3 d)
{
    double c = nc_v3_dot(d, g->sun);
    return c > 0 && nc_v3_norm(nc_v3_sub(d, nc_v3_scale(g->sun, c))) <= g->tol_rad;
}

int nc_shadow_grid_lit_at(const struct nc_shadow_grid *g, double pu, double pv, double ph)
{
    double a = (pu - g->u0) / g->cell_m, b = (pv - g->v0) / g->cell_m;
    if (!(a >= 0 && b >= 0 && a < g->n && b < g->n))
        return !isnan(a) && !isnan(b) && !isnan(ph); /* beyond every face's column */
    return ph > g->hmax[(size_t)(int)b * g->n + (int)a];
}

int nc_shadow_grid_lit(const struct nc_shadow_grid *g, struct nc_vec3 p, struct nc_vec3 d)
{
    return nc_shadow_grid_dir_ok(g, d) &&
           nc_shadow_grid_lit_at(g, nc_v3_dot(p, g->u), nc_v3_dot(p, g->v), nc_v3_dot(p, g->sun));
}

int nc_shadow_grid_lit_in(const struct nc_shadow_grid *g, const struct nc_vec3 axis[3], const double off[3],
                          struct nc_vec3 p)
{
    return nc_shadow_grid_lit_at(g, nc_v3_dot(p, axis[0]) - off[0], nc_v3_dot(p, axis[1]) - off[1],
                                 nc_v3_dot(p, axis[2]) - off[2]);
}

/* Eight points of nc_shadow_grid_lit16 in AVX-512 registers, their cells
 * read by one gather (the scalar reads wait on memory one after another):
 * the same operations in the same order, so the same answers. Cell indices
 * in 32 bits: the build caps the grid at 2048 x 2048. */
__attribute__((target("avx512f,avx512vl"))) static __mmask8 lit8_avx512(const struct nc_shadow_grid *g,
                                                                const struct nc_vec3 axis[3], const double off[3],
                                                                const float *x, const float *y, const float *z)
{
    typedef __m512d V;
    const V px = _mm512_cvtps_pd(_mm256_loadu_ps(x)), py = _mm512_cvtps_pd(_mm256_loadu_ps(y)),
            pz = _mm512_cvtps_pd(_mm256_loadu_ps(z));
    V c[3];
    for (int k = 0; k < 3; k++) {
        V t = _mm512_add_pd(_mm512_mul_pd(px, _mm512_set1_pd(axis[k].x)), _mm512_mul_pd(py, _mm512_set1_pd(axis[k].y)));
        t = _mm512_add_pd(t, _mm512_mul_pd(pz, _mm512_set1_pd(axis[k].z)));
        c[k] = _mm512_sub_pd(t, _mm512_set1_pd(off[k]));
    }
    const V cell = _mm512_set1_pd(g->cell_m), n = _mm512_set1_pd(g->n), zero = _mm512_setzero_pd();
    const V a = _mm512_div_pd(_mm512_sub_pd(c[0], _mm512_set1_pd(g->u0)), cell),
            b = _mm512_div_pd(_mm512_sub_pd(c[1], _mm512_set1_pd(g->v0)), cell);
    __mmask8 in = _mm512_cmp_pd_mask(a, zero, _CMP_GE_OQ);
    in = _mm512_mask_cmp_pd_mask(in, b, zero, _CMP_GE_OQ);
    in = _mm512_mask_cmp_pd_mask(in, a, n, _CMP_LT_OQ);
    in = _mm512_mask_cmp_pd_mask(in, b, n, _CMP_LT_OQ);
    const __m256i k = _mm256_add_epi32(_mm256_mullo_epi32(_mm512_cvttpd_epi32(b), _mm256_set1_epi32(g->n)),
                                       _mm512_cvttpd_epi32(a));
    const __m256 h = _mm256_mmask_i32gather_ps(_mm256_setzero_ps(), in, k, g->hmax, 4);
    const __mmask8 above = _mm512_mask_cmp_pd_mask(in, c[2], _mm512_cvtps_pd(h), _CMP_GT_OQ);
    __mmask8 beyond = _mm512_cmp_pd_mask(a, a, _CMP_ORD_Q) & _mm512_cmp_pd_mask(b, b, _CMP_ORD_Q) &
                      _mm512_cmp_pd_mask(c[2], c[2], _CMP_ORD_Q);
    return above | (beyond & (__mmask8)~in);
}

void nc_shadow_grid_lit16(const struct nc_shadow_grid *g, const struct nc_vec3 axis[3], const double off[3],
                          const float *x, const float *y, const float *z, const int *want, int *lit)
{
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl")) {
        const unsigned lo = lit8_avx512(g, axis, off, x, y, z), hi = lit8_avx512(g, axis, off, x + 8, y + 8, z + 8);
        const unsigned m = lo | hi << 8;
        for (int i = 0; i < 16; i++)
            lit[i] = want[i] && (m >> i & 1) ? -1 : 0;
        return;
    }
    for (int i = 0; i < 16; i++)
        lit[i] = want[i] && nc_shadow_grid_lit_in(g, axis, off, nc_v3(x[i], y[i], z[i])) ? -1 : 0;
}

void nc_shadow_grid_free(struct nc_shadow_grid *g)
{
    free(g->hmax);
    memset(g, 0, sizeof *g);
}
