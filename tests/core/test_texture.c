/* test_texture.c - the texture statistics (core/texture.h): FAST corners
 * against OpenCV's counts on the same image, the power spectrum's slope of
 * fields synthesised with a known power law, and the gradient statistics of
 * a sinusoid against their closed forms. */
#include <fftw3.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/imgcmp.h"
#include "core/texture.h"
#include "testutil.h"

/* A deterministic 8-bit test image: xorshift bytes row by row, then the
 * integer mean (truncated) of each interior pixel's 3x3 neighbourhood. */
enum { GW = 200, GH = 150 };
static void golden_image(uint8_t *img)
{
    static uint8_t raw[GH][GW];
    uint64_t s = 0x9e3779b97f4a7c15ull;
    for (int y = 0; y < GH; y++)
        for (int x = 0; x < GW; x++) {
            s ^= s << 13, s ^= s >> 7, s ^= s << 17;
            raw[y][x] = (uint8_t)(s >> 56);
        }
    for (int y = 0; y < GH; y++)
        for (int x = 0; x < GW; x++) {
            int sum = 0;
            if (x == 0 || y == 0 || x == GW - 1 || y == GH - 1) {
                img[y * GW + x] = raw[y][x];
                continue;
            }
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    sum += raw[y + dy][x + dx];
            img[y * GW + x] = (uint8_t)(sum / 9);
        }
}

static void check_fast(void)
{
    static uint8_t img[GW * GH], mask[GW * GH], left[GW * GH];
    golden_image(img);
    /* OpenCV 4.6.0 (Debian python3-opencv), FastFeatureDetector TYPE_9_16
     * with non-maximum suppression, on this image (built the same way in
     * numpy): 2250 corners at threshold 10 (1125 with x < 100), 1806 at 20
     * (905). Independent code, the same rules: the counts must agree exactly. */
    long n10 = nc_texture_fast(img, GW, GH, 10, NULL, NULL, mask), n20 = nc_texture_fast(img, GW, GH, 20, NULL, NULL, mask);
    for (int i = 0; i < GW * GH; i++)
        left[i] = i % GW < GW / 2;
    long l10 = nc_texture_fast(img, GW, GH, 10, left, NULL, mask);
    long l20 = nc_texture_fast(img, GW, GH, 20, left, NULL, mask), in_left = 0, off = 0;
    for (int i = 0; i < GW * GH; i++)
        in_left += mask[i] && left[i], off += mask[i] && !left[i];
    printf("FAST on the golden image: %ld corners at threshold 10 (%ld left), %ld at 20 (%ld left)\n", n10, l10, n20,
           l20);
    CHECK(n10 == 2250 && l10 == 1125, "threshold 10: %ld, %ld left (OpenCV: 2250, 1125)", n10, l10);
    CHECK(n20 == 1806 && l20 == 905, "threshold 20: %ld, %ld left (OpenCV: 1806, 905)", n20, l20);
    CHECK(in_left == l20 && off == 0, "the region: %ld corners marked in it, %ld outside", in_left, off);

    /* A single bright pixel: one corner, there; a bright square: its corner
     * pixels tie in score with their neighbours, and OpenCV keeps none. */
    memset(img, 10, sizeof img);
    img[40 * GW + 60] = 200;
    CHECK(nc_texture_fast(img, GW, GH, 10, NULL, NULL, mask) == 1 && mask[40 * GW + 60], "a bright pixel is one corner");
    for (int y = 20; y < 40; y++)
        memset(img + y * GW + 20, 200, 20);
    CHECK(nc_texture_fast(img, GW, GH, 10, NULL, NULL, mask) == 1, "a square's corners tie with their neighbours");
    /* No corner on a constant image or a ramp gentler than the threshold. */
    for (int i = 0; i < GW * GH; i++)
        img[i] = (uint8_t)(i % GW);
    CHECK(nc_texture_fast(img, GW, GH, 10, NULL, NULL, mask) == 0, "a ramp of 1 per pixel has no corner");
    /* Nor within 3 pixels of the border. */
    memset(img, 10, sizeof img);
    img[2 * GW + 60] = 200;
    CHECK(nc_texture_fast(img, GW, GH, 10, NULL, NULL, mask) == 0, "a pixel 2 from the border is never a corner");
    /* A pixel whose circle holds a missing one is not tested: a missing
     * pixel (0 in the 8-bit image) beside a dark ground makes no corner. */
    static uint8_t valid[GW * GH];
    memset(img, 100, sizeof img);
    memset(valid, 1, sizeof valid);
    img[40 * GW + 60] = 0, valid[40 * GW + 60] = 0;
    CHECK(nc_texture_fast(img, GW, GH, 10, NULL, NULL, mask) == 1, "a dark pixel is a corner");
    CHECK(nc_texture_fast(img, GW, GH, 10, NULL, valid, mask) == 0, "a missing pixel made a corner");
}

/* A periodic n x n field whose power falls as f^-beta (random phases). */
static void power_law(int n, double beta, uint64_t seed, float *out)
{
    const int nc = n / 2 + 1;
    fftw_complex *c = fftw_malloc(sizeof *c * (size_t)n * (size_t)nc);
    double *r = fftw_malloc(sizeof *r * (size_t)n * (size_t)n);
    uint64_t s = seed;
    for (int ky = 0; ky < n; ky++)
        for (int kx = 0; kx < nc; kx++) {
            const double fy = (ky <= n / 2 ? ky : ky - n) / (double)n, fx = kx / (double)n, f = hypot(fx, fy);
            s ^= s << 13, s ^= s >> 7, s ^= s << 17;
            const double ph = 2 * M_PI * (double)(s >> 11) * 0x1p-53, a = f > 0 ? pow(f, -beta / 2) : 0.0;
            c[(size_t)ky * nc + kx][0] = a * cos(ph);
            c[(size_t)ky * nc + kx][1] = a * sin(ph);
        }
    fftw_plan p = fftw_plan_dft_c2r_2d(n, n, c, r, FFTW_ESTIMATE);
    fftw_execute(p);
    fftw_destroy_plan(p);
    for (int i = 0; i < n * n; i++)
        out[i] = (float)(100.0 + r[i]);
    fftw_free(c);
    fftw_free(r);
}

static void check_spectrum(void)
{
    enum { N = 512 };
    static float img[N * N];
    const double betas[] = {0.0, 1.5, 2.5, 3.5};
    for (int k = 0; k < 4; k++) {
        power_law(N, betas[k], 88172645463325252ull + (uint64_t)k, img);
        double r2;
        const double b = nc_texture_psd_beta(img, N, N, 1.0 / 64, 0.25, &r2);
        printf("power law f^-%.1f: beta %.3f (R^2 %.4f)\n", betas[k], b, r2);
        CHECK(fabs(b - betas[k]) < 0.1, "beta %.3f for a field of beta %.1f", b, betas[k]);
        CHECK(k == 0 || r2 > 0.99, "the log-log fit of beta %.1f: R^2 %.4f", betas[k], r2);
    }
    CHECK(isnan(nc_texture_psd_beta(img, N, N, 0.2, 0.21, NULL)), "a band of under 3 bins gives NaN");
}

static void check_gradients(void)
{
    enum { W = 130, H = 64 }; /* the interior columns 1 .. 128: whole periods */
    static float img[W * H];
    /* I = 100 + 10 sin(2 pi x / 32): central differences 10 sin(2 pi / 32)
     * cos(2 pi x / 32); over the mean 100, |grad| averages 0.1 sin(2 pi /
     * 32) 2 / pi and has RMS 0.1 sin(2 pi / 32) / sqrt 2; dI/dy = 0, so the
     * components together have kurtosis 2 E[cos^4] / E[cos^2]^2 = 3. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            img[y * W + x] = (float)(100.0 + 10.0 * sin(2 * M_PI * x / 32));
    struct nc_texture_opts o;
    nc_texture_defaults(&o);
    struct nc_texture t;
    CHECK(nc_texture_measure(img, W, H, &o, &t) == 0, "measure the sinusoid");
    double mean = 0; /* the level gradients are taken over: 100, and what the 130 columns' sines leave */
    for (int x = 0; x < W; x++)
        mean += (100.0 + 10.0 * sin(2 * M_PI * x / 32)) / W;
    const double g = 10.0 / mean * sin(2 * M_PI / 32);
    printf("sinusoid: grad mean %.6f (%.6f), rms %.6f (%.6f), kurtosis %.4f (3); beta %.2f\n", t.grad_mean,
           g * 2 / M_PI, t.grad_rms, g / sqrt(2), t.grad_kurtosis, t.psd_beta);
    CHECK(fabs(t.grad_mean / (g * 2 / M_PI) - 1) < 5e-3, "grad mean %.6f", t.grad_mean);
    CHECK(fabs(t.grad_rms / (g / sqrt(2)) - 1) < 1e-5, "grad rms %.6f", t.grad_rms);
    CHECK(fabs(t.grad_kurtosis - 3) < 1e-4, "kurtosis %.5f", t.grad_kurtosis);
    CHECK(t.region_px == W * H && t.corners == 0, "region %zu px, %zu corners", t.region_px, t.corners);

    /* The 8-bit scale: the 0.5th and 99.5th percentiles; a NaN pixel is
     * outside the region; Otsu's region keeps the bright half. */
    for (int i = 0; i < W * H; i++)
        img[i] = (float)(i % 1000);
    img[5] = NAN;
    CHECK(nc_texture_measure(img, W, H, &o, &t) == 0 && t.region_px == W * H - 1, "region without the NaN: %zu",
          t.region_px);
    CHECK(t.lo >= 4 && t.lo <= 6 && t.hi >= 993 && t.hi <= 995, "percentiles %g, %g", t.lo, t.hi);
    o.otsu = 1;
    CHECK(nc_texture_measure(img, W, H, &o, &t) == 0 && t.region_px > W * H / 3 && t.region_px < 2 * W * H / 3,
          "Otsu's region: %zu of %d px", t.region_px, W * H);
    static uint8_t mask[W * H]; /* a given region overrides Otsu's: the first 10 rows, less the NaN */
    for (int i = 0; i < 10 * W; i++)
        mask[i] = 1;
    o.mask = mask;
    CHECK(nc_texture_measure(img, W, H, &o, &t) == 0 && t.region_px == 10 * W - 1, "the mask's region: %zu px",
          t.region_px);
    o.mask = NULL;
    for (int i = 0; i < W * H; i++)
        img[i] = NAN;
    CHECK(nc_texture_measure(img, W, H, &o, &t) < 0, "no finite pixel: an error");
    CHECK(nc_texture_measure(img, 6, 6, &o, &t) < 0, "6x6: too small");

    /* Edge cases an outside check found: (1) a flat image with one bright
     * pixel, LO = HI at the percentiles: above them is 255 (every pixel was
     * 0, no corner); (2) gradients where no region pixel has its 4
     * neighbours in the region: null, not 0; (3) values 4e38 apart: the
     * gradients taken in double (their float differences overflowed); (4)
     * a pixel on Otsu's threshold is in the upper class. */
    o.otsu = 0;
    for (int i = 0; i < W * H; i++)
        img[i] = 20;
    img[32 * W + 64] = 250;
    CHECK(nc_texture_measure(img, W, H, &o, &t) == 0 && t.lo == 20 && t.hi == 20 && t.corners == 1,
          "one bright pixel on a flat image: scale [%g, %g], %zu corners (1)", t.lo, t.hi, t.corners);
    o.otsu = 1;
    CHECK(nc_texture_measure(img, W, H, &o, &t) == 0 && t.region_px == 1 && isnan(t.grad_mean) &&
              isnan(t.grad_rms) && isnan(t.grad_kurtosis),
          "Otsu's region of one pixel: %zu px, gradients %g %g %g (null)", t.region_px, t.grad_mean, t.grad_rms,
          t.grad_kurtosis);
    o.otsu = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            img[y * W + x] = (x + y) % 2 ? 3e38f : -1e38f; /* differences of 4e38: beyond a float */
    CHECK(nc_texture_measure(img, W, H, &o, &t) == 0 && isfinite(t.grad_mean) && isfinite(t.grad_rms),
          "a 3e38, -1e38 checkerboard: gradients %g %g (finite)", t.grad_mean, t.grad_rms);
    for (int i = 0; i < W * H; i++) /* 0 .. 4096: the cut's edges at whole values */
        img[i] = (float)(i % 4097);
    const double thr = nc_otsu_threshold(img, (size_t)W * H);
    size_t at_or_above = 0;
    for (int i = 0; i < W * H; i++)
        at_or_above += img[i] >= thr;
    o.otsu = 1;
    CHECK(thr == floor(thr) && nc_texture_measure(img, W, H, &o, &t) == 0 && t.region_px == at_or_above,
          "Otsu's threshold %g (whole): region %zu px, at or above it %zu", thr, t.region_px, at_or_above);
}

int main(void)
{
    check_fast();
    check_spectrum();
    check_gradients();
    return nc_test_end();
}
