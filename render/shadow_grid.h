/* shadow_grid.h - proving that a sunlit surface point is outside its own
 * body's shadow, so its shadow ray need not be traced.
 *
 * On a closed, outward-wound surface a ray that starts outside the solid can
 * only enter it, so the first face it meets turns away from the Sun (n . s < 0).
 * Looking along the Sun direction s, the grid stores per cell the highest
 * height h = x . s of any such face reaching into the cell. A point whose
 * height is above its cell's value has nothing that could stop its ray toward
 * the Sun. The test is conservative (it never declares a shadowed point lit,
 * with margins for the float geometry Embree traces); it knows nothing of
 * Embree, cameras or other bodies.
 */
#ifndef NC_SHADOW_GRID_H
#define NC_SHADOW_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "core/vec.h"

struct nc_shadow_grid {
    struct nc_vec3 sun;   /* unit Sun direction it was built for (mesh frame) */
    struct nc_vec3 u, v;  /* the grid's axes, perpendicular to sun */
    double u0, v0;        /* lower corner, m */
    double cell_m, margin_m, tol_rad;
    int n;                /* n x n cells */
    float *hmax;          /* per cell; -INFINITY where no face turned away reaches */
};

/* Whether the triangles form a closed surface wound outward: every edge is
 * used as often in one direction as in the other, and the signed volume is
 * positive. 1 yes, 0 no, or a negative error code. */
int nc_shadow_grid_closed(const double *v, size_t nv, const uint32_t *tri, size_t nt);

/* Build (or rebuild, reusing memory) for vertices v (xyz, any frame),
 * triangles tri, a unit Sun direction in that frame good for rays within
 * tol_rad of it (at least 1e-6; a grid can then serve a slowly turning
 * body for many frames), and the sphere (centre, radius_m) that holds every
 * vertex. margin_m bounds how far the geometry as traced (float vertices,
 * transforms and ray origins) can lie from these coordinates. */
int nc_shadow_grid_build(struct nc_shadow_grid *g, const double *v, const uint32_t *tri, size_t nt, struct nc_vec3 sun,
                         double tol_rad, struct nc_vec3 centre, double radius_m, double margin_m);
/* 1 if a ray from p toward direction d (unit, same frame) cannot meet a face
 * of the mesh; 0 if that is not proven (d too far from the grid's sun for
 * the margin, or something turned away from the Sun above p). */
int nc_shadow_grid_lit(const struct nc_shadow_grid *g, struct nc_vec3 p, struct nc_vec3 d);
/* The same in two steps, for many rays: whether direction d is within
 * tol_rad of the grid's sun, then the point by its coordinates along u, v
 * and sun. */
int nc_shadow_grid_dir_ok(const struct nc_shadow_grid *g, struct nc_vec3 d);
int nc_shadow_grid_lit_at(const struct nc_shadow_grid *g, double pu, double pv, double ph);
/* nc_shadow_grid_lit_at for point p of another frame, whose coordinates
 * along u, v and sun are c_k = p . axis[k] - off[k]. */
int nc_shadow_grid_lit_in(const struct nc_shadow_grid *g, const struct nc_vec3 axis[3], const double off[3],
                          struct nc_vec3 p);
/* nc_shadow_grid_lit_in for 16 float points at once, (x[i], y[i], z[i]):
 * lit[i] = -1 where want[i] and the point is proven lit, else 0. The same
 * operations in the same order, so the same answers. */
void nc_shadow_grid_lit16(const struct nc_shadow_grid *g, const struct nc_vec3 axis[3], const double off[3],
                          const float *x, const float *y, const float *z, const int *want, int *lit);
void nc_shadow_grid_free(struct nc_shadow_grid *g);

#endif
