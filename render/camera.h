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

#include <math.h>

#include "core/config.h"
#include "core/vec.h"

struct nc_camera {
    int width_px, height_px;
    double fx_px, fy_px, cx_px, cy_px;
    /* Brown-Conrady distortion on normalised coordinates (x, y) = (X/Z, Y/Z):
     * r^2 = x^2 + y^2,
     * x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2),
     * y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y,
     * pixel = (fx x_d + cx, fy y_d + cy) (the OpenCV convention). */
    double k1, k2, k3, p1, p2;
    int distorted;
    double focal_length_m; /* 0 when the camera is given by fx_px/fy_px */
    struct nc_vec3 position_m; /* scene frame */
    struct nc_quat attitude_q; /* camera -> scene */
    struct nc_vec3 velocity_m_s;         /* scene frame */
    struct nc_vec3 angular_velocity_rad_s; /* camera frame (as gyros report) */
    /* The image as stored is the rendered view mirrored top to bottom
     * (flip_rows) and/or left to right (flip_cols): a SUM file's pixel grid
     * with K22 < 0 or K11 < 0 (docs/sumfiles.md). Writers apply it. */
    int flip_rows, flip_cols;
    /* The camera model's margin around the sensor's image (a PSF's half
     * size, pixels on every side: nc_camsys_render_camera), 0 without one:
     * the render keys its samples to the sensor's pixels, so a margin
     * changes no sample of theirs. */
    int margin_px;
    /* camera.sumfile: the SUM file's Sun direction (body-fixed, unit) and
     * picture time; from_sumfile 0 otherwise. */
    int from_sumfile;
    struct nc_vec3 sumfile_sun;
    char sumfile_utc[64];
};

/* Unnormalised direction, camera frame, through pixel coordinates (x, y) of
 * the undistorted pinhole (no lens distortion applied). */
static inline struct nc_vec3 nc_camera_dir(const struct nc_camera *c, double x, double y)
{
    return nc_v3((x - c->cx_px) / c->fx_px, (y - c->cy_px) / c->fy_px, 1.0);
}

/* The solid angle (sr) of the pinhole pixel that looks along camera-frame
 * direction dir (nc_camera_dir) for focal lengths fx, fy (px): cos^3 of its
 * field angle over fx fy. */
static inline double nc_camera_pixel_sr(double fx_px, double fy_px, struct nc_vec3 dir)
{
    return pow(nc_v3_norm(dir) / dir.z, -3.0) / (fx_px * fy_px);
}

/* Whether c's distortion has a unique inverse over the area its samples
 * reach (pixel centres +- 0.5 px, and margin_px pixels more on every side;
 * c is the image's camera, without the margin): 0 if so; 1 if the inverse
 * fails at pixel at[] (the image's pixels: negative in the margin); 2 if
 * the map folds frac of the way from the centre towards at[]. */
int nc_camera_unfolded(const struct nc_camera *c, int margin_px, double at[2], double *frac);

/* The ray (camera frame, unnormalised, z = 1) that the lens images onto
 * pixel coordinates (x, y): the distortion is inverted exactly (Newton). */
struct nc_vec3 nc_camera_ray(const struct nc_camera *c, double x, double y);
/* The solid angle (sr) pixel (x, y) of c sees through its lens: the
 * pinhole's at its true ray (nc_camera_ray) over the distortion's area
 * Jacobian there (det of d(xd, yd) / d(x, y)); the pinhole's without one. */
double nc_camera_pixel_sr_at(const struct nc_camera *c, double x, double y);
/* Pixel coordinates of camera-frame direction d (d.z > 0); returns -1 when
 * d is behind the camera. */
int nc_camera_project(const struct nc_camera *c, struct nc_vec3 d, double *x, double *y);

/* Read the "camera" section: intrinsics, distortion and pose. */
int nc_camera_from_config(struct nc_cfg_node *map, struct nc_camera *c);
/* Intrinsics and distortion only (a camera without a pose: `navcam expose`). */
int nc_camera_intrinsics_from_config(struct nc_cfg_node *map, struct nc_camera *c);

#endif
