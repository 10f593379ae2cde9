/* frame_io.h - writing a rendered frame to an image file with the metadata a
 * user needs to trust it: quantity and units, pose, Sun, intrinsics, version.
 * Shared by `navcam render` and the file output driver. */
#ifndef NC_FRAME_IO_H
#define NC_FRAME_IO_H

#include "render/image_io.h"
#include "render/render.h"
#include "render/scene.h"

/* radiance, iof and range come from the renderer; electrons (noise-free
 * photo-electrons) and dn (a digitised frame) need the camera model. */
/* NC_Q_ROCK_ID: the boulder each pixel shows (nc_frame.rock_id, which the
 * caller allocates), as float32 (exact to 2^24), -1 for none. */
enum nc_quantity { NC_Q_RADIANCE, NC_Q_IOF, NC_Q_RANGE, NC_Q_ROCK_ID, NC_Q_ELECTRONS, NC_Q_DN };

extern const char *const nc_quantity_names[]; /* NULL-terminated, enum order */
const char *nc_quantity_units(enum nc_quantity q);
int nc_quantity_parse(const char *name, enum nc_quantity *q);
/* Whether a file at path (its extension) can hold quantity q: rock_id
 * needs a float format (a PNG's 16 unsigned bits hold no -1). */
int nc_quantity_format_check(enum nc_quantity q, const char *path);

/* The scene's metadata (pose, Sun, intrinsics, version, quantity and units):
 * fills attrs (up to max, each value stored in text[i]) and returns the count. */
int nc_frame_meta(const struct nc_scene *s, enum nc_quantity q, struct nc_image_attr *attrs, char (*text)[200],
                  int max);
/* Write radiance, iof or range of f to path (format from the extension),
 * with the scene's metadata and nextra more attributes (e.g.
 * navcam:fits_row_order, image_io.h). */
int nc_frame_write(const char *path, const struct nc_frame *f, enum nc_quantity q, const struct nc_scene *s,
                   const struct nc_image_attr *extra, int nextra, double *preview_scale);

#endif
