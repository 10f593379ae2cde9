/* psf.h - the optics' point spread function: kernels (Gaussian, Airy,
 * from an image) and their convolution with a frame. Knows nothing of the
 * detector or the renderer.
 */
#ifndef NC_PSF_H
#define NC_PSF_H

enum nc_psf_kind { NC_PSF_NONE, NC_PSF_GAUSSIAN, NC_PSF_AIRY, NC_PSF_IMAGE };

struct nc_psf {
    enum nc_psf_kind kind;
    double sigma_px;  /* gaussian */
    int size;         /* kernel is size x size, size odd; 0 = no kernel */
    double *kernel;   /* normalised to sum 1, row-major, centre at size/2 */
};

int nc_psf_gaussian(double sigma_px, struct nc_psf *psf);
/* Airy pattern of a circular aperture, integrated over the pixel area. */
int nc_psf_airy(double wavelength_m, double f_number, double pixel_pitch_m, struct nc_psf *psf);
int nc_psf_image(const char *path, struct nc_psf *psf);
/* out = in convolved with the kernel (same size; zero outside the image). Uses
 * FFTW above a kernel size threshold, direct summation below. scratch, if not
 * NULL, is a width*height work buffer (saves an allocation per frame). */
int nc_psf_apply(const struct nc_psf *psf, const float *in, float *out, int width, int height);
int nc_psf_apply_scratch(const struct nc_psf *psf, const float *in, float *out, int width, int height,
                         float *scratch);
void nc_psf_free(struct nc_psf *psf);

#endif
