/* camsys_io.c - loading a camera model with its scene, and its metadata. */
#include <stdio.h>
#include <string.h>

#include "camera/load.h"
#include "core/error.h"

int nc_setup_load(const char *path, const char *const *sets, int nsets, struct nc_scene *s, struct nc_camsys *cs)
{
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    int rc = nc_cfg_load_scene(&cfg, path, sets, nsets), have_cs = 0;
    if (rc >= 0 && (rc = nc_scene_read_view(&cfg, s)) >= 0) {
        /* The emulator's sections, and the stars (nc_sky_load reads them). */
        static const char *const serve_sections[] = {"serve", "outputs", "stars"};
        for (int i = 0; i < 3; i++) {
            struct nc_cfg_node *n = nc_cfg_get(cfg.root, serve_sections[i]);
            if (n)
                nc_cfg_mark_used(n);
        }
        /* The camera model's sections, checked before the bodies are built. */
        if ((rc = nc_camsys_from_config(cfg.root, &s->camera, s->camera.focal_length_m, cs)) >= 0) {
            have_cs = 1;
            rc = nc_camsys_check_sections(&cfg);
        }
        if (rc >= 0)
            rc = nc_scene_check_sections(&cfg);
        if (rc >= 0)
            rc = nc_scene_read_bodies(&cfg, s);
        if (rc >= 0)
            rc = nc_cfg_check_unused(&cfg);
        if (rc < 0 && have_cs)
            nc_camsys_free(cs);
        if (rc < 0)
            nc_scene_free(s);
    }
    nc_cfg_free(&cfg);
    return rc;
}

int nc_sky_load(const char *path, const char *const *sets, int nsets, struct nc_sky *sky)
{
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    int rc = nc_cfg_load_scene(&cfg, path, sets, nsets);
    if (rc >= 0)
        rc = nc_sky_from_config(&cfg, sky);
    nc_cfg_free(&cfg);
    return rc;
}

int nc_camsys_load(const char *path, const char *const *sets, int nsets, struct nc_camera *geom, struct nc_camsys *cs)
{
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    /* as a scene file is read (`base: builtin:default` laid under it), for a whole scene works too */
    int rc = path ? nc_cfg_load_scene(&cfg, path, sets, nsets)
                  : nc_error(NC_EUSAGE, "a camera configuration file is needed");
    struct nc_cfg_node *cam = NULL;
    if (rc >= 0 && (rc = nc_cfg_map(cfg.root, "camera", &cam)) == 0)
        rc = nc_cfg_missing(cfg.root, "camera", "a map with width_px, height_px and focal length and pitch");
    if (rc >= 0)
        rc = nc_camera_intrinsics_from_config(cam, geom);
    if (rc >= 0) {
        /* Parts of a scene file that a camera alone does not use. */
        static const char *const ignore_top[] = {"bodies", "sun", "render", "serve", "outputs", "stars"};
        static const char *const ignore_cam[] = {"position_m", "attitude_q", "look_at_m", "up", "velocity_m_s",
                                                 "angular_velocity_rad_s"};
        for (size_t i = 0; i < sizeof ignore_top / sizeof ignore_top[0]; i++) {
            struct nc_cfg_node *n = nc_cfg_get(cfg.root, ignore_top[i]);
            if (n)
                nc_cfg_mark_used(n);
        }
        for (size_t i = 0; i < sizeof ignore_cam / sizeof ignore_cam[0]; i++) {
            struct nc_cfg_node *n = nc_cfg_get(cam, ignore_cam[i]);
            if (n)
                nc_cfg_mark_used(n);
        }
        rc = nc_camsys_from_config(cfg.root, geom, geom->focal_length_m, cs);
        if (rc >= 0 && (rc = nc_cfg_check_unused(&cfg)) < 0)
            nc_camsys_free(cs);
    }
    nc_cfg_free(&cfg);
    return rc;
}

int nc_camsys_meta(const struct nc_camsys *cs, double exposure_s, uint64_t frame, struct nc_image_attr *attrs,
                   char (*v)[200], int max)
{
    if (max < 6)
        return 0;
    const struct nc_sensor *s = &cs->sensor;
    snprintf(v[0], 200, "%d", s->adc_bits);
    snprintf(v[1], 200, "%.17g", s->gain_e_per_dn);
    snprintf(v[2], 200, "%.17g", s->analog_gain_db);
    snprintf(v[3], 200, "%.17g", s->bias_dn);
    snprintf(v[4], 200, "%.17g", exposure_s);
    snprintf(v[5], 200, "%llu", (unsigned long long)frame);
    const struct nc_image_attr a[] = {
        {"navcam:adc_bits", v[0]},    {"navcam:gain_e_per_dn", v[1]}, {"navcam:analog_gain_db", v[2]},
        {"navcam:bias_dn", v[3]},     {"navcam:exposure_s", v[4]},    {"navcam:frame", v[5]},
    };
    memcpy(attrs, a, sizeof a);
    return 6;
}
