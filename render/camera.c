/* camera.c - reading the camera section of a scene configuration. */
#include "camera.h"

#include <stdio.h>

#include "error.h"

int nc_camera_from_config(struct nc_cfg_node *map, struct nc_camera *c)
{
    int rc;
    long w = 0, h = 0;
    if ((rc = nc_cfg_int(map, "width_px", 1, 16384, &w)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "width_px", "image width in pixels");
    if ((rc = nc_cfg_int(map, "height_px", 1, 16384, &h)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "height_px", "image height in pixels");
    c->width_px = (int)w;
    c->height_px = (int)h;

    double f = 0, pitch = 0, fx = 0, fy = 0;
    int hf, hp, hfx, hfy;
    if ((hf = nc_cfg_double(map, "focal_length_m", 1e-6, 100, &f)) < 0 ||
        (hp = nc_cfg_double(map, "pixel_pitch_m", 1e-8, 1e-2, &pitch)) < 0 ||
        (hfx = nc_cfg_double(map, "fx_px", 1e-3, 1e9, &fx)) < 0 ||
        (hfy = nc_cfg_double(map, "fy_px", 1e-3, 1e9, &fy)) < 0)
        return hf < 0 ? hf : hp < 0 ? hp : hfx < 0 ? hfx : hfy;
    if ((hf || hp) && (hfx || hfy))
        return nc_cfg_error(nc_cfg_get(map, hf ? "focal_length_m" : "pixel_pitch_m"),
                            "give either focal_length_m and pixel_pitch_m, or fx_px and fy_px, not both");
    if (hf || hp) {
        if (!hf || !hp)
            return nc_cfg_missing(map, hf ? "pixel_pitch_m" : "focal_length_m",
                                  "focal_length_m and pixel_pitch_m together (metres)");
        c->fx_px = c->fy_px = f / pitch;
    } else if (hfx || hfy) {
        if (!hfx || !hfy)
            return nc_cfg_missing(map, hfx ? "fy_px" : "fx_px", "fx_px and fy_px together (pixels)");
        c->fx_px = fx;
        c->fy_px = fy;
    } else {
        return nc_cfg_missing(map, "focal_length_m", "focal_length_m and pixel_pitch_m, or fx_px and fy_px");
    }
    c->cx_px = 0.5 * (c->width_px - 1);
    c->cy_px = 0.5 * (c->height_px - 1);
    if ((rc = nc_cfg_double(map, "cx_px", -1e6, 1e6, &c->cx_px)) < 0 ||
        (rc = nc_cfg_double(map, "cy_px", -1e6, 1e6, &c->cy_px)) < 0)
        return rc;

    if ((rc = nc_cfg_vec3(map, "position_m", &c->position_m)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "position_m", "[x, y, z] in metres, scene frame");
    struct nc_vec3 target, up = nc_v3(0, 0, 1);
    int hq = nc_cfg_quat(map, "attitude_q", &c->attitude_q);
    int ht = nc_cfg_vec3(map, "look_at_m", &target);
    int hu = nc_cfg_vec3(map, "up", &up);
    if (hq < 0 || ht < 0 || hu < 0)
        return hq < 0 ? hq : ht < 0 ? ht : hu;
    if (hq && ht)
        return nc_cfg_error(nc_cfg_get(map, "look_at_m"), "give either attitude_q or look_at_m, not both");
    if (hu && !ht)
        return nc_cfg_error(nc_cfg_get(map, "up"), "'up' only goes with look_at_m");
    if (ht) {
        if ((rc = nc_quat_look_at(c->position_m, target, up, &c->attitude_q)) < 0) {
            char why[256];
            snprintf(why, sizeof why, "%s", nc_errmsg());
            return nc_cfg_error(nc_cfg_get(map, "look_at_m"), "%s", why);
        }
    } else if (!hq) {
        return nc_cfg_missing(map, "attitude_q", "[w, x, y, z] camera-to-scene, or look_at_m");
    }
    return 0;
}
