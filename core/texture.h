/* texture.h - the texture statistics of an image: what feature trackers,
 * terrain-relative navigation and hazard detection lock onto, measured the
 * same way on a render and on a real image (`navcam texture`,
 * docs/terrain.md):
 *   - keypoint density: FAST corners (Rosten and Drummond 2006; 9 of the 16
 *     pixels of the radius-3 circle, non-maximum suppression), as OpenCV's
 *     FastFeatureDetector (TYPE_9_16) finds them on the image scaled to
 *     8 bits;
 *   - the power spectrum's slope: beta of P(f) ~ f^-beta, from the radially
 *     averaged 2-D power spectrum of the image (mean removed, Hann window)
 *     over a band of spatial frequencies;
 *   - gradient statistics: the central-difference gradient over the mean
 *     level (mean and RMS magnitude per pixel), and the kurtosis of its
 *     components (3 for Gaussian gradients, larger for sparse edges).
 * Images are float arrays, row-major, width x height, any units; NaN and
 * Inf pixels are left out of the region. Pure computation: no files, no
 * logging; the spectrum plans an FFTW transform, so calls must not run
 * beside other FFTW planning (FFTW's planner is not thread-safe).
 */
#ifndef NC_TEXTURE_H
#define NC_TEXTURE_H

#include <stddef.h>
#include <stdint.h>

struct nc_texture_opts {
    int threshold;     /* FAST: a circle pixel counts when it differs from the centre by more than
                          this, in 8-bit units (OpenCV's default 10) */
    double lo, hi;     /* the values scaled to 0 and 255 for FAST; lo >= hi: the region's 0.5th
                          and 99.5th percentiles */
    int otsu;          /* the region: 0 every finite pixel, 1 those above Otsu's threshold (a body
                          against the sky) */
    const uint8_t *mask; /* NULL, or the region given: its non-zero pixels (finite ones) */
    double f_lo, f_hi; /* the spectrum's band, cycles per pixel (0 < f_lo < f_hi <= 0.5) */
};

/* threshold 10, percentiles, every finite pixel (no mask), band 1/64 .. 1/4 cycle per pixel */
void nc_texture_defaults(struct nc_texture_opts *o);

struct nc_texture {
    size_t region_px;      /* pixels measured */
    double lo, hi;         /* the 8-bit scale used: lo -> 0, hi -> 255 */
    size_t corners;        /* FAST corners on region pixels, after suppression */
    double corners_per_mpx; /* per million region pixels */
    double psd_beta;       /* P(f) ~ f^-beta over the band; NaN when fewer than 3 bins have power */
    double psd_r2;         /* the log-log fit's coefficient of determination */
    double grad_mean, grad_rms; /* |grad I| / mean(I), per pixel, over region pixels whose 4 neighbours are in it */
    double grad_kurtosis;  /* kurtosis of the components dI/dx, dI/dy together (NaN when constant) */
};

/* Measure img. Returns 0, or a negative error code (no region, an image
 * too small for the circle or the band, out of memory). */
int nc_texture_measure(const float *img, int w, int h, const struct nc_texture_opts *o, struct nc_texture *out);

/* The FAST corners of an 8-bit image (pixels within 3 of the border are
 * never corners): mask[i] set for each corner kept after non-maximum
 * suppression, where region (may be NULL) is non-zero; returns how many, or
 * a negative error code (out of memory).
 * A pixel p is a corner when 9 contiguous pixels of the circle are all
 * brighter than I_p + t or all darker than I_p - t; its score is the
 * largest t for which it still is one; a corner is kept when its score
 * exceeds those of its 8 neighbours (0 for a neighbour that is no corner).
 * With valid (may be NULL), a pixel is tested only when it and its 16
 * circle pixels are valid (non-zero): a missing pixel makes no corner. */
long nc_texture_fast(const uint8_t *img, int w, int h, int t, const uint8_t *region, const uint8_t *valid,
                     uint8_t *mask);

/* The slope beta of P(f) ~ f^-beta of img (w x h, finite values) over
 * [f_lo, f_hi) cycles per pixel: the mean removed, a 2-D Hann window, the
 * power |FFT|^2 averaged over the frequencies f = |(fx, fy)| in each bin of
 * an eighth of an octave, and a least-squares line through log P against
 * the bins' mean log f. r2 (may be NULL) receives the fit's R^2. NaN when
 * fewer than 3 bins hold a frequency. */
double nc_texture_psd_beta(const float *img, int w, int h, double f_lo, double f_hi, double *r2);

#endif
