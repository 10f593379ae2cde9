/* imgcmp.h - comparing a real image with a rendered one (`navcam compare`):
 * the seed paper's procedure (background removed with Otsu's threshold,
 * the foreground's intensities matched, per-pixel relative error) plus the
 * measures a navigation engineer reads off a pair: normalised cross
 * correlation at several scales, the overlap of the two silhouettes, and
 * the sub-pixel shift that registers them.
 *
 * Images are float arrays, row-major, width x height, any units (the two
 * need not share them when a fit is asked for). Non-finite pixels are
 * treated as missing everywhere. Pure computation: no files, no logging.
 */
#ifndef NC_IMGCMP_H
#define NC_IMGCMP_H

#include <stddef.h>

/* Otsu (1979): the threshold between the finite values of px that
 * maximises the between-class variance of a 4096-bin histogram over
 * [min, max]. A constant image gives its value (everything background). */
double nc_otsu_threshold(const float *px, size_t n);

/* out(x, y) = in(x - dx, y - dy): in moved by (dx, dy) pixels, by Keys'
 * cubic convolution (a = -0.5); pixels whose stencil leaves the image are
 * NaN. */
void nc_imgcmp_shift(const float *in, int w, int h, double dx, double dy, float *out);

/* Pearson correlation of a and b over the pixels where both are finite
 * (and mask, if not NULL, is non-zero), after averaging blocks of
 * block x block pixels (a block counts when all its pixels do); NaN when
 * fewer than 2 blocks count or either side is constant. */
double nc_imgcmp_ncc(const float *a, const float *b, const unsigned char *mask, int w, int h, int block);

/* The shift (dx, dy) of render that best matches real (largest NCC over
 * the whole frame): whole pixels within +-radius_px, then halving steps
 * down to 1/64 px around the best. */
int nc_imgcmp_register(const float *real, const float *render, int w, int h, int radius_px, double *dx,
                       double *dy);

enum nc_imgcmp_fit { NC_FIT_NONE, NC_FIT_SCALE, NC_FIT_HISTOGRAM };

struct nc_imgcmp_result {
    double threshold_real, threshold_render; /* Otsu's, in each image's units */
    size_t foreground_px;                    /* real above its threshold, finite in both */
    double scale;                            /* NC_FIT_SCALE: real ~ scale x render (else 1) */
    double rel_mean, rel_median, rel_p95, rel_rms; /* |render' - real| / real over the foreground */
    double rel_bias;                               /* mean of (render' - real) / real */
    double limb_iou;   /* |A and B| / |A or B| of the two foregrounds (each by its own Otsu threshold) */
    double ncc[5];     /* foreground NCC at blocks 1, 2, 4, 8, 16 (render' against real) */
};
extern const int nc_imgcmp_blocks[5];

/* Compare: render is fitted to real over real's foreground (render' =
 * scale x render, or render's foreground values mapped to real's by rank),
 * then measured. rel (may be NULL; w x h) receives the signed relative
 * error per foreground pixel and NaN elsewhere. render is not changed. */
int nc_imgcmp(const float *real, const float *render, int w, int h, enum nc_imgcmp_fit fit,
              struct nc_imgcmp_result *out, float *rel);

/* The histogram of the finite values of v within [lo, hi) in nbins bins
 * (values outside are counted in the end bins). */
void nc_imgcmp_histogram(const float *v, size_t n, double lo, double hi, int nbins, size_t *count);

#endif
