/* image_io_impl.h - back-ends behind image_io.h: OpenImageIO (C++, a module
 * loaded on first use) for EXR, TIFF and PNG, cfitsio for FITS. Internal to
 * render/. */
#ifndef NC_IMAGE_IO_IMPL_H
#define NC_IMAGE_IO_IMPL_H

#include "render/image_io.h"

#ifdef __cplusplus
extern "C" {
#endif

enum nc__pixel { NC__PX_FLOAT, NC__PX_U16, NC__PX_U8 };

/* The OpenImageIO back-end is a module, navcam-oiio.so beside the commands,
 * loaded on first use: OpenImageIO and the 260 libraries it pulls in take
 * about 0.4 s to load here (4 to 6 s under qemu's emulation), which a
 * command that reads and writes no EXR, TIFF or PNG file should not pay.
 * Its one entry point, nc__oiio_module(), returns this table; each function
 * returns 0 or an error code (error.h) with the message in err. attrs go
 * into the file as the format allows; description is a JSON object of all
 * attrs. read_attr takes an attribute by name, "ImageDescription" included. */
#define NC__OIIO_ABI 1
struct nc__oiio_api {
    int abi; /* NC__OIIO_ABI */
    int (*write)(const char *path, const void *px, int width, int height, enum nc__pixel type,
                 const struct nc_image_attr *attrs, int nattrs, const char *description, char *err, size_t errlen);
    int (*read)(const char *path, float **px, int *width, int *height, char *err, size_t errlen);
    int (*read_attr)(const char *path, const char *name, char *buf, size_t len, char *err, size_t errlen);
};
const struct nc__oiio_api *nc__oiio_module(void);
/* image_oiio_load.c: the module loaded once per process (an error names
 * where it was looked for), and its functions with the message of a
 * failure recorded as nc_error's. */
int nc__oiio_load(void);
int nc__oiio_write(const char *path, const void *px, int width, int height, enum nc__pixel type,
                   const struct nc_image_attr *attrs, int nattrs, const char *description);
int nc__oiio_read(const char *path, float **px, int *width, int *height);
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
