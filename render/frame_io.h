/* frame_io.h - writing a rendered frame to an image file with the metadata a
 * user needs to trust it: quantity and units, pose, Sun, intrinsics, version.
 * Shared by `navcam render` and the file output driver. */
#ifndef NC_FRAME_IO_H
#define NC_FRAME_IO_H

#include "render.h"
#include "scene.h"

enum nc_quantity { NC_Q_RADIANCE, NC_Q_IOF, NC_Q_RANGE };

extern const char *const nc_quantity_names[]; /* NULL-terminated, enum order */
const char *nc_quantity_units(enum nc_quantity q);
int nc_quantity_parse(const char *name, enum nc_quantity *q);

/* Write one quantity of f to path (format from the extension). */
int nc_frame_write(const char *path, const struct nc_frame *f, enum nc_quantity q, const struct nc_scene *s,
                   double *preview_scale);

#endif
