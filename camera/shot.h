/* shot.h - one frame of a scene to an image file: render (with the
 * exposure's motion and render.quality auto), stars, the Sun, the stored
 * image's mirroring, then the camera model for electrons and DN, and the
 * file with its metadata. Shared by `navcam render` and `navcam batch`;
 * printing what happened is the caller's. */
#ifndef NC_CAMERA_SHOT_H
#define NC_CAMERA_SHOT_H

#include <stdint.h>

#include "camera/camsys.h"
#include "camera/sky.h"
#include "render/frame_io.h"
#include "render/render.h"
#include "render/scene.h"

struct nc_shot_info {
    int time_samples;
    char quality[300];     /* render.quality auto's choice ("" when manual), without the pilots' time */
    double quality_ms;     /* the pilots' time, ms */
    struct nc_sky_stats stars;
    double stars_ms;
    struct nc_sun_view sun;
    char sun_warning[80];  /* "" when none */
    char inside_warning[200]; /* most camera rays met the back of a surface ("" when not) */
    double render_ms;
    double preview_scale;  /* 16-bit preview: what 65535 stands for (0: not a preview) */
};

/* The scene, its camera model and its stars (nc_setup_load, nc_sky_load,
 * prepared for the camera) from one configuration; nothing to free on error. */
int nc_shot_setup(const char *path, const char *const *sets, int nsets, struct nc_scene *scene,
                  struct nc_camsys *cs, struct nc_sky *sky);

/* Mirror f's planes top to bottom and/or left to right in place
 * (nc_camera.flip_rows, flip_cols). */
void nc_frame_flip(struct nc_frame *f, int rows, int cols);

/* Electrons of a radiance image (the camera model's render size) as camera
 * c stores its image: the optics act on the rendered view, then a mirrored
 * camera's (a SUM file's K11 or K22 < 0) electrons are mirrored, so that
 * the sensor's patterns and noise belong to stored pixels. */
int nc_shot_electrons(const struct nc_camsys *cs, const struct nc_camera *c, const float *radiance,
                      double exposure_s, float *electrons);
/* A mirrored camera's attribute navcam:image_mirrored ("rows=R columns=C",
 * its text in val) into *out: 1, or 0 (nothing) for a camera that is not. */
int nc_shot_mirrored_attr(const struct nc_camera *c, char val[32], struct nc_image_attr *out);

/* Render scene (its quality settings may be changed by render.quality auto:
 * they are recorded in the file) to path as quantity q; sky may be off (on,
 * its stars move by their proper motion to t_sim_s after simulation time
 * 0). extra attributes go into the file too. */
int nc_shot(struct nc_renderer *r, struct nc_scene *scene, const struct nc_camsys *cs, struct nc_sky *sky,
            enum nc_quantity q, double exposure_s, double t_sim_s, uint64_t frame_no, const char *path,
            const struct nc_image_attr *extra, int nextra, struct nc_shot_info *info);

/* A celestial WCS (TAN, ICRS) of camera c's stored image as FITS
 * attributes ("fits:CTYPE1", ...) into out[15], their numbers' text in
 * val; 0 (none) for a distorted camera. Returns how many. */
int nc_shot_wcs_attrs(const struct nc_camera *c, char (*val)[32], struct nc_image_attr *out);
/* The detail a frame was rendered with, read off its renderer after the
 * render (the levels of detail's error bound, m; the boulder cut, m, 0:
 * every rock; the detailed surfaces' threshold, px; the roughness each
 * body's rocks not traced were folded into, deg, -1: none, and the largest
 * of those, what frame records give). */
struct nc_shot_detail {
    double lod_error_m, boulder_min_m, boulder_mesh_px;
    double fold_theta_bar_deg[NC_MAX_BODIES], fold_max_deg;
};
/* The text of its attributes. */
struct nc_shot_detail_text {
    char num[3][40], normals[NC_MAX_BODIES * 72], fold[NC_MAX_BODIES * 80];
};
void nc_shot_detail_of(const struct nc_renderer *r, int nbodies, struct nc_shot_detail *d);
/* d and how scene shades its meshes as attributes into out[5]
 * (navcam:lod_error_m, boulder_min_m, boulder_mesh_px; navcam:normals
 * when a body is a mesh, navcam:rock_fold_theta_bar_deg when rocks were
 * folded), their text in t. Returns how many. */
int nc_shot_detail_attrs(const struct nc_scene *scene, const struct nc_shot_detail *d, struct nc_shot_detail_text *t,
                         struct nc_image_attr *out);
/* The geometry planes (render.h, enum nc_geom_plane) of scene at pixel
 * centres: one sample a pixel, direct light only, no time samples; then
 * mirrored as the stored image is. geom: NC_GEOM_PLANES x w x h floats. */
int nc_shot_geometry(struct nc_renderer *r, const struct nc_scene *scene, float *geom, int32_t *rock_id);

#endif
