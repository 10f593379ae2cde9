/* craters.h - impact craters carved into a body's mesh (docs/terrain.md).
 *
 * A population follows a cumulative size-frequency distribution
 * N(>D) = C D^-b per km^2 of surface (D the rim-to-rim diameter in metres)
 * between a smallest and a largest diameter; centres are uniform over the
 * mesh's area and ages uniform in [0, 1) (a constant impact flux; 1 is the
 * age of the surface). Each crater is a simple bowl: a parabolic cavity
 * with a raised rim and an ejecta blanket thinning as (r/R)^-3, made
 * shallower and its rim lower with age; younger craters erase the relief
 * of older ones inside their cavity, so overlaps come out in age order.
 * Everything is a function of the mesh, the parameters and the seed.
 */
#ifndef NC_CRATERS_H
#define NC_CRATERS_H

#include <stddef.h>
#include <stdint.h>

#include "render/mesh.h"

/* More craters than this on one body is an error (a typo in the density). */
#define NC_CRATERS_MAX 4000000

struct nc_crater_params {
    double c_per_km2;   /* C of N(>D) = C D^-b per km^2, D in metres: N(>1 m) */
    double slope;       /* b > 0 */
    double d_min_m, d_max_m;
    double depth_ratio; /* fresh rim-crest-to-floor depth over D */
    double rim_ratio;   /* fresh rim height above the surrounding surface over D */
    double degradation; /* 0..1: the fraction of its depth the oldest crater has lost */
    uint64_t seed;
};

struct nc_crater {
    double centre_m[3]; /* on the mesh, body frame */
    double normal[3];   /* the face's unit normal there */
    double d_m;         /* rim-to-rim diameter */
    double age;         /* [0, 1): 0 fresh */
};

struct nc_crater_field {
    struct nc_crater *crater; /* oldest first */
    size_t n;
    size_t applied;           /* craters that moved at least one vertex (nc_craters_apply) */
    double area_km2;          /* the surface they were drawn on */
    struct nc_crater_params params;
};

/* Defaults for mesh m: fresh simple craters, Pike (1977) depth 0.196 D and
 * rim height 0.036 D (docs/terrain.md), cumulative slope 2, half the depth
 * lost by the oldest; diameters from four mean edge lengths (smaller ones
 * hold too few vertices to show) to the radius of the sphere of m's area;
 * density 0, seed 1. */
void nc_crater_params_default(const struct nc_mesh *m, struct nc_crater_params *p);
/* The expected number on area_km2 of surface, and the density C giving a
 * mean of count craters there. */
double nc_craters_expected(const struct nc_crater_params *p, double area_km2);
double nc_craters_density_for(const struct nc_crater_params *p, double area_km2, double count);
/* Draw the population on mesh m (outward-wound faces); at most max_craters
 * (more is an error naming the count). The count is Poisson. */
int nc_craters_generate(const struct nc_mesh *m, const struct nc_crater_params *p, size_t max_craters,
                        struct nc_crater_field *out);
/* Carve the field into m, oldest crater first: each vertex moves along its
 * direction in dir (3 nv unit vectors; NULL: the mesh's pre-crater vertex
 * normals). On a mesh with relief, pass the surface normals under the relief
 * (nc_mesh_relief's base_normals): its rough vertex normals would turn a
 * deep crater's displacement from vertex to vertex and fold the mesh. A
 * crater whose cavity holds no vertex is below the mesh's resolution and
 * left out (f->applied counts the others). */
int nc_craters_apply(struct nc_crater_field *f, struct nc_mesh *m, const double *dir);
void nc_craters_free(struct nc_crater_field *f);

#endif
