/* image_io_impl.h - back-ends behind image_io.h: OpenImageIO (C++) for EXR,
 * TIFF and PNG, cfitsio for FITS. Internal to render/. */
#ifndef NC_IMAGE_IO_IMPL_H
#define NC_IMAGE_IO_IMPL_H

#include "render/image_io.h"

#ifdef __cplusplus
extern "C" {
#endif

enum nc__pixel { NC__PX_FLOAT, NC__PX_U16, NC__PX_U8 };

/* attrs go into the file as the format allows; description is a JSON object
 * of all attrs. */
int nc__oiio_write(const char *path, const void *px, int width, int height, enum nc__pixel type,
                   const struct nc_image_attr *attrs, int nattrs, const char *description);
int nc__oiio_read(const char *path, float **px, int *width, int *height);
/* Attribute by name; "ImageDescription" included. */
int nc__oiio_read_attr(const char *path, const char *name, char *buf, size_t len);

/* depth > 1 writes a cube of depth planes. */
int nc__fits_write(const char *path, const void *px, enum nc__pixel type, int width, int height, int depth,
                   const struct nc_image_attr *attrs, int nattrs);
int nc__fits_read(const char *path, float **px, int *width, int *height);
int nc__fits_read_attr(const char *path, const char *name, char *buf, size_t len);

#ifdef __cplusplus
}
#endif

#endif
