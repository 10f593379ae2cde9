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
#define NC_ROCK_RELIEF_OCTAVES 3 /* nc_boulder_relief */

/* A rock in its own frame, in units of half its longest dimension (its two
 * farthest corners are 2 units apart): the points x with n . x <= d for
 * every plane k (n = (nx[k], ny[k], nz[k]) unit), inside the box of
 * half-extents half (half[0] the longest).
 * Planes are stored by component, and every slot from nplanes on repeats
 * plane 0, so that a loop may run over all NC_ROCK_PLANES. */
struct nc_rock_shape {
    float nx[NC_ROCK_PLANES], ny[NC_ROCK_PLANES], nz[NC_ROCK_PLANES], d[NC_ROCK_PLANES];
    float half[3];
    int nplanes;
};

/* The corners of shape sh (rock units): every point where three of its
 * planes meet inside the others (within 1e-5), into v. Returns how many
 * (at most max; NC_ROCK_CORNERS_MAX holds any shape's). */
#define NC_ROCK_CORNERS_MAX 256
int nc_rock_shape_corners(const struct nc_rock_shape *sh, float (*v)[3], int max);

/* Octaves of diameter [2^j, 2^(j+1)) m that a population may use. */
#define NC_BOULDER_OCTAVE_MIN (-20) /* 1 um: below anything a camera resolves */
#define NC_BOULDER_OCTAVE_MAX 20    /* 1 km */
#define NC_BOULDER_OCTAVES (NC_BOULDER_OCTAVE_MAX - NC_BOULDER_OCTAVE_MIN + 1)

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
    double burial_min, burial_max; /* beta, drawn uniformly: the centre at (1 - 2 beta) x its depth below it */
    int shapes;        /* distinct rock shapes, 1..NC_ROCK_SHAPES_MAX */
    double roughness_deg; /* the faces' relief: RMS slope, 0..45 deg (0: flat faces) */
    uint64_t seed;
};

/* The rocks of one octave: rock[first .. first + n), largest first. */
struct nc_boulder_octave {
    int j;
    size_t first, n;
};

/* The list runs from the largest octave to the smallest and, within each,
 * from the largest rock to the smallest (ties in the order drawn): the
 * rocks of diameter D or more are always a prefix. */
struct nc_boulder_field {
    struct nc_boulder *rock;
    size_t n;
    struct nc_boulder_octave octave[NC_BOULDER_OCTAVES];
    int noctaves;
    struct nc_rock_shape *shape;
    int nshapes;
    struct nc_boulder_params params;
    double area_m2;    /* the surface they lie on */
    /* nc_boulder_relief's octaves' gradient scales for roughness_deg (0: none) */
    double relief[NC_ROCK_RELIEF_OCTAVES];
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
/* Relief on the rocks' faces, for shading: a height field over each rock's
 * own frame, fBm of gradient noise (core/noise.h) in NC_ROCK_RELIEF_OCTAVES
 * octaves of wavelength D/4, D/8, D/16 (D the rock's longest dimension),
 * amplitude going as wavelength^NC_ROCK_RELIEF_HURST (the roughness
 * exponent of fracture surfaces, about 0.8), seeded per rock, scaled so
 * that its gradient along a face has RMS magnitude tan(roughness_deg). g:
 * the gradient at p (the rock's frame, in units of half its longest
 * dimension; dimensionless). footprint: the size of a pixel there, same
 * units (0: none): an octave is whole where its wavelength spans 4
 * footprints or more, fades linearly to nothing at 2 (a pixel cannot show
 * it; the material's theta_bar stands for what is finer). A function of the
 * rock, the point and the footprint alone. Zero where roughness_deg is 0.
 * Octaves from first on (0: all; a detailed surface's shading takes those
 * its geometry does not carry, NC_ROCK_MESH_OCTAVES). */
#define NC_ROCK_RELIEF_HURST 0.8
void nc_boulder_relief(const struct nc_boulder_field *f, size_t k, const double p[3], double footprint, int first,
                       double g[3]);
/* The detailed surface of shape s, for rocks resolved by many pixels
 * (rt_rocks.h): an icosphere of 20 x 4^subdivisions triangles whose
 * vertices are put on the shape's planes along their directions from its
 * centre (its convex outline, edges and corners rounded at the scale of a
 * triangle), then moved inward along those directions where a height is
 * negative: the first NC_ROCK_MESH_OCTAVES octaves of nc_boulder_relief
 * (those the triangles resolve: the same amplitudes, seeded per shape, no
 * footprint; the finer ones stay in the shading). The faces keep their
 * planes where the height is positive and are pitted where it is negative,
 * so the surface lies within the shape's planes: the flat-faced rock's
 * box, sphere and planes bound it. Rock units, outward winding. Needs
 * roughness_deg > 0 (flat faces need no mesh). */
#define NC_ROCK_MESH_SUBDIVISIONS 3 /* 1280 triangles a shape */
#define NC_ROCK_MESH_OCTAVES 1      /* wavelength D/4: four to seven vertex spacings */
int nc_rock_shape_mesh(const struct nc_boulder_field *f, int s, int subdivisions, struct nc_mesh *out);
/* How many rocks have a diameter of at least d_m (a prefix of the list). */
size_t nc_boulders_at_least(const struct nc_boulder_field *f, double d_m);
/* The cover of the rocks rock[from .. n): the sum of the disks of their
 * longest dimensions, pi (D/2)^2, over the surface's area (may exceed 1).
 * What the reflectance folds in for rocks that are not traced (material.h). */
double nc_boulders_cover(const struct nc_boulder_field *f, size_t from);
/* The radius of the sphere about the body origin that holds every rock
 * (0 for none). */
double nc_boulders_bounding_radius(const struct nc_boulder_field *f);
/* The expected number of rocks on area_km2 of surface. */
double nc_boulders_expected(const struct nc_boulder_params *p, double area_km2);
void nc_boulders_free(struct nc_boulder_field *f);

#endif
