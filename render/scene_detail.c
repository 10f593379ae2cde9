/* scene_detail.c - a body's surface detail from its configuration
 * (docs/terrain.md): relief below its mesh's resolution (shape.relief),
 * craters carved into it (shape.craters), how the mesh is shaded
 * (shape.normals), boulders on it (boulders), and albedo variation
 * over ground and rocks (albedo_variation). Reads config nodes and
 * builds render/ data; no rendering here. */
#include "render/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/log.h"
#include "render/craters.h"

/* Detail needs a triangle mesh: a loaded one or the asteroid's. */

int nc__scene_error_at(const struct nc_cfg_node *n)
{
    char why[800];
    snprintf(why, sizeof why, "%s", nc_errmsg());
    return nc_cfg_error(n, "%s", why);
}

/* max_diameter_m not above min_diameter_m: the error names the key given
 * (max, else min: a --set of one names the --set), else the map. */
static int diameters_error(struct nc_cfg_node *map, double d_min_m, double d_max_m)
{
    struct nc_cfg_node *at = nc_cfg_get(map, "max_diameter_m");
    if (!at)
        at = nc_cfg_get(map, "min_diameter_m");
    return nc_cfg_error(at ? at : map, "max_diameter_m (%g) must exceed min_diameter_m (%g)", d_max_m, d_min_m);
}

/* `shape.craters` of a mesh or asteroid (nc__scene_detail_from_config
 * refuses it on other shapes): a mean count of the default population (a
 * number), or a map of its parameters. An asteroid without the key gets
 * 100. */
static int craters_from_config(struct nc_cfg_node *sh, struct nc_body *b, const double *dir, int dry)
{
    struct nc_cfg_node *node = nc_cfg_get(sh, "craters"), *map = NULL;
    if (!node && b->shape != NC_SHAPE_ASTEROID) {
        const struct nc_cfg_node *seed = nc_cfg_get(sh, "seed");
        return seed ? nc_cfg_error(seed, "a mesh's seed is its craters' (docs/config.md): give shape.craters too, "
                                         "or remove the seed")
                    : 0;
    }
    struct nc_crater_params p;
    nc_crater_params_default(&b->mesh, &p);
    double area_km2 = 1e-6 * nc_mesh_area_m2(&b->mesh), count = 100;
    long v;
    int rc;
    if ((rc = nc_cfg_seed(sh, "seed", &p.seed)) < 0)
        return rc;
    if (node && node->kind == NC_CFG_SCALAR) {
        if ((rc = nc_cfg_int(sh, "craters", 0, 10000000, &v)) < 0) /* as craters.count */
            return rc;
        count = (double)v;
    } else if (node) {
        if ((rc = nc_cfg_map(sh, "craters", &map)) < 0)
            return rc;
        int has_n, has_c, has_s, has_b;
        double sat = 0;
        if ((has_n = nc_cfg_double(map, "count", 0, 1e7, &count)) < 0 ||
            (has_c = nc_cfg_double(map, "density_per_km2", 0, 1e15, &p.c_per_km2)) < 0 ||
            (has_s = nc_cfg_double(map, "saturation", 0, 1, &sat)) < 0)
            return has_n < 0 ? has_n : has_c < 0 ? has_c : has_s;
        static const char *const selectors[] = {"count", "density_per_km2", "saturation", NULL};
        if (has_n + has_c + has_s == 0)
            return nc_cfg_missing_any(map, selectors, "give one of count (mean number), density_per_km2 (N(>1 m) "
                                                      "per km^2) or saturation (fraction of geometric saturation)");
        if (has_n + has_c + has_s != 1)
            return nc_cfg_error(map, "give one of count (mean number), density_per_km2 (N(>1 m) per km^2) or "
                                     "saturation (fraction of geometric saturation), not several");
        if (has_c || has_s)
            count = -1;
        if ((has_b = nc_cfg_double(map, "slope", 0.5, 6, &p.slope)) < 0)
            return has_b;
        if (has_s && has_b && p.slope != 2)
            return nc_cfg_key_error(map, "slope", "saturation implies slope 2");
        if (has_s) /* Gault (1970): geometric saturation N(>D) = 1.54 D^-2 per km^2, D in km */
            p.c_per_km2 = sat * 1.54e6;
        if ((rc = nc_cfg_double(map, "min_diameter_m", 1e-6, 1e7, &p.d_min_m)) < 0 ||
            (rc = nc_cfg_double(map, "max_diameter_m", 1e-6, 2e7, &p.d_max_m)) < 0 ||
            (rc = nc_cfg_double(map, "depth_ratio", 0, 1, &p.depth_ratio)) < 0 ||
            (rc = nc_cfg_double(map, "rim_ratio", 0, 1, &p.rim_ratio)) < 0 ||
            (rc = nc_cfg_double(map, "degradation", 0, 1, &p.degradation)) < 0 ||
            (rc = nc_cfg_seed(map, "seed", &p.seed)) < 0)
            return rc;
        if (dry) /* the diameters' defaults come from the mesh */
            return 0;
        if (!(p.d_max_m > p.d_min_m))
            return diameters_error(map, p.d_min_m, p.d_max_m);
    }
    if (dry)
        return 0;
    if (count >= 0)
        p.c_per_km2 = nc_craters_density_for(&p, area_km2, count);
    /* Against geometric saturation, 1.54e6 D^-2 per km^2 (D in m), at the
     * end of the diameters where the population comes closest to it: beyond
     * ten times it every crater only erases others, and carving them takes
     * minutes (2 million craters of 142 to 285 m on the default asteroid at
     * subdivisions 3, 5e4 times saturation: 6.5 min). */
    const double d_worst = p.slope > 2 ? p.d_min_m : p.d_max_m;
    const double sat_x = p.c_per_km2 * pow(d_worst, 2 - p.slope) / 1.54e6;
    if (node && sat_x > 10)
        return nc_cfg_error(node, "N(>D) = %.4g D^-%g per km^2 (D in m) is %.3g times geometric saturation (1.54e6 "
                            "D^-2) at D = %.3g m: at most 10 times (beyond it craters only erase each other; real "
                            "surfaces saturate at a few per cent of it): a smaller count, density_per_km2 or "
                            "saturation%s", p.c_per_km2, p.slope, sat_x, d_worst,
                            p.slope > 2 ? ", or a larger min_diameter_m"
                                        : p.slope < 2 ? ", or a smaller max_diameter_m" : "");
    struct nc_crater_field f;
    if ((rc = nc_craters_generate(&b->mesh, &p, NC_CRATERS_MAX, &f)) == 0)
        rc = nc_craters_apply(&f, &b->mesh, dir);
    if (rc < 0) {
        nc_craters_free(&f);
        return nc__scene_error_at(node ? node : sh);
    }
    if (f.n)
        nc_log_info("scene", "body '%s': %zu craters of %.3g to %.3g m (N(>1 m) = %.4g per km^2, slope %g, seed %llu), "
                    "%zu resolved by the mesh", b->name, f.n, p.d_min_m, p.d_max_m, p.c_per_km2, p.slope,
                    (unsigned long long)p.seed, f.applied);
    b->craters = f; /* kept: `navcam batch` lists the craters in view */
    b->bounding_radius_m = nc_mesh_bounding_radius(&b->mesh);
    return 0;
}

/* Rocks beyond this are a mistake in the density or the smallest diameter
 * (a million cost about 180 MB with the ray tracer's records and tree:
 * test_boulders). */
#define MAX_BOULDERS 16000000

/* `boulders:` of a body (docs/terrain.md): a preset or C and slope, the
 * diameter range, burial, shapes, the faces' roughness, seed. */
static int boulders_from_config(struct nc_cfg_node *item, struct nc_body *b, int dry)
{
    struct nc_cfg_node *map;
    int rc, has_c, has_slope;
    if ((rc = nc_cfg_map(item, "boulders", &map)) <= 0)
        return rc;
    if (!nc_body_is_mesh(b))
        return nc_cfg_key_error(item, "boulders", "boulders need a mesh or asteroid shape");
    struct nc_boulder_params p = {.d_min_m = 1, .d_max_m = 64, .burial_min = 0.1, .burial_max = 0.5, .shapes = 48,
                                  .seed = 1};
    const char *preset = NULL;
    double burial[2];
    long v;
    if ((rc = nc_cfg_string(map, "preset", &preset)) < 0)
        return rc;
    if (preset && nc_boulder_preset(preset, &p) < 0)
        return nc_cfg_key_error(map, "preset", "unknown preset '%s': bennu, ryugu or itokawa", preset);
    if ((has_c = nc_cfg_double(map, "density_per_km2", 0, 1e15, &p.c_per_km2)) < 0 ||
        (has_slope = nc_cfg_double(map, "slope", 0.5, 6, &p.slope)) < 0)
        return has_c < 0 ? has_c : has_slope;
    if (!preset && (!has_c || !has_slope))
        return nc_cfg_missing(map, has_c ? "slope" : "density_per_km2",
                              "a preset (bennu, ryugu, itokawa), or both density_per_km2 (N(>1 m) per km^2) and slope");
    if ((rc = nc_cfg_double(map, "min_diameter_m", 1e-6, 1e6, &p.d_min_m)) < 0 ||
        (rc = nc_cfg_double(map, "max_diameter_m", 1e-6, 2e6, &p.d_max_m)) < 0)
        return rc;
    if (!(p.d_max_m > p.d_min_m))
        return diameters_error(map, p.d_min_m, p.d_max_m);
    if ((rc = nc_cfg_doubles(map, "burial", burial, 2)) < 0)
        return rc;
    if (rc) {
        if (!(burial[0] >= 0 && burial[1] >= burial[0] && burial[1] <= 1))
            return nc_cfg_key_error(map, "burial",
                                    "expected [min, max] buried fractions of the extent along the normal, "
                                    "0 <= min <= max <= 1");
        p.burial_min = burial[0], p.burial_max = burial[1];
    }
    if ((rc = nc_cfg_int(map, "shapes", 1, NC_ROCK_SHAPES_MAX, &v)) < 0)
        return rc;
    if (rc)
        p.shapes = (int)v;
    if ((rc = nc_cfg_double(map, "roughness_deg", 0, 45, &p.roughness_deg)) < 0)
        return rc;
    if ((rc = nc_cfg_seed(map, "seed", &p.seed)) < 0 || dry)
        return rc;
    if ((rc = nc_boulders_generate(&b->mesh, &p, MAX_BOULDERS, &b->boulders)) < 0) {
        /* too many rocks: where the smallest diameter was given (a --set, say) */
        struct nc_cfg_node *at = rc == NC_ERANGE ? nc_cfg_get(map, "min_diameter_m") : NULL;
        return nc__scene_error_at(at ? at : map);
    }
    /* rocks standing out past the mesh's farthest vertex widen the body */
    b->bounding_radius_m = fmax(b->bounding_radius_m, nc_boulders_bounding_radius(&b->boulders));
    nc_log_info("scene", "body '%s': %zu boulders of %g to %g m (N(>1 m) = %.4g per km^2, slope %g, seed %llu)",
                b->name, b->boulders.n, p.d_min_m, p.d_max_m, p.c_per_km2, p.slope, (unsigned long long)p.seed);
    return 0;
}

/* `shape.relief` of a mesh or asteroid: fBm relief below its resolution;
 * *base_normals the normals under it (nc_mesh_relief), NULL without relief. */
static int relief_from_config(struct nc_cfg_node *sh, struct nc_body *b, double **base_normals, int dry)
{
    *base_normals = NULL;
    struct nc_cfg_node *map;
    int rc;
    if ((rc = nc_cfg_map(sh, "relief", &map)) <= 0)
        return rc;
    struct nc_relief_params p = {.hurst = 0.8, .amplitude = 1, .seed = 1};
    if ((rc = nc_cfg_double(map, "edge_m", 1e-6, 1e7, &p.edge_m)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "edge_m", "the mean edge length to subdivide down to, metres");
    if ((rc = nc_cfg_double(map, "hurst", 0.01, 0.99, &p.hurst)) < 0 ||
        (rc = nc_cfg_double(map, "amplitude", 0, 100, &p.amplitude)) < 0 ||
        (rc = nc_cfg_seed(map, "seed", &p.seed)) < 0 || dry)
        return rc;
    struct nc_relief_info info;
    if ((rc = nc_mesh_relief(&b->mesh, &p, NC_RELIEF_MAX_TRIANGLES, &info, base_normals)) < 0) {
        return nc__scene_error_at(map);
    }
    nc_log_info("scene", "body '%s': relief from mean edges of %.4g m down to %.4g m (%d subdivisions, %zu triangles; "
                "Hurst %g, s = %.4g m^%g measured on the mesh x %g)", b->name, info.model_edge_m, info.edge_m,
                info.levels, b->mesh.nt, p.hurst, info.s, 1 - p.hurst, p.amplitude);
    b->bounding_radius_m = nc_mesh_bounding_radius(&b->mesh);
    return 0;
}

/* `albedo_variation:` of a body with a mesh (docs/terrain.md). */
static int albedo_var_from_config(struct nc_cfg_node *item, struct nc_body *b, int dry)
{
    struct nc_cfg_node *map;
    int rc;
    if ((rc = nc_cfg_map(item, "albedo_variation", &map)) <= 0)
        return rc;
    if (!nc_body_is_mesh(b))
        return nc_cfg_key_error(item, "albedo_variation",
                                "albedo_variation needs a mesh or asteroid shape (an albedo map serves the others)");
    /* default largest wavelength: a tenth of the radius of the sphere of
     * the same area, and at least four times the shortest the mesh carries
     * (twice its mean edge: a small tile) */
    const double shortest_m = 2 * nc_mesh_mean_edge_m(&b->mesh);
    struct nc_albedo_var_params p = {.rms = 0.1, .largest_m = 0.1 * sqrt(nc_mesh_area_m2(&b->mesh) / (4 * M_PI)),
                                     .hurst = 0.5, .rocks_rms = -1, .seed = 1};
    p.largest_m = fmax(p.largest_m, 4 * shortest_m);
    int given;
    if ((rc = nc_cfg_double(map, "rms", 0, 2, &p.rms)) < 0 ||
        (rc = given = nc_cfg_double(map, "largest_m", 1e-6, 1e9, &p.largest_m)) < 0 ||
        (rc = nc_cfg_double(map, "hurst", 0, 1, &p.hurst)) < 0 ||
        (rc = nc_cfg_double(map, "rocks_rms", 0, 2, &p.rocks_rms)) < 0 || (rc = nc_cfg_seed(map, "seed", &p.seed)) < 0 ||
        dry)
        return rc;
    if (given && p.largest_m < shortest_m)
        return nc_cfg_key_error(map, "largest_m", "%g m is below the shortest wavelength the mesh carries "
                                "(twice its mean edge: %.4g m): raise it, or refine the mesh (shape.relief)",
                                p.largest_m, shortest_m);
    if (p.rocks_rms < 0)
        p.rocks_rms = p.rms;
    double smallest_m = 0;
    if (p.rms > 0 && (rc = nc_albedo_var_vertices(&b->mesh, &p, &b->albedo_vertex, &smallest_m)) < 0)
        return nc__scene_error_at(map);
    b->albedo_var = p;
    nc_log_info("scene", "body '%s': albedo variation, RMS %g on the ground (wavelengths %.4g to %.4g m, Hurst %g), "
                "%g per rock, seed %llu", b->name, p.rms, p.largest_m, smallest_m, p.hurst, p.rocks_rms,
                (unsigned long long)p.seed);
    return 0;
}

int nc__scene_detail_from_config(struct nc_cfg_node *item, struct nc_cfg_node *shape, struct nc_body *b, int dry)
{
    if (!nc_body_is_mesh(b)) { /* a sphere's detail keys are refused, not asked: its key list leaves them out */
        static const char *const mesh_only[][2] = {{"normals", "normals apply to mesh and asteroid shapes"},
                                                   {"relief", "relief needs a mesh or asteroid shape"},
                                                   {"craters", "craters need a mesh or asteroid shape"}};
        for (int i = 0; i < 3; i++)
            if (nc__cfg_find(shape, mesh_only[i][0]))
                return nc_cfg_key_error(shape, mesh_only[i][0], "%s", mesh_only[i][1]);
        const int rc = boulders_from_config(item, b, dry);
        return rc < 0 ? rc : albedo_var_from_config(item, b, dry);
    }
    static const char *const normals[] = {"flat", "smooth", NULL};
    int rc, smooth = 0;
    if ((rc = nc_cfg_enum(shape, "normals", normals, &smooth)) < 0)
        return rc;
    b->smooth_normals = smooth;
    /* Craters displace the relief along the surface under it, not along
     * its own rough normals (craters.h). */
    double *under = NULL;
    rc = relief_from_config(shape, b, &under, dry);
    if (rc >= 0)
        rc = craters_from_config(shape, b, under, dry);
    free(under);
    if (rc < 0)
        return rc;
    if ((rc = boulders_from_config(item, b, dry)) < 0)
        return rc;
    return albedo_var_from_config(item, b, dry);
}
