/* image_io.h - image files through OpenImageIO and cfitsio, behind a C interface.
 *
 * The format follows the file extension: .exr, .tif/.tiff and .fits store
 * float32 values as given; .png stores a 16-bit linear preview scaled so that
 * the largest finite value maps to 65535, with that scale written into the
 * file's metadata. NaN and Inf are written as 0. OpenImageIO (C++) is
 * behind it, loaded on first use (image_io_impl.h).
 * FITS is written and read with cfitsio (OpenImageIO 2.4 writes headers
 * standard readers reject and cannot read float FITS). Its rows go top row
 * first unless the attribute navcam:fits_row_order is "bottom_up" (the
 * archive convention); the keyword ROWORDER records which, and reading
 * returns top-down rows either way. Other formats are always top-down.
 */
#ifndef NC_IMAGE_IO_H
#define NC_IMAGE_IO_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

struct nc_image_attr {
    const char *name;     /* e.g. "navcam:camera_position_m" */
    const char *value;
};

/* 1 if path names a FITS file (.fits, .fit, .fts). */
int nc_image_is_fits(const char *path);
/* The value of navcam:fits_row_order from a command-line word ("top_down",
 * "bottom_up"): 0, or an error naming the choices. */
int nc_image_fits_row_order_ok(const char *word);
/* 1 if the extension is a supported output format (and *is_float), else 0. */
int nc_image_format_ok(const char *path, int *is_float);
/* Load now what reading or writing path's format needs: EXR, TIFF and PNG
 * go through OpenImageIO, a module loaded on first use (its libraries take
 * about 0.4 s to load). A program that will write such files calls this
 * once its configuration is read, before it renders, so that a missing
 * module fails before that work and the first frame does not wait. 0, or
 * an error naming where the module was looked for. */
int nc_image_prepare(const char *path);
/* Write a single-channel image; *preview_scale (may be NULL) receives the
 * value that 65535 stands for in a 16-bit preview, 0 for float formats. */
int nc_image_write(const char *path, const float *px, int width, int height, const struct nc_image_attr *attrs,
                   int nattrs, double *preview_scale);
/* Write digital numbers of an ADC with `bits` bits: 16-bit integers (8-bit
 * for bits <= 8) in .png, .tif and .fits; exact float32 values in .exr. */
int nc_image_write_dn(const char *path, const uint16_t *dn, int width, int height, int bits,
                      const struct nc_image_attr *attrs, int nattrs);
/* A FITS cube of nframes DN images (NAXIS3 = nframes). */
int nc_image_write_dn_cube(const char *path, const uint16_t *dn, int width, int height, int nframes, int bits,
                           const struct nc_image_attr *attrs, int nattrs);
/* Float32 planes (plane after plane, width x height each) in one FITS file
 * (.fits): a cube of nplanes planes whose keywords PLANE1 .. PLANEn name
 * them. Non-finite values are written as 0. */
int nc_image_write_planes(const char *path, const float *planes, int width, int height, int nplanes,
                          const char *const *names, const struct nc_image_attr *attrs, int nattrs);
/* px (w x h pixels of elem <= 8 bytes each) mirrored in place: top to
 * bottom when rows, left to right when cols (both: turned by 180 degrees). */
void nc_image_flip(void *px, size_t elem, int w, int h, int rows, int cols);
/* Read the first channel (first plane of a cube) as float (caller frees *px). */
int nc_image_read(const char *path, float **px, int *width, int *height);
/* Read one string attribute; 0 on success, negative if absent. */
int nc_image_read_attr(const char *path, const char *name, char *buf, size_t len);

#ifdef __cplusplus
}
#endif

#endif
