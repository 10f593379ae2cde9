/* mesh.h - triangle meshes in the body-fixed frame, in metres (double).
 *
 * Loaders for Wavefront OBJ and PLY (ASCII and binary), and a procedural
 * cratered asteroid. Loaders validate everything a renderer would trip on
 * (non-triangles, indices out of range, non-finite coordinates, empty meshes)
 * and report file and line; they never touch Embree.
 */
#ifndef NC_MESH_H
#define NC_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "core/vec.h"

struct nc_mesh {
    double *v;      /* xyz per vertex, metres, body-fixed frame */
    uint32_t *tri;  /* three vertex indices per triangle */
    size_t nv, nt;
};

void nc_mesh_free(struct nc_mesh *m);
/* Load OBJ or PLY (by extension), scaling coordinates by scale_to_m. */
int nc_mesh_load(const char *path, double scale_to_m, struct nc_mesh *out);
int nc_mesh_load_obj(const char *path, double scale_to_m, struct nc_mesh *out);
int nc_mesh_load_ply(const char *path, double scale_to_m, struct nc_mesh *out);

/* Procedural cratered asteroid: an icosphere (20 * 4^subdivisions triangles)
 * on a triaxial ellipsoid, with smooth lumps, then craters (craters.h).
 * Fully determined by its arguments. */
struct nc_asteroid_params {
    struct nc_vec3 radii_m;
    int subdivisions;  /* 0..9 */
    uint64_t seed;
    int craters;       /* mean number of craters of the default population (craters.h) */
    double lump_amplitude; /* relative radius variation of the lumps, e.g. 0.08 */
};
/* More craters than this on one body is an error (a typo in the density). */
#define NC_CRATERS_MAX 4000000
int nc_mesh_asteroid(const struct nc_asteroid_params *p, struct nc_mesh *out);

/* Levels of detail (mesh_lod.c): level 0 is the mesh itself (its own
 * triangle list, not copied); each next level has about 4x fewer triangles,
 * made by collapsing edges onto existing vertices (no vertex moves or is
 * added). error_m bounds, to the simplifier's estimate, how far a level's
 * surface lies from the full mesh: the sum of the quadric errors of the
 * steps from level 0, metres. */
#define NC_LOD_MAX_LEVELS 8
struct nc_mesh_lod_level {
    uint32_t *tri;
    size_t nt;
    double error_m;
};
struct nc_mesh_lod {
    struct nc_mesh_lod_level level[NC_LOD_MAX_LEVELS];
    int nlevels;
};
/* Levels down to min_triangles (no level below it; a mesh under 4x that
 * gets level 0 only). */
int nc_mesh_lod_build(const struct nc_mesh *m, size_t min_triangles, struct nc_mesh_lod *out);
void nc_mesh_lod_free(struct nc_mesh_lod *l);
/* The coarsest of nlevels levels with errors error_m[] (non-decreasing)
 * whose error is at most max_error_m; 0 when none is. */
int nc_mesh_lod_pick_error(const double *error_m, int nlevels, double max_error_m);

/* Largest distance of a used vertex from the body origin, metres. */
double nc_mesh_bounding_radius(const struct nc_mesh *m);

/* Measures (mesh_geom.c). Face t's area, m^2, and its unit normal by the
 * winding (zero for a degenerate face; unit_normal may be NULL). */
double nc_mesh_face(const struct nc_mesh *m, size_t t, struct nc_vec3 *unit_normal);
double nc_mesh_area_m2(const struct nc_mesh *m);
/* Unit normals at the vertices (3 per vertex, into n), the area-weighted
 * mean of the faces around each; zero for a vertex no face uses. */
void nc_mesh_vertex_normals(const struct nc_mesh *m, double *n);

#endif
