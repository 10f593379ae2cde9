/* boulders.h - boulders on a body's surface (docs/terrain.md).
 *
 * A population follows a cumulative size-frequency distribution
 * N(>D) = C D^-b per km^2 of surface (D the rock's longest dimension in
 * metres), between a smallest and a largest diameter. Rocks are drawn per
 * face of the body's mesh and per octave of diameter [2^j, 2^(j+1)) m, each
 * (face, octave) from its own seeded stream: the population is a function
 * of the mesh, the parameters and the seed alone, and raising the smallest
 * diameter keeps exactly the larger rocks of the same population. Each
 * rock rests on its face with a random orientation, buried by a random
 * fraction of its height, and takes one of a set of procedural shapes:
 * convex polyhedra cut from an ellipsoid of axial ratios near the
 * laboratory fragments' 2 : sqrt(2) : 1 (Michikami et al. 2022).
 */
#ifndef NC_BOULDERS_H
#define NC_BOULDERS_H

#include <stddef.h>
#include <stdint.h>

#include "render/mesh.h"

#define NC_ROCK_PLANES 32
#define NC_ROCK_SHAPES_MAX 256

/* A rock in its own frame, in units of half its longest dimension: the
 * points x with n . x <= d for every plane (n unit), inside the box of
 * half-extents half (half[0] = 1, the longest). */
struct nc_rock_shape {
    float plane[NC_ROCK_PLANES][4]; /* nx, ny, nz, d */
    float half[3];
    int nplanes;
};

/* 48 bytes a rock: a million cost 46 MiB here (plus the ray tracer's tree). */
struct nc_boulder {
    double centre_m[3]; /* body frame */
    float q[4];         /* rotation rock frame -> body frame: w, x, y, z */
    float half_m;       /* half the longest dimension, metres */
    uint16_t shape;
    uint16_t pad;
};

struct nc_boulder_params {
    double c_per_km2;  /* C of N(>D) = C D^-b per km^2, D in metres: N(>1 m) */
    double slope;      /* b > 0 */
    double d_min_m, d_max_m;
    double burial_min, burial_max; /* buried fraction of each rock's height, drawn uniformly */
    int shapes;        /* distinct rock shapes, 1..NC_ROCK_SHAPES_MAX */
    uint64_t seed;
};

struct nc_boulder_field {
    struct nc_boulder *rock;
    size_t n;
    struct nc_rock_shape *shape;
    int nshapes;
    struct nc_boulder_params params;
};

/* Presets from the literature (docs/terrain.md gives the sources): "bennu",
 * "ryugu", "itokawa" set c_per_km2 and slope. Returns 0, or NC_ECONFIG for
 * an unknown name. */
int nc_boulder_preset(const char *name, struct nc_boulder_params *p);
/* The population on mesh m (outward-wound faces). At most max_rocks rocks:
 * more is an error naming the count, so that a typo in C or the smallest
 * diameter does not fill the memory. */
int nc_boulders_generate(const struct nc_mesh *m, const struct nc_boulder_params *p, size_t max_rocks,
                         struct nc_boulder_field *out);
/* The expected number of rocks on area_km2 of surface. */
double nc_boulders_expected(const struct nc_boulder_params *p, double area_km2);
void nc_boulders_free(struct nc_boulder_field *f);

#endif
