/* camera.h - pinhole camera geometry: intrinsics and pose.
 *
 * Camera frame: +Z boresight, +X right, +Y down in the image. Pixel centres
 * are at integer pixel coordinates (x, y), x to the right from the left column,
 * y down from the top row; the principal point (cx, cy) is in the same
 * coordinates, so a centred one is ((width-1)/2, (height-1)/2).
 * attitude_q rotates camera-frame vectors into the scene frame (vec.h).
 */
#ifndef NC_CAMERA_H
#define NC_CAMERA_H

#include "config.h"
#include "vec.h"

struct nc_camera {
    int width_px, height_px;
    double fx_px, fy_px, cx_px, cy_px;
    struct nc_vec3 position_m; /* scene frame */
    struct nc_quat attitude_q; /* camera -> scene */
};

/* Unnormalised direction, camera frame, through pixel coordinates (x, y). */
static inline struct nc_vec3 nc_camera_dir(const struct nc_camera *c, double x, double y)
{
    return nc_v3((x - c->cx_px) / c->fx_px, (y - c->cy_px) / c->fy_px, 1.0);
}

/* Read the "camera" section. */
int nc_camera_from_config(struct nc_cfg_node *map, struct nc_camera *c);

#endif
