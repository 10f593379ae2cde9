/* scene.c - building a scene from configuration, and the built-in default. */
#include "render/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/log.h"

const char nc_default_scene_yaml[] =
    "# NavCam built-in default scene: a procedural cratered asteroid about 500 m\n"
    "# across, seen by a narrow-angle navigation camera 6 km away at 40 deg phase,\n"
    "# with the Hapke 2012 regolith parameters of comet 67P (Davidsson et al. 2022).\n"
    "bodies:\n"
    "  - name: asteroid\n"
    "    shape:\n"
    "      type: asteroid\n"
    "      radii_m: [280, 230, 200]\n"
    "      subdivisions: 7\n"
    "      seed: 7\n"
    "      craters: {saturation: 0.05}   # 5 % of geometric saturation, slope 2\n"
    "      lump_amplitude: 0.08\n"
    "    material:\n"
    "      preset: comet_67p\n"
    "    position_m: [0, 0, 0]\n"
    "    attitude_q: [1, 0, 0, 0]\n"
    "sun:\n"
    "  direction: [0.643, -0.766, 0.0]\n"
    "  distance_au: 1.2\n"
    "camera:\n"
    "  width_px: 1024\n"
    "  height_px: 1024\n"
    "  focal_length_m: 0.025\n"
    "  pixel_pitch_m: 5.5e-6\n"
    "  position_m: [0, -6000, 0]\n"
    "  look_at_m: [0, 0, 0]\n"
    "  up: [0, 0, 1]\n"
    "render:\n"
    "  samples_per_pixel: 4\n"
    "  seed: 1\n"
    "# A generic 1024x1024 navigation camera (configs/examples/navcam_camera.yaml\n"
    "# explains each value): f/4 optics, 5.5 um pixels, 12-bit ADC.\n"
    "optics:\n"
    "  f_number: 4.0\n"
    "  transmission: 0.9\n"
    "  passband: {from_m: 5.0e-7, to_m: 7.0e-7}    # a 500-700 nm filter through the 5772 K Sun\n"
    "  vignetting: cos4\n"
    "  psf: {type: gaussian, sigma_px: 0.7}\n"
    "sensor:\n"
    "  qe: 0.6\n"
    "  dark_current_e_s: 20\n"
    "  dark_ref_temp_k: 293.15\n"
    "  dark_doubling_k: 6.5\n"
    "  temperature_k: 283.15\n"
    "  dsnu_e_s: 2\n"
    "  prnu: 0.01\n"
    "  read_noise_e: 8\n"
    "  full_well_e: 20000\n"
    "  gain_e_per_dn: 5.0\n"
    "  bias_dn: 64\n"
    "  adc_bits: 12\n"
    "  seed: 1\n"
    "exposure:\n"
    "  time_s: 0.002\n";

static const char *const shape_names[] = {"sphere", "ellipsoid", "mesh", "asteroid", "dem", "globe", NULL};

/* dry: the keys read and checked, nothing loaded or built */
static int shape_from_config(struct nc_cfg_node *sh, struct nc_body *b, int dry)
{
    int type = 0, rc;
    if ((rc = nc_cfg_enum(sh, "type", shape_names, &type)) <= 0)
        return rc ? rc : nc_cfg_missing(sh, "type", "sphere, ellipsoid, mesh, asteroid, dem or globe");
    if (type >= 4) /* dem, globe: meshes from elevation data */
        return nc__scene_dem_from_config(sh, type == 5, b, dry);
    b->shape = (enum nc_shape_type)type;
    switch (b->shape) {
    case NC_SHAPE_SPHERE: {
        double r;
        if ((rc = nc_cfg_double(sh, "radius_m", 1e-6, 1e10, &r)) <= 0)
            return rc ? rc : nc_cfg_missing(sh, "radius_m", "sphere radius in metres");
        b->radii_m = nc_v3(r, r, r);
        b->bounding_radius_m = r;
        return 0;
    }
    case NC_SHAPE_ELLIPSOID:
    case NC_SHAPE_ASTEROID: {
        double r[3];
        if ((rc = nc_cfg_doubles(sh, "radii_m", r, 3)) <= 0)
            return rc ? rc : nc_cfg_missing(sh, "radii_m", "[a, b, c] semi-axes in metres");
        for (int i = 0; i < 3; i++)
            if (!(r[i] >= 1e-6 && r[i] <= 1e10))
                return nc_cfg_key_error(sh, "radii_m", "semi-axes must be in [1e-6, 1e10] m");
        b->radii_m = nc_v3(r[0], r[1], r[2]);
        b->bounding_radius_m = fmax(r[0], fmax(r[1], r[2]));
        if (b->shape == NC_SHAPE_ELLIPSOID)
            return 0;
        /* craters come after (scene_detail.c) */
        struct nc_asteroid_params ap = {.radii_m = b->radii_m, .subdivisions = 6, .seed = 1, .craters = 0,
                                        .lump_amplitude = 0.08};
        long v;
        if ((rc = nc_cfg_int(sh, "subdivisions", 0, 9, &v)) < 0)
            return rc;
        if (rc)
            ap.subdivisions = (int)v;
        if ((rc = nc_cfg_seed(sh, "seed", &ap.seed)) < 0)
            return rc;
        if ((rc = nc_cfg_double(sh, "lump_amplitude", 0, 0.5, &ap.lump_amplitude)) < 0 || dry)
            return rc < 0 ? rc : 0;
        if ((rc = nc_mesh_asteroid(&ap, &b->mesh)) < 0)
            return rc;
        b->bounding_radius_m = nc_mesh_bounding_radius(&b->mesh);
        return 0;
    }
    case NC_SHAPE_MESH: {
        static const char *const units[] = {"m", "km", NULL};
        const char *file;
        int unit = 0;
        double scale = 1;
        if ((rc = nc_cfg_string(sh, "file", &file)) <= 0)
            return rc ? rc : nc_cfg_missing(sh, "file", "path of an OBJ or PLY mesh");
        if ((rc = nc_cfg_enum(sh, "unit", units, &unit)) <= 0)
            return rc ? rc : nc_cfg_missing(sh, "unit", "the mesh's length unit: m or km");
        if ((rc = nc_cfg_double(sh, "scale", 1e-9, 1e9, &scale)) < 0 || dry)
            return rc < 0 ? rc : 0;
        char path[4096];
        nc_cfg_resolve_path(nc_cfg_get(sh, "file"), file, path, sizeof path);
        if ((rc = nc_mesh_load(path, scale * (unit ? 1000.0 : 1.0), &b->mesh)) < 0)
            return nc__scene_error_at(nc_cfg_get(sh, "file"));
        b->bounding_radius_m = nc_mesh_bounding_radius(&b->mesh);
        return 0;
    }
    }
    return 0;
}

/* A body's name, material and pose, and every key of its shape and surface
 * detail read and checked with nothing built (a dry pass on a copy): then
 * a mistake anywhere in it, an unknown key included, is reported before
 * the seconds its build can take. */
static int body_read(struct nc_cfg *cfg, struct nc_cfg_node *item, int index, struct nc_body *b)
{
    int rc;
    item->used = 1;
    if (item->kind != NC_CFG_MAP)
        return nc_cfg_error(item, "expected a map describing a body (shape, material, pose)");
    const char *name = NULL;
    if ((rc = nc_cfg_string(item, "name", &name)) < 0)
        return rc;
    snprintf(b->name, sizeof b->name, "%s", name ? name : "");
    if (!name)
        snprintf(b->name, sizeof b->name, "body%d", index);
    struct nc_cfg_node *sh, *mat;
    if ((rc = nc_cfg_map(item, "shape", &sh)) <= 0)
        return rc ? rc : nc_cfg_missing(item, "shape", "a map with 'type'");
    struct nc_body dry = *b;
    if ((rc = shape_from_config(sh, &dry, 1)) < 0 || (rc = nc__scene_detail_from_config(item, sh, &dry, 1)) < 0)
        return rc;
    if ((rc = nc_cfg_map(item, "material", &mat)) <= 0)
        return rc ? rc : nc_cfg_missing(item, "material", "a map with model (or preset) and parameters");
    if ((rc = nc_material_from_config(mat, &b->material)) < 0)
        return rc;
    b->position_m = nc_v3(0, 0, 0);
    b->attitude_q = (struct nc_quat){1, 0, 0, 0};
    if ((rc = nc_cfg_vec3_max(item, "position_m", NC_CAMERA_MAX_M, "m from the scene's origin", NC_CAMERA_MAX_TEXT,
                              &b->position_m)) < 0 ||
        (rc = nc_cfg_quat(item, "attitude_q", &b->attitude_q)) < 0 ||
        (rc = nc_cfg_vec3_max(item, "velocity_m_s", NC_SPEED_MAX_M_S, "m/s", NC_SPEED_MAX_TEXT,
                              &b->velocity_m_s)) < 0 ||
        (rc = nc_cfg_vec3(item, "angular_velocity_rad_s", &b->angular_velocity_rad_s)) < 0)
        return rc;
    return nc_cfg_check_unused_in(cfg, item);
}

/* The body's shape and surface detail, built (body_read first). */
static int body_build(struct nc_cfg_node *item, struct nc_body *b)
{
    struct nc_cfg_node *sh = nc_cfg_get(item, "shape");
    int rc = nc_material_load_albedo_map(nc_cfg_get(item, "material"), &b->material);
    if (rc >= 0)
        rc = shape_from_config(sh, b, 0);
    return rc < 0 ? rc : nc__scene_detail_from_config(item, sh, b, 0);
}

/* sum_dir: the camera's SUM file gives the direction (NULL: it does not). */
static int sun_from_config(struct nc_cfg_node *map, struct nc_sun *sun, const struct nc_vec3 *sum_dir)
{
    int rc, hd, hp, hdist;
    double dist_au = 1.0;
    if ((hd = nc_cfg_vec3(map, "direction", &sun->direction)) < 0)
        return hd;
    if (sum_dir && hd)
        return nc_cfg_key_error(map, "direction", "camera.sumfile gives the Sun's direction (SZ): remove "
                                                  "sun.direction");
    if ((hp = nc_cfg_vec3(map, "position_m", &sun->position_m)) < 0)
        return hp;
    if (sum_dir && hp)
        return nc_cfg_key_error(map, "position_m", "camera.sumfile gives the Sun's direction (SZ): give "
                                                   "sun.distance_au or sun.irradiance_w_m2 instead of "
                                                   "sun.position_m");
    if ((hdist = nc_cfg_double(map, "distance_au", 0.005, 1e4, &dist_au)) < 0) /* beyond the Sun's radius */
        return hdist;
    if ((rc = nc_cfg_double(map, "irradiance_w_m2", 0, 1e9, &sun->irradiance_w_m2)) < 0)
        return rc;
    sun->irradiance_override = rc;
    if (hd && hp)
        return nc_cfg_key_error(map, "position_m", "give either direction or position_m, not both");
    if (sum_dir && !hdist && !sun->irradiance_override)
        return nc_cfg_missing(map, "distance_au", "the heliocentric distance in au (camera.sumfile gives the Sun's "
                                                  "direction only)");
    if (sum_dir) {
        sun->direction = *sum_dir;
        hd = 1;
    }
    if (!hd && !hp)
        return nc_cfg_missing(map, "direction", "a vector toward the Sun in the body-fixed frame, or position_m");
    if (hp && hdist)
        return nc_cfg_key_error(map, "distance_au", "distance_au goes with direction; position_m sets the distance");
    double d_m;
    if (hd) {
        if (nc_v3_is_zero(sun->direction))
            return nc_cfg_key_error(map, "direction", "the Sun direction must not be zero");
        sun->direction = nc_v3_unit(sun->direction);
        d_m = dist_au * NC_AU_M;
    } else {
        d_m = nc_v3_norm(sun->position_m);
        if (!(d_m > NC_SUN_RADIUS_M))
            return nc_cfg_key_error(map, "position_m", "the Sun's centre lies %.4g m from bodies[0]'s origin, within "
                                    "its own radius (%.4g m)", d_m, NC_SUN_RADIUS_M);
        sun->has_position = 1;
    }
    sun->distance_m = d_m;
    if (!sun->irradiance_override)
        sun->irradiance_w_m2 = NC_SOLAR_CONSTANT_W_M2 * (NC_AU_M / d_m) * (NC_AU_M / d_m);
    return 0;
}

static int render_from_config(struct nc_cfg_node *map, struct nc_render_settings *r)
{
    long v;
    int rc;
    r->samples_per_pixel = 1;
    r->seed = 0;
    r->threads = 0;
    r->lod_error_px = 0;
    r->boulder_min_px = -1;
    r->boulder_fold = 1;
    r->boulder_mesh_px = 64;
    r->soft_shadows = 0;
    r->bounces = 0;
    r->roulette_after = 2;
    r->quality_auto = 0;
    r->auto_noise_fraction = 0.25;
    if (!map)
        return 0;
    if ((rc = nc_cfg_int(map, "samples_per_pixel", 1, 1024, &v)) < 0)
        return rc;
    if (rc) {
        long s = lround(sqrt((double)v));
        if (s * s != v)
            return nc_cfg_key_error(map, "samples_per_pixel",
                                    "expected a square number (1, 4, 9, 16, ...) for n x n stratified samples, "
                                    "got %ld", v);
        r->samples_per_pixel = (int)v;
    }
    if ((rc = nc_cfg_seed(map, "seed", &r->seed)) < 0)
        return rc;
    if ((rc = nc_cfg_int(map, "threads", 0, 1024, &v)) < 0)
        return rc;
    if (rc)
        r->threads = (int)v;
    if ((rc = nc_cfg_double(map, "lod_error_px", 0, 100, &r->lod_error_px)) < 0)
        return rc;
    if ((rc = nc_cfg_double(map, "boulder_min_px", 0, 1000, &r->boulder_min_px)) < 0 ||
        (rc = nc_cfg_double(map, "boulder_mesh_px", 0, 100000, &r->boulder_mesh_px)) < 0)
        return rc;
    static const char *const bools[] = {"false", "true", NULL};
    if ((rc = nc_cfg_enum(map, "boulder_fold", bools, &r->boulder_fold)) < 0 ||
        (rc = nc_cfg_enum(map, "soft_shadows", bools, &r->soft_shadows)) < 0)
        return rc;
    if ((rc = nc_cfg_int(map, "bounces", 0, 64, &v)) < 0)
        return rc;
    if (rc)
        r->bounces = (int)v;
    if ((rc = nc_cfg_int(map, "roulette_after", 0, 64, &v)) < 0)
        return rc;
    if (rc)
        r->roulette_after = (int)v;
    static const char *const qualities[] = {"manual", "auto", NULL};
    if ((rc = nc_cfg_enum(map, "quality", qualities, &r->quality_auto)) < 0 ||
        (rc = nc_cfg_double(map, "auto_noise_fraction", 0.01, 10, &r->auto_noise_fraction)) < 0)
        return rc;
    return 0;
}

int nc_scene_from_config(struct nc_cfg *cfg, struct nc_scene *s)
{
    int rc = nc_scene_read(cfg, s);
    if (rc >= 0 && (rc = nc_cfg_check_unused(cfg)) < 0)
        nc_scene_free(s);
    return rc;
}

int nc_scene_read_view(struct nc_cfg *cfg, struct nc_scene *s)
{
    memset(s, 0, sizeof *s);
    struct nc_cfg_node *root = cfg->root, *sun, *cam, *rnd = NULL;
    int rc;
    if (!root)
        return nc_error(NC_ECONFIG, "empty configuration");
    if ((rc = nc_cfg_map(root, "camera", &cam)) <= 0)
        return rc ? rc : nc_cfg_missing(root, "camera", "a map with pose and intrinsics");
    if ((rc = nc_camera_from_config(cam, &s->camera)) < 0 || (rc = nc_cfg_check_unused_in(cfg, cam)) < 0)
        return rc;
    if ((rc = nc_cfg_map(root, "sun", &sun)) <= 0)
        return rc ? rc
                  : nc_cfg_missing(root, "sun", s->camera.from_sumfile ? "a map with distance_au (the SUM file gives "
                                                                         "the direction)"
                                                                       : "a map with direction or position_m");
    if ((rc = sun_from_config(sun, &s->sun, s->camera.from_sumfile ? &s->camera.sumfile_sun : NULL)) < 0 ||
        (rc = nc_cfg_check_unused_in(cfg, sun)) < 0)
        return rc;
    if ((rc = nc_cfg_map(root, "render", &rnd)) < 0 || (rc = render_from_config(rnd, &s->render)) < 0 ||
        (rc = nc_cfg_check_unused_in(cfg, rnd)) < 0)
        return rc;
    return 0;
}

int nc_scene_read_bodies(struct nc_cfg *cfg, struct nc_scene *s)
{
    struct nc_cfg_node *bodies;
    int rc;
    if ((rc = nc_cfg_seq(cfg->root, "bodies", &bodies)) <= 0)
        return rc ? rc : nc_cfg_missing(cfg->root, "bodies", "a list of bodies");
    if (bodies->nchild == 0 || bodies->nchild > NC_MAX_BODIES)
        return nc_cfg_error(bodies, "expected 1 to %d bodies, got %zu", NC_MAX_BODIES, bodies->nchild);
    for (size_t i = 0; i < bodies->nchild; i++) {
        s->nbodies = (int)i + 1;
        if ((rc = body_read(cfg, bodies->child[i], (int)i, &s->body[i])) < 0) {
            nc_scene_free(s);
            return rc;
        }
    }
    for (size_t i = 0; i < bodies->nchild; i++)
        if ((rc = body_build(bodies->child[i], &s->body[i])) < 0) {
            nc_scene_free(s);
            return rc;
        }
    if (s->camera.from_sumfile) { /* its pose is in bodies[0]'s body-fixed frame */
        const struct nc_body *b0 = &s->body[0];
        s->camera.position_m = nc_v3_add(b0->position_m, nc_quat_rotate(b0->attitude_q, s->camera.position_m));
        s->camera.attitude_q = nc_quat_mul(b0->attitude_q, s->camera.attitude_q);
    }
    return 0;
}

int nc_scene_check_sections(struct nc_cfg *cfg)
{
    nc_cfg_get(cfg->root, "bodies"); /* read next */
    return nc_cfg_check_unused_keys(cfg, cfg->root);
}

int nc_scene_read(struct nc_cfg *cfg, struct nc_scene *s)
{
    int rc = nc_scene_read_view(cfg, s);
    return rc < 0 ? rc : nc_scene_read_bodies(cfg, s);
}

int nc_cfg_load_scene(struct nc_cfg *cfg, const char *path, const char *const *sets, int nsets)
{
    int rc = path ? nc_cfg_load_file(cfg, path) : nc_cfg_load_string(cfg, nc_default_scene_yaml, "<built-in default scene>");
    /* `base: builtin:default`: this file is laid over the built-in default
     * scene (maps merge, anything else replaces). */
    const char *base = NULL;
    if (rc >= 0 && path && cfg->root && cfg->root->kind == NC_CFG_MAP &&
        (rc = nc_cfg_string(cfg->root, "base", &base)) > 0) {
        if (strcmp(base, "builtin:default"))
            return nc_cfg_key_error(cfg->root, "base", "unknown base '%s' (known: builtin:default)", base);
        struct nc_cfg def;
        nc_cfg_init(&def);
        if ((rc = nc_cfg_load_string(&def, nc_default_scene_yaml, "<built-in default scene>")) >= 0 &&
            (rc = nc_cfg_overlay(&def, cfg)) >= 0) {
            *cfg = def;
        } else {
            nc_cfg_free(&def);
        }
    }
    for (int i = 0; rc >= 0 && i < nsets; i++) {
        if (!strncmp(sets[i], "base=", 5) || !strncmp(sets[i], "base.", 5)) /* too late: the file is laid already */
            return nc_error(NC_EUSAGE, "--set %s: base is a scene file's key (base: builtin:default lays the file "
                                       "over the built-in default scene; docs/config.md), not a --set one",
                            sets[i]);
        rc = nc_cfg_set(cfg, sets[i]);
    }
    return rc;
}

int nc_scene_load(const char *path, const char *const *sets, int nsets, struct nc_scene *s)
{
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    int rc = nc_cfg_load_scene(&cfg, path, sets, nsets);
    if (rc >= 0)
        rc = nc_scene_from_config(&cfg, s);
    nc_cfg_free(&cfg);
    return rc;
}

void nc_scene_free(struct nc_scene *s)
{
    for (int i = 0; i < s->nbodies; i++) {
        nc_mesh_free(&s->body[i].mesh);
        nc_boulders_free(&s->body[i].boulders);
        nc_craters_free(&s->body[i].craters);
        free(s->body[i].albedo_vertex);
        s->body[i].albedo_vertex = NULL;
        nc_material_free(&s->body[i].material);
    }
    s->nbodies = 0;
}

/* A Sun given by its position (bodies[0]'s frame, from its origin): where it
 * is in the scene. */
static struct nc_vec3 sun_in_scene(const struct nc_scene *s)
{
    const struct nc_body *b0 = &s->body[0];
    return nc_v3_add(nc_quat_rotate(b0->attitude_q, s->sun.position_m), b0->position_m);
}

void nc_scene_sun_at(const struct nc_scene *s, struct nc_vec3 p, struct nc_vec3 *dir, double *irradiance_w_m2)
{
    if (!s->sun.has_position) {
        *dir = nc_quat_rotate(s->body[0].attitude_q, s->sun.direction);
        *irradiance_w_m2 = s->sun.irradiance_w_m2;
        return;
    }
    struct nc_vec3 d = nc_v3_sub(sun_in_scene(s), p);
    double r = nc_v3_norm(d), r0 = nc_v3_norm(s->sun.position_m);
    *dir = nc_v3_scale(d, 1.0 / r);
    *irradiance_w_m2 = s->sun.irradiance_w_m2 * (r0 / r) * (r0 / r);
}

struct nc_quat nc_quat_propagate(struct nc_quat q, struct nc_vec3 w, double dt)
{
    double a = nc_v3_norm(w) * dt;
    if (a == 0)
        return q;
    struct nc_vec3 axis = nc_v3_unit(w);
    double sh = sin(0.5 * a);
    struct nc_quat d = {cos(0.5 * a), axis.x * sh, axis.y * sh, axis.z * sh};
    struct nc_quat r = nc_quat_mul(q, d); /* rate in the body's own frame: right product */
    double n = nc_quat_norm(r);
    return (struct nc_quat){r.w / n, r.x / n, r.y / n, r.z / n};
}

void nc_scene_propagate(const struct nc_scene *s, double dt, struct nc_scene *out)
{
    *out = *s;
    struct nc_camera *c = &out->camera;
    c->position_m = nc_v3_add(c->position_m, nc_v3_scale(c->velocity_m_s, dt));
    c->attitude_q = nc_quat_propagate(c->attitude_q, c->angular_velocity_rad_s, dt);
    for (int i = 0; i < out->nbodies; i++) {
        struct nc_body *b = &out->body[i];
        b->position_m = nc_v3_add(b->position_m, nc_v3_scale(b->velocity_m_s, dt));
        b->attitude_q = nc_quat_propagate(b->attitude_q, b->angular_velocity_rad_s, dt);
    }
}

double nc_scene_boulder_min_px(const struct nc_scene *s, int b)
{
    if (s->render.boulder_min_px >= 0)
        return s->render.boulder_min_px;
    return s->render.boulder_fold && nc_material_roughness_param(&s->body[b].material) >= 0 ? 1.0 : 0.0;
}

static double sun_radius(double d) { return d > NC_SUN_RADIUS_M ? asin(NC_SUN_RADIUS_M / d) : M_PI / 2; }

double nc_scene_sun_radius_rad(const struct nc_scene *s)
{
    return sun_radius(s->sun.has_position ? nc_v3_norm(s->sun.position_m) : s->sun.distance_m);
}

double nc_scene_sun_radius_from(const struct nc_scene *s, struct nc_vec3 p)
{
    return sun_radius(s->sun.has_position ? nc_v3_norm(nc_v3_sub(sun_in_scene(s), p)) : s->sun.distance_m);
}
