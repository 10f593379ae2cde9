/* rng.c - Philox4x32-10 (Salmon et al., SC'11) over many counters at once:
 * eight counters per AVX2 register when the CPU has AVX2, Random123's scalar
 * philox4x32 otherwise. Both give the same bits (the arithmetic is exact
 * integer arithmetic); tests/emulator/test_rng.c checks every word against
 * Random123. */
#include <immintrin.h>
#include <stdint.h>
#include <string.h>

#include "camera/rng.h"

/* Eight counters: c[j] holds word j of each. Per round (published algorithm):
 * (hi0, lo0) = M0 * c0, (hi1, lo1) = M1 * c2,
 * c = {hi1 ^ c1 ^ k0, lo1, hi0 ^ c3 ^ k1, lo0}, then the key is bumped. */
__attribute__((target("avx2"))) static void philox8(uint32_t k0, uint32_t k1, __m256i c[4])
{
    const __m256i m0 = _mm256_set1_epi64x(0xD2511F53u), m1 = _mm256_set1_epi64x(0xCD9E8D57u);
    const __m256i odd_mask = _mm256_set1_epi64x((int64_t)0xFFFFFFFF00000000ull);
    __m256i c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3];
    for (int r = 0; r < 10; r++) {
        /* 32x32 -> 64 products of the even and the odd 32-bit lanes. */
        __m256i p0e = _mm256_mul_epu32(c0, m0), p0o = _mm256_mul_epu32(_mm256_srli_epi64(c0, 32), m0);
        __m256i p1e = _mm256_mul_epu32(c2, m1), p1o = _mm256_mul_epu32(_mm256_srli_epi64(c2, 32), m1);
        /* hi words back into their lanes: even lane <- high half of p_e, odd lane <- high half of p_o. */
        __m256i hi0 = _mm256_or_si256(_mm256_srli_epi64(p0e, 32), _mm256_and_si256(p0o, odd_mask));
        __m256i lo0 = _mm256_or_si256(_mm256_and_si256(p0e, _mm256_set1_epi64x(0xFFFFFFFF)), _mm256_slli_epi64(p0o, 32));
        __m256i hi1 = _mm256_or_si256(_mm256_srli_epi64(p1e, 32), _mm256_and_si256(p1o, odd_mask));
        __m256i lo1 = _mm256_or_si256(_mm256_and_si256(p1e, _mm256_set1_epi64x(0xFFFFFFFF)), _mm256_slli_epi64(p1o, 32));
        __m256i n0 = _mm256_xor_si256(_mm256_xor_si256(hi1, c1), _mm256_set1_epi32((int)k0));
        __m256i n2 = _mm256_xor_si256(_mm256_xor_si256(hi0, c3), _mm256_set1_epi32((int)k1));
        c0 = n0;
        c1 = lo1;
        c2 = n2;
        c3 = lo0;
        k0 += 0x9E3779B9u;
        k1 += 0xBB67AE85u;
    }
    c[0] = c0, c[1] = c1, c[2] = c2, c[3] = c3;
}

__attribute__((target("avx2"))) static void words_avx2(uint64_t seed, uint32_t f0, uint32_t f1, uint32_t first,
                                                       uint32_t block, size_t count, uint32_t *const out[4])
{
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for (size_t base = 0; base < count; base += 8) {
        __m256i c[4] = {_mm256_add_epi32(_mm256_set1_epi32((int)(first + (uint32_t)base)), lane),
                        _mm256_set1_epi32((int)f0), _mm256_set1_epi32((int)f1), _mm256_set1_epi32((int)block)};
        philox8((uint32_t)seed, (uint32_t)(seed >> 32), c);
        if (base + 8 <= count) {
            for (int j = 0; j < 4; j++)
                _mm256_storeu_si256((__m256i *)(out[j] + base), c[j]);
        } else {
            uint32_t w[4][8];
            for (int j = 0; j < 4; j++)
                _mm256_storeu_si256((__m256i *)w[j], c[j]);
            for (size_t l = 0; base + l < count; l++)
                for (int j = 0; j < 4; j++)
                    out[j][base + l] = w[j][l];
        }
    }
}

void nc_rng_words(uint64_t seed, enum nc_rng_stream stream, uint64_t frame, uint32_t first, uint32_t block,
                  size_t count, uint32_t *const out[4])
{
    static int avx2 = -1;
    if (avx2 < 0) {
        __builtin_cpu_init();
        avx2 = __builtin_cpu_supports("avx2");
    }
    const uint32_t f0 = (uint32_t)frame, f1 = (uint32_t)(frame >> 32) ^ ((uint32_t)stream << 28);
    if (avx2) {
        words_avx2(seed, f0, f1, first, block, count, out);
        return;
    }
    philox4x32_key_t k = {{(uint32_t)seed, (uint32_t)(seed >> 32)}};
    for (size_t i = 0; i < count; i++) {
        philox4x32_ctr_t c = {{first + (uint32_t)i, f0, f1, block}};
        philox4x32_ctr_t r = philox4x32(c, k);
        for (int j = 0; j < 4; j++)
            out[j][i] = r.v[j];
    }
}
