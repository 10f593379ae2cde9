/* rng.h - counter-based random numbers (Random123 Philox4x32-10): every
 * draw is a pure function of (seed, stream, frame, index, block), so results
 * never depend on thread count or order. */
#ifndef NC_CAMERA_RNG_H
#define NC_CAMERA_RNG_H

#include <math.h>
#include <stdint.h>

#include <Random123/philox.h>

enum nc_rng_stream { NC_RNG_FIXED_PATTERN = 1, NC_RNG_PIXEL_NOISE = 2, NC_RNG_COSMIC = 3 };

/* Four uniforms in (0, 1). */
static inline void nc_rng4(uint64_t seed, enum nc_rng_stream stream, uint64_t frame, uint32_t index, uint32_t block,
                           double u[4])
{
    philox4x32_key_t k = {{(uint32_t)seed, (uint32_t)(seed >> 32)}};
    philox4x32_ctr_t c = {{index, (uint32_t)frame, (uint32_t)(frame >> 32) ^ ((uint32_t)stream << 28), block}};
    philox4x32_ctr_t r = philox4x32(c, k);
    for (int i = 0; i < 4; i++)
        u[i] = ((double)r.v[i] + 0.5) * 0x1.0p-32;
}

/* Philox4x32-10 for `count` consecutive indices first .. first+count-1 (same
 * seed, stream, frame, block): out[j][i] is word j of index first+i,
 * bit-identical to nc_rng4's words (rng.c: eight counters per AVX2 register,
 * checked against Random123 by the tests). */
void nc_rng_words(uint64_t seed, enum nc_rng_stream stream, uint64_t frame, uint32_t first, uint32_t block,
                  size_t count, uint32_t *const out[4]);

/* Two independent standard normals from two uniforms (Box-Muller). */
static inline void nc_normal2(double u1, double u2, double *z1, double *z2)
{
    double rad = sqrt(-2.0 * log(u1)), a = 2.0 * M_PI * u2;
    *z1 = rad * cos(a);
    *z2 = rad * sin(a);
}

#endif
