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

#include <immintrin.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

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
        if (k + 6 < n) /* candidates are scattered: fetch ahead (6 gained 1 % over 2 on the crop) */
            _mm_prefetch((const char *)&cand[list[k + 6]], _MM_HINT_T0);
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
