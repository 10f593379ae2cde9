/* noise.h - gradient noise (Perlin 2002's construction) on a unit-period
 * lattice: corners carry hashed gradients among the 12 cube-edge
 * directions, blended with the quintic fade. Zero at the lattice points,
 * mean zero, RMS NC_NOISE_RMS (measured over 2 million uniform points: 0.2699;
 * test_noise checks it); a pure function of the seed and the point (no
 * state, any thread). */
#ifndef NC_NOISE_H
#define NC_NOISE_H

#include <stdint.h>

#define NC_NOISE_RMS 0.27
#define NC_NOISE_GRAD_RMS 0.704

double nc_noise3(uint64_t seed, double x, double y, double z);
/* The same value (bit for bit) and its gradient g, per lattice period.
 * Each component of g has RMS NC_NOISE_GRAD_RMS over uniform points
 * (measured over a million: 0.7044; test_noise checks it). */
double nc_noise3_grad(uint64_t seed, double x, double y, double z, double g[3]);

#endif
