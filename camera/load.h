/* load.h - a camera model (and a scene with it) from a configuration file,
 * and the sensor's metadata for image files. The glue between the config
 * tree, the renderer's scene and the camera model; no physics here.
 */
#ifndef NC_CAMERA_LOAD_H
#define NC_CAMERA_LOAD_H

#include <stdint.h>

#include "camera/camsys.h"
#include "camera/sky.h"
#include "render/frame_io.h"
#include "render/scene.h"

/* A scene and its camera model from one configuration (path NULL: the
 * built-in default scene), with --set overrides; unknown keys are errors. */
int nc_setup_load(const char *path, const char *const *sets, int nsets, struct nc_scene *s, struct nc_camsys *cs);
/* The same configuration's `stars` section (sky->on = 0 without one). */
int nc_sky_load(const char *path, const char *const *sets, int nsets, struct nc_sky *sky);
/* A camera alone (intrinsics, optics, sensor, exposure), for `navcam expose`.
 * A whole scene file is accepted: its pose, bodies, Sun and render settings
 * are ignored. */
int nc_camsys_load(const char *path, const char *const *sets, int nsets, struct nc_camera *geom, struct nc_camsys *cs);
/* The sensor's metadata (ADC, gain, bias, exposure, frame) appended to attrs. */
int nc_camsys_meta(const struct nc_camsys *cs, double exposure_s, uint64_t frame, struct nc_image_attr *attrs,
                   char (*text)[200], int max);

#endif
