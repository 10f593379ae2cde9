/* texture.c - the texture statistics of texture.h: FAST corners on the
 * image scaled to 8 bits, the power spectrum's slope (FFTW) and gradient
 * statistics. Pure computation on caller-owned arrays. */
#include "core/texture.h"

#include <errno.h>
#include <fftw3.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/imgcmp.h"

void nc_texture_defaults(struct nc_texture_opts *o)
{
    *o = (struct nc_texture_opts){
        .threshold = 10, .lo = 0, .hi = 0, .otsu = 0, .mask = NULL, .f_lo = 1.0 / 64, .f_hi = 0.25};
}

/* The circle of radius 3 (Bresenham), clockwise from the top. */
static const int circle[16][2] = {{0, -3}, {1, -3}, {2, -2}, {3, -1}, {3, 0},  {3, 1},  {2, 2},   {1, 3},
                                  {0, 3},  {-1, 3}, {-2, 2}, {-3, 1}, {-3, 0}, {-3, -1}, {-2, -2}, {-1, -3}};

/* The largest t for which the pixel at p is a corner, or -1 when it is none
 * at t: the best over the 16 arcs of 9 contiguous circle pixels of the
 * smallest difference from the centre, all of one sign, minus 1 (the
 * differences must exceed t). */
static int fast_score(const uint8_t *p, int w, int t)
{
    int d[16], above = 0, below = 0;
    for (int k = 0; k < 16; k++)
        d[k] = (int)p[circle[k][1] * w + circle[k][0]] - (int)p[0];
    /* any 9 contiguous of the 16 hold at least 2 of the 4 compass pixels */
    for (int k = 0; k < 16; k += 4)
        above += d[k] > t, below += d[k] < -t;
    if (above < 2 && below < 2)
        return -1;
    int best = 0;
    for (int k = 0; k < 16; k++) {
        int lo = 255, hi = 255; /* smallest d, smallest -d, over the arc k .. k + 8 */
        for (int i = 0; i < 9; i++) {
            const int v = d[(k + i) & 15];
            lo = v < lo ? v : lo;
            hi = -v < hi ? -v : hi;
        }
        best = lo > best ? lo : best;
        best = hi > best ? hi : best;
    }
    return best > t ? best - 1 : -1;
}

/* The pixel at v and its circle all valid. */
static int circle_valid(const uint8_t *v, int w)
{
    int ok = v[0] != 0;
    for (int k = 0; k < 16; k++)
        ok &= v[circle[k][1] * w + circle[k][0]] != 0;
    return ok;
}

long nc_texture_fast(const uint8_t *img, int w, int h, int t, const uint8_t *region, const uint8_t *valid,
                     uint8_t *mask)
{
    memset(mask, 0, (size_t)w * (size_t)h);
    if (w < 7 || h < 7)
        return 0;
    int *score = calloc((size_t)w * (size_t)h, sizeof *score);
    if (!score)
        return nc_error(-ENOMEM, "texture: out of memory for a %dx%d image", w, h);
    for (int y = 3; y < h - 3; y++)
        for (int x = 3; x < w - 3; x++) {
            const size_t o = (size_t)y * (size_t)w + (size_t)x;
            const int s = !valid || circle_valid(valid + o, w) ? fast_score(img + o, w, t) : -1;
            score[o] = s < 0 ? 0 : s;
            mask[o] = s >= 0; /* a corner, before suppression */
        }
    long n = 0;
    for (int y = 3; y < h - 3; y++)
        for (int x = 3; x < w - 3; x++) {
            const size_t o = (size_t)y * (size_t)w + (size_t)x;
            if (!mask[o])
                continue;
            int keep = !region || region[o];
            for (int dy = -1; dy <= 1 && keep; dy++)
                for (int dx = -1; dx <= 1 && keep; dx++)
                    if ((dx || dy) && score[o] <= score[(size_t)(y + dy) * (size_t)w + (size_t)(x + dx)])
                        keep = 0;
            mask[o] = (uint8_t)(keep ? 2 : 1);
        }
    for (size_t o = 0; o < (size_t)w * (size_t)h; o++) {
        n += mask[o] == 2;
        mask[o] = mask[o] == 2;
    }
    free(score);
    return n;
}

double nc_texture_psd_beta(const float *img, int w, int h, double f_lo, double f_hi, double *r2)
{
    if (r2)
        *r2 = NAN;
    if (w < 4 || h < 4 || !(f_lo > 0) || !(f_hi > f_lo))
        return NAN;
    const int wc = w / 2 + 1;
    double *in = fftw_malloc(sizeof *in * (size_t)w * (size_t)h);
    fftw_complex *out = fftw_malloc(sizeof *out * (size_t)wc * (size_t)h);
    enum { PER_OCTAVE = 8, MAXBINS = 256 };
    const int nb = (int)ceil(PER_OCTAVE * log2(f_hi / f_lo));
    double *acc = calloc(3 * (size_t)(nb > 0 ? nb : 1), sizeof *acc); /* power, log10 f, count per bin */
    double beta = NAN;
    if (!in || !out || !acc || nb > MAXBINS)
        goto done;
    double mean = 0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        mean += img[i];
    mean /= (double)w * (double)h;
    for (int y = 0; y < h; y++) {
        const double wy = 0.5 - 0.5 * cos(2 * M_PI * y / (h - 1));
        for (int x = 0; x < w; x++) {
            const double wx = 0.5 - 0.5 * cos(2 * M_PI * x / (w - 1));
            in[(size_t)y * (size_t)w + (size_t)x] = (img[(size_t)y * (size_t)w + (size_t)x] - mean) * wx * wy;
        }
    }
    fftw_plan plan = fftw_plan_dft_r2c_2d(h, w, in, out, FFTW_ESTIMATE);
    if (!plan)
        goto done;
    fftw_execute(plan);
    fftw_destroy_plan(plan);
    for (int ky = 0; ky < h; ky++)
        for (int kx = 0; kx < wc; kx++) {
            const double fy = (ky <= h / 2 ? ky : ky - h) / (double)h, fx = kx / (double)w, f = hypot(fx, fy);
            if (!(f >= f_lo && f < f_hi))
                continue;
            const int b = (int)floor(PER_OCTAVE * log2(f / f_lo));
            if (b < 0 || b >= nb)
                continue;
            const double *c = out[(size_t)ky * (size_t)wc + (size_t)kx];
            acc[3 * b] += c[0] * c[0] + c[1] * c[1];
            acc[3 * b + 1] += log10(f);
            acc[3 * b + 2] += 1;
        }
    /* least squares through (mean log f, log mean P) of the bins with power */
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    int m = 0;
    for (int b = 0; b < nb; b++) {
        if (!(acc[3 * b + 2] > 0) || !(acc[3 * b] > 0))
            continue;
        const double x = acc[3 * b + 1] / acc[3 * b + 2], y = log10(acc[3 * b] / acc[3 * b + 2]);
        sx += x, sy += y, sxx += x * x, sxy += x * y, syy += y * y;
        m++;
    }
    if (m >= 3) {
        const double vx = sxx - sx * sx / m, vy = syy - sy * sy / m, cxy = sxy - sx * sy / m;
        beta = vx > 0 ? -cxy / vx : NAN;
        if (r2)
            *r2 = vx > 0 && vy > 0 ? cxy * cxy / (vx * vy) : NAN;
    }
done:
    fftw_free(in);
    fftw_free(out);
    free(acc);
    return beta;
}

static int cmp_float(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

int nc_texture_measure(const float *img, int w, int h, const struct nc_texture_opts *o, struct nc_texture *out)
{
    memset(out, 0, sizeof *out);
    out->psd_beta = out->psd_r2 = out->grad_mean = out->grad_rms = out->grad_kurtosis = NAN; /* null if undefined */
    if (w < 7 || h < 7)
        return nc_error(NC_ERANGE, "texture: a %dx%d image is too small (at least 7x7)", w, h);
    const size_t n = (size_t)w * (size_t)h;
    uint8_t *region = malloc(n), *u8 = malloc(n), *mask = malloc(n);
    float *sorted = malloc(n * sizeof *sorted), *filled = malloc(n * sizeof *filled);
    int rc = 0;
    if (!region || !u8 || !mask || !sorted || !filled) {
        rc = nc_error(-ENOMEM, "texture: out of memory for a %dx%d image", w, h);
        goto done;
    }
    const double thr = o->otsu && !o->mask ? nc_otsu_threshold(img, n) : -INFINITY;
    size_t m = 0;
    double mean = 0;
    for (size_t i = 0; i < n; i++) {
        region[i] = isfinite(img[i]) && (o->mask ? o->mask[i] != 0 : img[i] >= thr);
        if (region[i]) {
            sorted[m++] = img[i];
            mean += img[i];
        }
    }
    if (m == 0) {
        rc = nc_error(NC_ERANGE, "texture: no pixel in the region (%s)",
                      o->mask ? "the mask given" : o->otsu ? "above Otsu's threshold" : "finite");
        goto done;
    }
    mean /= (double)m;
    out->region_px = m;
    /* the 8-bit scale */
    out->lo = o->lo, out->hi = o->hi;
    if (!(o->hi > o->lo)) {
        qsort(sorted, m, sizeof *sorted, cmp_float);
        out->lo = sorted[(size_t)(0.005 * (double)(m - 1) + 0.5)];
        out->hi = sorted[(size_t)(0.995 * (double)(m - 1) + 0.5)];
    }
    /* LO = HI (99.5 % of the region one value: a star field, a point): LO and below 0, above it 255 */
    const double span = out->hi - out->lo; /* round(255 (v - LO) / (HI - LO)) in that order: halves up */
    for (size_t i = 0; i < n; i++) {
        const double v = !isfinite(img[i]) ? 0.0
                         : span > 0         ? floor(255.0 * (img[i] - out->lo) / span + 0.5)
                         : img[i] > out->lo ? 255
                                            : 0;
        u8[i] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
    }
    for (size_t i = 0; i < n; i++) /* the finite pixels: filled's bytes, before the spectrum needs it */
        ((uint8_t *)filled)[i] = isfinite(img[i]) != 0;
    const long corners = nc_texture_fast(u8, w, h, o->threshold, region, (const uint8_t *)filled, mask);
    if (corners < 0) {
        rc = (int)corners;
        goto done;
    }
    out->corners = (size_t)corners;
    out->corners_per_mpx = (double)out->corners / (double)m * 1e6;
    /* the spectrum, pixels off the region at the region's mean */
    for (size_t i = 0; i < n; i++)
        filled[i] = region[i] ? img[i] : (float)mean;
    out->psd_beta = nc_texture_psd_beta(filled, w, h, o->f_lo, o->f_hi, &out->psd_r2);
    /* gradients over the mean level */
    double sg = 0, sg2 = 0, sc = 0, sc2 = 0, sc4 = 0;
    size_t ng = 0;
    for (int pass = 0; pass < 2; pass++) {
        const double cm = ng ? sc / (2.0 * (double)ng) : 0.0; /* the components' mean (pass 1) */
        for (int y = 1; y < h - 1; y++)
            for (int x = 1; x < w - 1; x++) {
                const size_t i = (size_t)y * (size_t)w + (size_t)x;
                if (!region[i] || !region[i - 1] || !region[i + 1] || !region[i - (size_t)w] || !region[i + (size_t)w])
                    continue;
                const double gx = 0.5 * ((double)img[i + 1] - img[i - 1]) / mean, /* in double: +-3e38 apart */
                             gy = 0.5 * ((double)img[i + (size_t)w] - img[i - (size_t)w]) / mean;
                if (pass == 0) {
                    sg += sqrt(gx * gx + gy * gy);
                    sg2 += gx * gx + gy * gy;
                    sc += gx + gy;
                    ng++;
                } else {
                    const double a = gx - cm, b = gy - cm;
                    sc2 += a * a + b * b;
                    sc4 += a * a * a * a + b * b * b * b;
                }
            }
    }
    if (ng > 0) {
        out->grad_mean = sg / (double)ng;
        out->grad_rms = sqrt(sg2 / (double)ng);
        const double m2 = sc2 / (2.0 * (double)ng), m4 = sc4 / (2.0 * (double)ng);
        out->grad_kurtosis = m2 > 0 ? m4 / (m2 * m2) : NAN;
    }
done:
    free(region);
    free(u8);
    free(mask);
    free(sorted);
    free(filled);
    return rc;
}
