/* scene_dem.c - the shapes built from elevation data (docs/terrain.md):
 * `dem`, a terrain tile from a height image, flat or on a sphere; `globe`,
 * a sphere displaced by an equirectangular elevation map. Both become
 * meshes (nc_body.shape = NC_SHAPE_MESH), so that everything a mesh can
 * carry (levels of detail, relief, craters, boulders, smooth normals,
 * albedo variation) applies. Reads config nodes and images; no rendering. */
#include "render/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/log.h"
#include "render/albedo_map.h"
#include "render/image_io.h"
#include "render/mesh.h"

static int dem_from_config(struct nc_cfg_node *sh, struct nc_body *b, int dry)
{
    const char *file;
    int rc;
    if ((rc = nc_cfg_string(sh, "file", &file)) <= 0)
        return rc ? rc : nc_cfg_missing(sh, "file", "a height image (float TIFF or FITS; 16-bit PNG with height_scale)");
    struct nc_dem_tile_params p = {.height_scale = 1};
    struct nc_cfg_node *px = nc_cfg_get(sh, "pixel_m");
    if (!px)
        return nc_cfg_missing(sh, "pixel_m", "the ground sample distance in metres, or [east, north]");
    if (px->kind == NC_CFG_SEQ)
        rc = nc_cfg_doubles(sh, "pixel_m", p.pixel_m, 2);
    else if ((rc = nc_cfg_double(sh, "pixel_m", 1e-6, 1e7, &p.pixel_m[0])) > 0)
        p.pixel_m[1] = p.pixel_m[0];
    if (rc < 0)
        return rc;
    if (!(p.pixel_m[0] >= 1e-6 && p.pixel_m[0] <= 1e7 && p.pixel_m[1] >= 1e-6 && p.pixel_m[1] <= 1e7))
        return nc_cfg_error(px, "expected pixel sizes in [1e-6, 1e7] m, got %g and %g", p.pixel_m[0], p.pixel_m[1]);
    if ((rc = nc_cfg_double(sh, "height_scale", -1e9, 1e9, &p.height_scale)) < 0 ||
        (rc = nc_cfg_double(sh, "height_offset_m", -1e9, 1e9, &p.height_offset_m)) < 0)
        return rc;
    struct nc_cfg_node *sph;
    if ((rc = nc_cfg_map(sh, "on_sphere", &sph)) < 0)
        return rc;
    if (rc) {
        if ((rc = nc_cfg_double(sph, "radius_m", 1, NC_MESH_MAX_M, &p.radius_m)) <= 0)
            return rc ? rc : nc_cfg_missing(sph, "radius_m", "the reference sphere's radius, metres");
        if ((rc = nc_cfg_double(sph, "lat_deg", -90, 90, &p.lat_deg)) <= 0)
            return rc ? rc : nc_cfg_missing(sph, "lat_deg", "planetocentric latitude of the tile's centre");
        if ((rc = nc_cfg_double(sph, "lon_deg", -360, 360, &p.lon_deg)) <= 0)
            return rc ? rc : nc_cfg_missing(sph, "lon_deg", "east longitude of the tile's centre");
    }
    if (dry)
        return 0;
    char path[4096];
    nc_cfg_resolve_path(nc_cfg_get(sh, "file"), file, path, sizeof path);
    float *h;
    int w, rows;
    if ((rc = nc_image_read(path, &h, &w, &rows)) < 0)
        return nc__scene_error_at(nc_cfg_get(sh, "file"));
    rc = nc_mesh_dem_tile(h, w, rows, &p, &b->mesh);
    free(h);
    if (rc < 0) { /* the file named, as the read's errors do */
        char why[1024];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        nc_error(rc, "%s: %s", path, why);
        return nc__scene_error_at(nc_cfg_get(sh, "file"));
    }
    b->bounding_radius_m = nc_mesh_bounding_radius(&b->mesh);
    nc_log_info("scene", "body '%s': DEM %s, %dx%d pixels of %g x %g m, %zu triangles%s", b->name, path, w, rows,
                p.pixel_m[0], p.pixel_m[1], b->mesh.nt, p.radius_m > 0 ? ", on a sphere" : "");
    return 0;
}

static int globe_from_config(struct nc_cfg_node *sh, struct nc_body *b, int dry)
{
    double r;
    long sub = 7;
    int rc;
    if ((rc = nc_cfg_double(sh, "radius_m", 1e-3, NC_MESH_MAX_M, &r)) <= 0)
        return rc ? rc : nc_cfg_missing(sh, "radius_m", "the reference sphere's radius, metres");
    if ((rc = nc_cfg_int(sh, "subdivisions", 0, 9, &sub)) < 0)
        return rc;
    struct nc_cfg_node *em;
    if ((rc = nc_cfg_map(sh, "elevation_map", &em)) <= 0)
        return rc ? rc : nc_cfg_missing(sh, "elevation_map", "an equirectangular elevation image (file, scale: m per unit)");
    struct nc_albedo_map *map;
    if ((rc = nc_elevation_map_from_config(em, dry ? NULL : &map)) < 0 || dry)
        return rc < 0 ? rc : 0;
    rc = nc_mesh_globe(r, (int)sub, map, &b->mesh);
    nc_albedo_map_free(map);
    if (rc < 0)
        return nc__scene_error_at(em);
    b->bounding_radius_m = nc_mesh_bounding_radius(&b->mesh);
    nc_log_info("scene", "body '%s': globe of radius %g m with an elevation map, %zu triangles", b->name, r,
                b->mesh.nt);
    return 0;
}

int nc__scene_dem_from_config(struct nc_cfg_node *sh, int globe, struct nc_body *b, int dry)
{
    b->shape = NC_SHAPE_MESH;
    return globe ? globe_from_config(sh, b, dry) : dem_from_config(sh, b, dry);
}
