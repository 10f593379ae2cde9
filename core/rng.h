/* rng.h - a small deterministic random stream (splitmix64) for procedural
 * generators: a function of its seed alone, the same on every machine. */
#ifndef NC_RNG_H
#define NC_RNG_H

#include <math.h>
#include <stdint.h>

#include "core/vec.h"

static inline uint64_t nc_rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform on [0, 1), 53 bits. */
static inline double nc_rng_uniform(uint64_t *s) { return (double)(nc_rng_next(s) >> 11) * 0x1.0p-53; }

/* Uniform on the unit sphere. */
static inline struct nc_vec3 nc_rng_dir(uint64_t *s)
{
    double z = 2 * nc_rng_uniform(s) - 1, phi = 2 * M_PI * nc_rng_uniform(s), r = sqrt(1 - z * z);
    return nc_v3(r * cos(phi), r * sin(phi), z);
}

/* A seed for the stream of item (a, b) of a generator seeded with seed. */
static inline uint64_t nc_rng_seed(uint64_t seed, uint64_t a, uint64_t b)
{
    uint64_t s = seed ^ (a * 0xd6e8feb86659fd93ull);
    nc_rng_next(&s);
    s ^= b * 0xa0761d6478bd642full;
    return nc_rng_next(&s);
}

/* A Poisson count of mean lambda (normal approximation above 30). */
static inline uint64_t nc_rng_poisson(uint64_t *s, double lambda)
{
    if (lambda > 30) { /* Box-Muller */
        double u = nc_rng_uniform(s), v = nc_rng_uniform(s);
        double k = lambda + sqrt(lambda) * sqrt(-2 * log(1 - u)) * cos(2 * M_PI * v);
        return k > 0 ? (uint64_t)llround(k) : 0;
    }
    double p = exp(-lambda), c = p, u = nc_rng_uniform(s);
    uint64_t k = 0;
    while (u > c && k < 1000) {
        k++;
        p *= lambda / (double)k;
        c += p;
    }
    return k;
}

#endif
