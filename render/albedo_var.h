/* albedo_var.h - procedural albedo variation on a body's surface
 * (docs/terrain.md): a factor on the material's albedo parameter (like an
 * albedo map's), lognormal so that it is positive with mean 1 and the
 * configured relative RMS. On the ground it is fBm gradient noise of the
 * body-fixed position, from the largest wavelength down to twice the
 * mesh's mean edge, evaluated once per vertex and interpolated across
 * each triangle; each boulder takes one factor of its own. A function of
 * the mesh, the parameters and the seed alone. */
#ifndef NC_ALBEDO_VAR_H
#define NC_ALBEDO_VAR_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "core/rng.h"
#include "render/mesh.h"

struct nc_albedo_var_params {
    double rms;       /* relative RMS of the ground's factor (0: none) */
    double largest_m; /* longest wavelength of the ground's variation, m */
    double hurst;     /* each octave's amplitude goes as wavelength^hurst */
    double rocks_rms; /* relative RMS of a rock's factor (0: none) */
    uint64_t seed;
};

/* The ground's factor at every vertex of m: *out (nv floats, malloc'd) and
 * the shortest wavelength used (twice the mean edge), m. */
int nc_albedo_var_vertices(const struct nc_mesh *m, const struct nc_albedo_var_params *p, float **out,
                           double *smallest_m);

/* The factor of rock i of the body's boulder list. */
static inline float nc_albedo_var_rock(const struct nc_albedo_var_params *p, size_t i)
{
    if (!(p->rocks_rms > 0))
        return 1.0f;
    uint64_t h = nc_rng_seed(p->seed, 0x726f636bull /* "rock" */, (uint64_t)i);
    double u1 = ((double)(h >> 40) + 0.5) * 0x1.0p-24, u2 = (double)(h & 0xffffff) * 0x1.0p-24;
    double z = sqrt(-2 * log(u1)) * cos(2 * M_PI * u2); /* Box-Muller: standard normal */
    double s2 = log1p(p->rocks_rms * p->rocks_rms);
    return (float)exp(sqrt(s2) * z - 0.5 * s2);
}

#endif
