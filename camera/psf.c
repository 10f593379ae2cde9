/* psf.c - point spread functions: kernels (pixel-integrated Gaussian, Airy
 * pattern of a circular aperture, user image) normalised to sum 1, and their
 * application to a focal-plane image, direct for small kernels and by FFT
 * (FFTW, FFTW_ESTIMATE plans so results never depend on timing) for large
 * ones. The Gaussian is separable and always applied as two 1-D passes. */
#include <errno.h>
#include <fftw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camsys.h"
#include "core/error.h"
#include "render/image_io.h"

#define FFT_MIN_SIZE 9 /* kernels this wide or wider go through the FFT */

void nc_psf_free(struct nc_psf *psf)
{
    free(psf->kernel);
    psf->kernel = NULL;
    psf->size = 0;
}

static int normalise(struct nc_psf *psf)
{
    double sum = 0;
    int n = psf->size * psf->size;
    for (int i = 0; i < n; i++)
        sum += psf->kernel[i];
    if (!(sum > 0))
        return nc_error(NC_ERANGE, "PSF kernel sums to %g; it must be positive", sum);
    for (int i = 0; i < n; i++)
        psf->kernel[i] /= sum;
    return 0;
}

int nc_psf_gaussian(double sigma_px, struct nc_psf *psf)
{
    /* Pixel-integrated: K(i) = [erf((i+1/2)/(s sqrt 2)) - erf((i-1/2)/(s sqrt 2))]/2, to 5 sigma. */
    int r = (int)ceil(5.0 * sigma_px);
    psf->kind = NC_PSF_GAUSSIAN;
    psf->sigma_px = sigma_px;
    psf->size = 2 * r + 1;
    psf->kernel = malloc((size_t)psf->size * psf->size * sizeof(double));
    if (!psf->kernel)
        return nc_error(-ENOMEM, "out of memory");
    double g[2 * 500 + 1], a = 1.0 / (sigma_px * sqrt(2.0));
    if (r > 500)
        return nc_error(NC_ERANGE, "Gaussian PSF sigma %g px is too wide", sigma_px);
    for (int i = -r; i <= r; i++)
        g[i + r] = 0.5 * (erf((i + 0.5) * a) - erf((i - 0.5) * a));
    for (int y = 0; y < psf->size; y++)
        for (int x = 0; x < psf->size; x++)
            psf->kernel[y * psf->size + x] = g[y] * g[x];
    return normalise(psf);
}

int nc_psf_airy(double wavelength_m, double f_number, double pitch_m, struct nc_psf *psf)
{
    /* I(r) = [2 J1(v)/v]^2, v = pi r / (lambda N); first dark ring at
     * r = 1.22 lambda N. Cut at the 12th dark ring (v = 38.4748, the 12th
     * zero of J1: r = 12.247 lambda N), a circle, in a square kernel of
     * that half-width (at least 3 px), integrated over each pixel with 8x8
     * samples, or more when the pattern is small against the pixel (4 to a
     * lambda N, at most 128x128); a pattern that fits in the middle pixel
     * is all in it. */
    const double v12 = 38.4748;
    double lnp = wavelength_m * f_number / pitch_m; /* lambda N in pixels */
    int r = (int)ceil(fmax(3.0, v12 / M_PI * lnp));
    if (r > 200)
        return nc_error(NC_ERANGE, "Airy PSF is %d px wide; use a Gaussian or an image kernel", 2 * r + 1);
    psf->kind = NC_PSF_AIRY;
    psf->size = 2 * r + 1;
    psf->kernel = calloc((size_t)psf->size * psf->size, sizeof(double));
    if (!psf->kernel)
        return nc_error(-ENOMEM, "out of memory");
    if (v12 / M_PI * lnp <= 0.5) {
        psf->kernel[r * psf->size + r] = 1;
        return 0;
    }
    const int ss = (int)fmin(128, fmax(8, ceil(4 / lnp)));
    for (int y = -r; y <= r; y++)
        for (int x = -r; x <= r; x++) {
            double sum = 0;
            for (int j = 0; j < ss; j++)
                for (int i = 0; i < ss; i++) {
                    double px = x - 0.5 + (i + 0.5) / ss, py = y - 0.5 + (j + 0.5) / ss;
                    double v = M_PI * sqrt(px * px + py * py) / lnp;
                    double a = v > 1e-8 ? 2.0 * j1(v) / v : 1.0;
                    sum += v < v12 ? a * a : 0.0;
                }
            psf->kernel[(y + r) * psf->size + (x + r)] = sum;
        }
    return normalise(psf);
}

int nc_psf_image(const char *path, struct nc_psf *psf)
{
    float *px;
    int w, h, rc = nc_image_read(path, &px, &w, &h);
    if (rc < 0)
        return rc;
    if (w != h || w % 2 == 0) {
        free(px);
        return nc_error(NC_ERANGE, "%s: a PSF kernel must be square with an odd size, got %dx%d", path, w, h);
    }
    psf->kind = NC_PSF_IMAGE;
    psf->size = w;
    psf->kernel = malloc((size_t)w * w * sizeof(double));
    if (!psf->kernel) {
        free(px);
        return nc_error(-ENOMEM, "out of memory");
    }
    for (int i = 0; i < w * w; i++) {
        if (!(px[i] >= 0 && isfinite(px[i]))) {
            free(px);
            nc_psf_free(psf);
            return nc_error(NC_ERANGE, "%s: kernel value at (%d, %d) is negative or not finite", path, i % w, i / w);
        }
        psf->kernel[i] = px[i];
    }
    free(px);
    if ((rc = normalise(psf)) < 0) {
        char why[256];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        nc_psf_free(psf);
        return nc_error(rc, "%s: %s", path, why);
    }
    return 0;
}

/* Separable Gaussian: rows then columns, zero outside the image. Written as
 * tap-by-tap multiply-adds over whole rows so that the compiler vectorises
 * them; float accumulation over at most 2 r + 1 taps (relative error ~1e-7). */
/* Compiled twice, for AVX2 and for baseline x86-64, the CPU picks at run
 * time; no FMA in either, so both give the same bits. */
__attribute__((target_clones("avx2", "default")))
static int apply_separable(const struct nc_psf *psf, const float *in, float *out, int W, int H, float *scratch)
{
    const int k = psf->size, r = k / 2;
    const double *g = psf->kernel + (size_t)r * k; /* centre row: g1[x] g1[r] */
    float *g1 = malloc((size_t)k * sizeof *g1), *tmp = scratch ? scratch : malloc((size_t)W * H * sizeof *tmp);
    if (!g1 || !tmp) {
        free(g1);
        if (!scratch)
            free(tmp);
        return nc_error(-ENOMEM, "out of memory");
    }
    const double c = sqrt(g[r]);
    for (int i = 0; i < k; i++)
        g1[i] = (float)(g[i] / c);
    /* Rows: tmp[x] = sum_i g1[i] in[x + r - i] (symmetric kernel), x in range. */
    for (int y = 0; y < H; y++) {
        const float *src = in + (size_t)y * W;
        float *dst = tmp + (size_t)y * W;
        memset(dst, 0, (size_t)W * sizeof *dst);
        for (int i = 0; i < k; i++) {
            const int d = i - r; /* dst[x] += g1[i] src[x + d] */
            const int x0 = d < 0 ? -d : 0, x1 = d > 0 ? W - d : W;
            const float w = g1[i];
            for (int x = x0; x < x1; x++)
                dst[x] += w * src[x + d];
        }
    }
    /* Columns, a whole row of outputs at a time. */
    for (int y = 0; y < H; y++) {
        float *dst = out + (size_t)y * W;
        memset(dst, 0, (size_t)W * sizeof *dst);
        for (int i = 0; i < k; i++) {
            const int yy = y + i - r;
            if (yy < 0 || yy >= H)
                continue;
            const float *src = tmp + (size_t)yy * W;
            const float w = g1[i];
            for (int x = 0; x < W; x++)
                dst[x] += w * src[x];
        }
    }
    free(g1);
    if (!scratch)
        free(tmp);
    return 0;
}

/* out(x, y) = sum over taps of K(r + dy, r + dx) in(x - dx, y - dy): a point
 * source at p lands on p + (dx, dy) with weight K(r + dy, r + dx). */
static int apply_direct(const struct nc_psf *psf, const float *in, float *out, int W, int H)
{
    int k = psf->size, r = k / 2;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double s = 0;
            for (int j = 0; j < k; j++) {
                int yy = y - (j - r);
                if (yy < 0 || yy >= H)
                    continue;
                for (int i = 0; i < k; i++) {
                    int xx = x - (i - r);
                    if (xx >= 0 && xx < W)
                        s += psf->kernel[j * k + i] * in[(size_t)yy * W + xx];
                }
            }
            out[(size_t)y * W + x] = (float)s;
        }
    return 0;
}

/* Smallest n >= m whose prime factors are 2, 3, 5 and 7 (fast for FFTW). */
static int fft_size(int m)
{
    for (int n = m;; n++) {
        int v = n;
        for (int p = 2; p <= 7; p++)
            while (v % p == 0)
                v /= p;
        if (v == 1)
            return n;
    }
}

static int apply_fft(const struct nc_psf *psf, const float *in, float *out, int W, int H)
{
    int k = psf->size, r = k / 2;
    int pw = fft_size(W + k - 1), ph = fft_size(H + k - 1), cw = pw / 2 + 1;
    double *a = fftw_malloc(sizeof(double) * pw * ph), *b = fftw_malloc(sizeof(double) * pw * ph);
    fftw_complex *fa = fftw_malloc(sizeof(fftw_complex) * cw * ph), *fb = fftw_malloc(sizeof(fftw_complex) * cw * ph);
    if (!a || !b || !fa || !fb) {
        fftw_free(a), fftw_free(b), fftw_free(fa), fftw_free(fb);
        return nc_error(-ENOMEM, "out of memory for a %dx%d FFT", pw, ph);
    }
    memset(a, 0, sizeof(double) * pw * ph);
    memset(b, 0, sizeof(double) * pw * ph);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            a[(size_t)y * pw + x] = in[(size_t)y * W + x];
    /* Kernel with its centre at (0, 0), wrapped. */
    for (int j = 0; j < k; j++)
        for (int i = 0; i < k; i++)
            b[(size_t)((j - r + ph) % ph) * pw + (i - r + pw) % pw] = psf->kernel[j * k + i];
    fftw_plan p1 = fftw_plan_dft_r2c_2d(ph, pw, a, fa, FFTW_ESTIMATE);
    fftw_plan p2 = fftw_plan_dft_r2c_2d(ph, pw, b, fb, FFTW_ESTIMATE);
    fftw_plan p3 = fftw_plan_dft_c2r_2d(ph, pw, fa, a, FFTW_ESTIMATE);
    fftw_execute(p1);
    fftw_execute(p2);
    for (size_t i = 0; i < (size_t)cw * ph; i++) {
        double re = fa[i][0] * fb[i][0] - fa[i][1] * fb[i][1], im = fa[i][0] * fb[i][1] + fa[i][1] * fb[i][0];
        fa[i][0] = re;
        fa[i][1] = im;
    }
    fftw_execute(p3);
    double scale = 1.0 / ((double)pw * ph);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double v = a[(size_t)y * pw + x] * scale;
            out[(size_t)y * W + x] = (float)(v > 0 ? v : 0); /* FFT rounding can dip below 0 */
        }
    fftw_destroy_plan(p1);
    fftw_destroy_plan(p2);
    fftw_destroy_plan(p3);
    fftw_free(a), fftw_free(b), fftw_free(fa), fftw_free(fb);
    return 0;
}

int nc_psf_apply(const struct nc_psf *psf, const float *in, float *out, int W, int H)
{
    return nc_psf_apply_scratch(psf, in, out, W, H, NULL);
}

int nc_psf_apply_scratch(const struct nc_psf *psf, const float *in, float *out, int W, int H, float *scratch)
{
    if (psf->size <= 1 || !psf->kernel) {
        memmove(out, in, (size_t)W * H * sizeof *out);
        return 0;
    }
    if (psf->kind == NC_PSF_GAUSSIAN)
        return apply_separable(psf, in, out, W, H, scratch);
    return psf->size >= FFT_MIN_SIZE ? apply_fft(psf, in, out, W, H) : apply_direct(psf, in, out, W, H);
}
