/* imgcmp.c - a real image against a rendered one (imgcmp.h). */
#include "core/imgcmp.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

const int nc_imgcmp_blocks[5] = {1, 2, 4, 8, 16};

double nc_otsu_threshold(const float *px, size_t n)
{
    enum { NB = 4096 };
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++)
        if (isfinite(px[i])) {
            lo = fmin(lo, px[i]);
            hi = fmax(hi, px[i]);
        }
    if (!(hi > lo)) /* one value: no upper class (nothing is at or above) */
        return isfinite(lo) ? nextafter(lo, INFINITY) : 0.0;
    size_t hist[NB] = {0}; /* 32 KiB: reentrant */
    size_t total = 0;
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(px[i])) {
            int b = (int)((px[i] - lo) / (hi - lo) * NB);
            hist[b < NB ? b : NB - 1]++;
            total++;
        }
    for (int b = 0; b < NB; b++)
        sum += (double)b * (double)hist[b];
    /* Otsu 1979 eq. 18: maximise w0 w1 (mu0 - mu1)^2 over the cut. */
    double w0 = 0, s0 = 0, best = -1;
    int cut = 0;
    for (int b = 0; b < NB - 1; b++) {
        w0 += (double)hist[b];
        s0 += (double)b * (double)hist[b];
        double w1 = (double)total - w0;
        if (w0 == 0 || w1 == 0)
            continue;
        double d = s0 / w0 - (sum - s0) / w1, v = w0 * w1 * d * d;
        if (v > best) {
            best = v;
            cut = b;
        }
    }
    return lo + (hi - lo) * (cut + 1) / NB; /* the lower edge of the upper class's first bin: values at or above it */
}

/* Keys (1981) cubic convolution kernel, a = -0.5. */
static double keys(double x)
{
    x = fabs(x);
    if (x < 1)
        return (1.5 * x - 2.5) * x * x + 1;
    if (x < 2)
        return ((-0.5 * x + 2.5) * x - 4) * x + 2;
    return 0;
}

void nc_imgcmp_shift(const float *in, int w, int h, double dx, double dy, float *out)
{
    /* out(x) = in(x - dx): the source is at x - dx = ix + fx, fx in [0, 1) */
    double sx = -dx, sy = -dy;
    int ix = (int)floor(sx), iy = (int)floor(sy);
    double fx = sx - ix, fy = sy - iy, kx[4], ky[4];
    for (int k = 0; k < 4; k++) {
        kx[k] = keys(fx - (k - 1));
        ky[k] = keys(fy - (k - 1));
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int x0 = x + ix - 1, y0 = y + iy - 1;
            float *o = &out[(size_t)y * (size_t)w + (size_t)x];
            if (x0 < 0 || y0 < 0 || x0 + 3 >= w || y0 + 3 >= h) {
                *o = NAN;
                continue;
            }
            double acc = 0;
            for (int j = 0; j < 4; j++) {
                const float *row = &in[(size_t)(y0 + j) * (size_t)w + (size_t)x0];
                acc += ky[j] * (kx[0] * row[0] + kx[1] * row[1] + kx[2] * row[2] + kx[3] * row[3]);
            }
            *o = (float)acc;
        }
}

double nc_imgcmp_ncc(const float *a, const float *b, const unsigned char *mask, int w, int h, int block)
{
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    size_t n = 0;
    for (int by = 0; by + block <= h; by += block)
        for (int bx = 0; bx + block <= w; bx += block) {
            double ma = 0, mb = 0;
            int ok = 1;
            for (int y = by; y < by + block && ok; y++)
                for (int x = bx; x < bx + block; x++) {
                    size_t i = (size_t)y * (size_t)w + (size_t)x;
                    if (!isfinite(a[i]) || !isfinite(b[i]) || (mask && !mask[i])) {
                        ok = 0;
                        break;
                    }
                    ma += a[i];
                    mb += b[i];
                }
            if (!ok)
                continue;
            sa += ma;
            sb += mb;
            saa += ma * ma;
            sbb += mb * mb;
            sab += ma * mb;
            n++;
        }
    if (n < 2)
        return NAN;
    double va = saa - sa * sa / (double)n, vb = sbb - sb * sb / (double)n, cab = sab - sa * sb / (double)n;
    /* a constant image (its variance lost in the rounding of these sums: a relative spread under 1e-6,
     * float's resolution) has no correlation */
    if (!(va > 1e-12 * saa && vb > 1e-12 * sbb))
        return NAN;
    return cab / sqrt(va * vb);
}

/* Whether the finite pixels of img take more than one value. */
static int varies(const float *img, int w, int h)
{
    const float *first = NULL;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        if (isfinite(img[i])) {
            if (first && img[i] != *first)
                return 1;
            first = first ? first : img + i;
        }
    return 0;
}

/* The render moved by (tx, ty) against real: keep it if it correlates best. */
struct search {
    const float *real, *render;
    float *moved;
    int w, h;
    double best, bx, by;
};

static void consider(struct search *s, double tx, double ty)
{
    nc_imgcmp_shift(s->render, s->w, s->h, tx, ty, s->moved);
    double c = nc_imgcmp_ncc(s->real, s->moved, NULL, s->w, s->h, 1);
    if (c > s->best) {
        s->best = c;
        s->bx = tx;
        s->by = ty;
    }
}

int nc_imgcmp_register(const float *real, const float *render, int w, int h, int radius_px, double *dx, double *dy)
{
    struct search s = {real, render, malloc((size_t)w * (size_t)h * sizeof(float)), w, h, -2, 0, 0};
    if (!s.moved)
        return nc_error(-ENOMEM, "out of memory");
    for (int sy = -radius_px; sy <= radius_px; sy++)
        for (int sx = -radius_px; sx <= radius_px; sx++)
            consider(&s, sx, sy);
    for (double step = 0.5; step >= 1.0 / 64; step /= 2) {
        const double cx = s.bx, cy = s.by;
        for (int k = 0; k < 9; k++)
            if (k != 4)
                consider(&s, cx + step * (k % 3 - 1), cy + step * (k / 3 - 1));
    }
    free(s.moved);
    if (!(s.best > -2)) {
        const char *flat = varies(real, w, h) ? varies(render, w, h) ? NULL : "the render" : "the real image";
        if (flat)
            return nc_error(NC_ERANGE, "registration: %s is constant over its finite pixels: nothing to correlate",
                            flat);
        return nc_error(NC_ERANGE, "registration: the images do not overlap at any shift within %d px", radius_px);
    }
    if (fabs(s.bx) > radius_px - 0.5 || fabs(s.by) > radius_px - 0.5)
        return nc_error(NC_ERANGE, "registration: the best shift (%g, %g) px lies at the edge of the search (+-%d "
                                   "px): the images may be farther apart; search wider (--register)",
                        s.bx, s.by, radius_px);
    *dx = s.bx;
    *dy = s.by;
    return 0;
}

struct ranked {
    float v;
    uint32_t i;
};

static int by_value(const void *a, const void *b)
{
    const struct ranked *x = a, *y = b;
    if (x->v != y->v)
        return x->v < y->v ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i; /* ties in pixel order: the same result every run */
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Nearest-rank percentile of sorted v[0..n). */
static double pct(const double *v, size_t n, double p)
{
    size_t k = (size_t)ceil(p * (double)n);
    return v[k ? k - 1 : 0];
}

/* The median of sorted v[0..n), n > 0: the middle value, or the mean of
 * the two middle ones. */
static double median(const double *v, size_t n) { return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]); }

int nc_imgcmp(const float *real, const float *render, int w, int h, enum nc_imgcmp_fit fit,
              struct nc_imgcmp_result *out, float *rel)
{
    const size_t n = (size_t)w * (size_t)h;
    memset(out, 0, sizeof *out);
    out->scale = 1;
    unsigned char *fg = calloc(n, 1);
    float *fit_px = calloc(n ? n : 1, sizeof *fit_px);
    struct ranked *ra = NULL, *rb = NULL;
    double *err = NULL;
    int rc = 0;
    if (!fg || !fit_px) {
        rc = nc_error(-ENOMEM, "out of memory");
        goto done;
    }
    /* Each image's threshold over the pixels both have (a pixel missing in
     * either is missing everywhere). */
    for (int k = 0; k < 2; k++) {
        const float *a = k ? render : real, *b = k ? real : render;
        for (size_t i = 0; i < n; i++)
            fit_px[i] = isfinite(b[i]) ? a[i] : NAN;
        *(k ? &out->threshold_render : &out->threshold_real) = nc_otsu_threshold(fit_px, n);
    }
    size_t inter = 0, uni = 0, m = 0;
    double srs = 0, sss = 0;
    for (size_t i = 0; i < n; i++) {
        /* a pixel missing in either image is missing from both silhouettes */
        const int both = isfinite(real[i]) && isfinite(render[i]);
        int a = both && real[i] >= out->threshold_real;
        int b = both && render[i] >= out->threshold_render;
        inter += a && b;
        uni += a || b;
        fg[i] = a && real[i] > 0 && isfinite(render[i]);
        fit_px[i] = render[i];
        if (fg[i]) {
            m++;
            srs += (double)real[i] * render[i];
            sss += (double)render[i] * render[i];
        }
    }
    out->limb_iou = uni ? (double)inter / (double)uni : NAN;
    out->foreground_px = m;
    if (m < 2) {
        rc = nc_error(NC_ERANGE, "the real image has %zu foreground pixels (above Otsu's threshold %g, positive, "
                                 "and finite in both images): nothing to compare", m, out->threshold_real);
        goto done;
    }
    if (fit == NC_FIT_SCALE) {
        if (!(sss > 0)) {
            rc = nc_error(NC_ERANGE, "the render is dark over the real image's foreground: no scale fits");
            goto done;
        }
        out->scale = srs / sss; /* least squares: min sum (real - k render)^2 */
        for (size_t i = 0; i < n; i++)
            fit_px[i] = (float)(out->scale * render[i]);
    } else if (fit == NC_FIT_HISTOGRAM) {
        ra = malloc(m * sizeof *ra);
        rb = malloc(m * sizeof *rb);
        if (!ra || !rb) {
            rc = nc_error(-ENOMEM, "out of memory");
            goto done;
        }
        for (size_t i = 0, k = 0; i < n; i++)
            if (fg[i]) {
                ra[k] = (struct ranked){real[i], (uint32_t)i};
                rb[k++] = (struct ranked){render[i], (uint32_t)i};
            }
        qsort(ra, m, sizeof *ra, by_value);
        qsort(rb, m, sizeof *rb, by_value);
        for (size_t k = 0; k < m; k++) /* the k-th brightest render pixel takes the k-th real value */
            fit_px[rb[k].i] = ra[k].v;
    }
    err = malloc(m * sizeof *err);
    if (!err) {
        rc = nc_error(-ENOMEM, "out of memory");
        goto done;
    }
    double sum = 0, sum2 = 0, bias = 0;
    for (size_t i = 0, k = 0; i < n; i++) {
        if (!fg[i]) {
            if (rel)
                rel[i] = NAN;
            continue;
        }
        double e = ((double)fit_px[i] - real[i]) / real[i];
        if (rel)
            rel[i] = (float)e;
        bias += e;
        err[k++] = fabs(e);
        sum += fabs(e);
        sum2 += e * e;
    }
    qsort(err, m, sizeof *err, cmp_double);
    out->rel_mean = sum / (double)m;
    out->rel_rms = sqrt(sum2 / (double)m);
    out->rel_bias = bias / (double)m;
    out->rel_median = median(err, m);
    out->rel_p95 = pct(err, m, 0.95);
    for (int k = 0; k < 5; k++)
        out->ncc[k] = nc_imgcmp_ncc(real, fit_px, fg, w, h, nc_imgcmp_blocks[k]);
done:
    free(fg);
    free(fit_px);
    free(ra);
    free(rb);
    free(err);
    return rc;
}

void nc_imgcmp_histogram(const float *v, size_t n, double lo, double hi, int nbins, size_t *count)
{
    memset(count, 0, (size_t)nbins * sizeof *count);
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(v[i]))
            continue;
        double f = (v[i] - lo) / (hi - lo) * nbins;
        int b = f < 0 ? 0 : f >= nbins ? nbins - 1 : (int)f;
        count[b]++;
    }
}
