/* mesh.h - triangle meshes in the body-fixed frame, in metres (double).
 *
 * Loaders for Wavefront OBJ, PLY (ASCII and binary) and SPC's ICQ, and a procedural
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
/* The farthest a vertex may lie from a model's origin, metres (the largest
 * globe radius a configuration takes): past it a value is a wrong unit or
 * scale (the ray tracer aborts on the 1e30 that such a file can hold). */
#define NC_MESH_MAX_M 1e10
/* 0, or (m freed) an error naming `what` and the first vertex beyond
 * NC_MESH_MAX_M, or saying that no triangle has an area. */
int nc_mesh_check_extent(struct nc_mesh *m, const char *what);
/* Load OBJ or PLY (by extension), scaling coordinates by scale_to_m. */
int nc_mesh_load(const char *path, double scale_to_m, struct nc_mesh *out);
int nc_mesh_load_obj(const char *path, double scale_to_m, struct nc_mesh *out);
int nc_mesh_load_ply(const char *path, double scale_to_m, struct nc_mesh *out);
/* SPC's ICQ (implicitly connected quadrilateral) shape, SHAPE.TXT
 * (mesh_icq.c): 12 Q^2 triangles, edge copies welded. */
int nc_mesh_load_icq(const char *path, double scale_to_m, struct nc_mesh *out);

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
/* Relief below the mesh's resolution (mesh_relief.c): the mesh subdivided
 * until its mean edge is at most edge_m, every vertex (the mesh's own
 * too) displaced along the normal by fractional Brownian motion of Hurst
 * exponent hurst, E[(h(x + l) - h(x))^2] = s^2 l^(2H), in octaves from half
 * the mesh's mean edge down to the final edge, with s measured on the mesh
 * itself (times amplitude). */
struct nc_relief_params {
    double edge_m;    /* subdivide until the mean edge is at most this, m */
    double hurst;     /* 0 < H < 1 */
    double amplitude; /* factor on the measured s (1: continue the model's roughness) */
    uint64_t seed;
};
struct nc_relief_info {
    int levels;          /* subdivisions made */
    double model_edge_m; /* the mesh's mean edge before */
    double edge_m;       /* and after (halved per level) */
    double s;            /* the s used, m^(1-H) */
};
/* base_normals (NULL: not wanted): on success with at least one level,
 * *base_normals holds each vertex's normal of the model's surface under it
 * (3 nv doubles, unit, malloc'd: the caller frees), interpolated from the
 * model's vertex normals: smooth at the model's scale, free of the relief's
 * roughness, so that a further displacement along them (craters) cannot
 * fold the relief; NULL when nothing was subdivided. */
int nc_mesh_relief(struct nc_mesh *m, const struct nc_relief_params *p, size_t max_triangles,
                   struct nc_relief_info *info, double **base_normals);
#define NC_RELIEF_MAX_TRIANGLES 8000000

int nc_mesh_asteroid(const struct nc_asteroid_params *p, struct nc_mesh *out);

/* Elevation data (mesh_dem.c). A terrain tile from a w x rows height image
 * (row 0 the northern edge, column 0 the western; a vertex per pixel
 * centre, two triangles per cell of four finite corners: a non-finite pixel
 * makes holes). Flat (radius_m 0): x east, y north, z up, the origin at the
 * image's centre at height 0. On a sphere of radius_m: the tile's centre at
 * planetocentric lat_deg, lon_deg (east), each pixel's east and north
 * offsets projected gnomonically onto the sphere and raised by its height,
 * in the sphere's body-fixed frame (+z the pole, +x longitude 0). Heights
 * are height_offset_m + height_scale x pixel value, metres. */
#define NC_DEM_MAX_PIXELS (4096 * 4096)
struct nc_dem_tile_params {
    double pixel_m[2]; /* ground sample distance along a row (east) and a column (north), m */
    double height_scale, height_offset_m;
    double radius_m, lat_deg, lon_deg;
};
int nc_mesh_dem_tile(const float *h, int w, int rows, const struct nc_dem_tile_params *p, struct nc_mesh *out);
/* A sphere of radius_m (an icosphere of 20 x 4^subdivisions faces) with
 * each vertex moved along its radius by the elevation map's value there, m. */
struct nc_albedo_map;
int nc_mesh_globe(double radius_m, int subdivisions, const struct nc_albedo_map *elevation, struct nc_mesh *out);

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
/* The mean length of the triangles' edges (each counted once per triangle), m. */
double nc_mesh_mean_edge_m(const struct nc_mesh *m);
/* Unit normals at the vertices (3 per vertex, into n), the area-weighted
 * mean of the faces around each; zero for a vertex no face uses. */
void nc_mesh_vertex_normals(const struct nc_mesh *m, double *n);
/* One level of subdivision: each triangle into four, a new vertex at the
 * middle of each edge (appended in the order the faces meet them). place,
 * if not NULL, may move each new vertex: it gets the edge's ends a < b, the
 * new vertex's index and its position (the midpoint) to change. */
typedef void (*nc_mesh_midpoint_fn)(void *ctx, const struct nc_mesh *m, uint32_t a, uint32_t b, uint32_t index,
                                    double *xyz);
int nc_mesh_subdivide(struct nc_mesh *m, nc_mesh_midpoint_fn place, void *ctx);

#endif
