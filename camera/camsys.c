/* camsys.c - the radiance -> electrons -> DN chain of the camera model
 * (camsys.h): PSF, shot, dark and read noise, cosmic rays, full well and
 * blooming, gain and the ADC. Configuration: camsys_config.c. */
#include "camera/camsys.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "camera/rng.h"
#include "render/vmath.h"

/* The most charge a pixel is given before noise and the full well, e-:
 * beyond any full well (1e9), and far below a float's range, so that
 * sqrt(charge) times a normal stays finite. */
#define CHARGE_MAX_E 1e30f

double nc_camsys_dn_per_e(const struct nc_camsys *cs)
{
    return exp10(cs->sensor.analog_gain_db / 20.0) / cs->sensor.gain_e_per_dn;
}

/* Photo-electrons: radiance x response x exposure. Far beyond any full well,
 * charge is capped so that a float holds it; NaN fails both comparisons and
 * becomes 0. */
__attribute__((target_clones("avx2", "default")))
static void scale_row(const float *restrict radiance, const float *restrict response, double exposure_s, size_t n,
                      float *restrict out)
{
    const float t = (float)exposure_s;
    for (size_t p = 0; p < n; p++) {
        float v = radiance[p] * response[p] * t;
        out[p] = v > 0 ? (v < 1e30f ? v : 1e30f) : 0.0f;
    }
}

int nc_camsys_electrons(const struct nc_camsys *cs, const float *radiance, double exposure_s, float *electrons)
{
    if (!(cs->sensor.pixel_pitch_m > 0))
        return nc_error(NC_ECONFIG, "%s: electrons and DN need the pixel pitch: set camera.focal_length_m with "
                                    "camera.pixel_pitch_m, or sensor.pixel_pitch_m", cs->where);
    const int RW = cs->render_width_px, RH = cs->render_height_px, m = cs->margin_px;
    if (cs->optics.psf.size <= 1) { /* no margin: straight into the sensor's image */
        scale_row(radiance, cs->response, exposure_s, (size_t)RW * (size_t)RH, electrons);
        return 0;
    }
    scale_row(radiance, cs->response, exposure_s, (size_t)RW * (size_t)RH, cs->scratch[0]);
    int rc = nc_psf_apply_scratch(&cs->optics.psf, cs->scratch[0], cs->scratch[2], RW, RH, cs->scratch[1]);
    if (rc < 0)
        return rc;
    for (int y = 0; y < cs->height_px; y++)
        memcpy(electrons + (size_t)y * cs->width_px, cs->scratch[2] + (size_t)(y + m) * RW + m,
               (size_t)cs->width_px * sizeof *electrons);
    return 0;
}

/* Exact Poisson sampling by inversion (used below 32 e-), given
 * p0 = exp(-lambda) and a uniform u: the smallest k with CDF(k) >= u. */
static inline float poisson_inversion(double lambda, double p0, double u)
{
    double p = p0, cdf = p;
    int k = 0;
    while (u > cdf && k < 200) {
        k++;
        p *= lambda / k;
        cdf += p;
    }
    return (float)k;
}

/* Charge q along the segment from (x, y) (pixel units, pixel (i, j) the
 * square [i, i + 1) x [j, j + 1)) at angle a, len long, into the pixels of
 * the W x H image e in proportion to the length inside each (all of it in
 * the first pixel if len is 0); what runs off the image is lost. The
 * pixels crossed in turn, each boundary where the segment meets it. */
static void track(double x, double y, double a, double len, double q, int W, int H, double *e)
{
    const double dx = cos(a), dy = sin(a);
    int i = (int)floor(x), j = (int)floor(y);
    const int si = dx > 0 ? 1 : -1, sj = dy > 0 ? 1 : -1;
    /* distances along the track to the next column and row boundary, and between boundaries */
    const double di = dx != 0 ? 1 / fabs(dx) : INFINITY, dj = dy != 0 ? 1 / fabs(dy) : INFINITY;
    double ti = dx != 0 ? ((dx > 0 ? i + 1 - x : x - i) * di) : INFINITY,
           tj = dy != 0 ? ((dy > 0 ? j + 1 - y : y - j) * dj) : INFINITY, t = 0;
    for (int n = 0; n < 1 << 20; n++) {
        const double next = fmin(fmin(ti, tj), len);
        const double share = len > 0 ? q * (next - t) / len : q;
        if (i >= 0 && i < W && j >= 0 && j < H)
            e[(size_t)j * W + i] += share;
        if (!(next < len))
            break;
        t = next;
        if (ti <= tj)
            i += si, ti += di;
        else
            j += sj, tj += dj;
    }
}

/* Cosmic-ray charge for this frame, added into e (keyed by seed and frame). */
static void cosmic_rays(const struct nc_camsys *cs, double exposure_s, uint64_t frame, double *e)
{
    const struct nc_sensor *s = &cs->sensor;
    const int W = cs->width_px, H = cs->height_px;
    double area_cm2 = W * H * cs->pixel_area_m2 * 1e4;
    double mean = s->cosmic_rate_cm2_s * area_cm2 * exposure_s, u[4];
    nc_rng4(s->seed, NC_RNG_COSMIC, frame, 0xffffffffu, 0, u);
    /* Number of hits: Poisson by inversion in blocks of uniforms. */
    long hits = 0;
    {
        double p = exp(-fmin(mean, 700)), cdf = p;
        if (mean < 500) {
            while (u[0] > cdf && hits < 1000000) {
                hits++;
                p *= mean / hits;
                cdf += p;
            }
        } else {
            double z1, z2;
            nc_normal2(u[1], u[2], &z1, &z2);
            hits = (long)fmax(0.0, floor(mean + sqrt(mean) * z1 + 0.5));
        }
    }
    for (long h = 0; h < hits; h++) {
        nc_rng4(s->seed, NC_RNG_COSMIC, frame, (uint32_t)h, 1, u);
        const double len = -s->cosmic_track_px * log(u[3]);
        /* e_per_px per pixel of projected track (a track shorter than a
         * pixel, near-normal incidence, still crosses the whole depth of
         * one), each pixel's share the length of track inside it */
        track(u[0] * W, u[1] * H, 2 * M_PI * u[2], len, s->cosmic_e_per_px * (len > 1.0 ? len : 1.0), W, H, e);
    }
}

/* q[x]: electrons after shot noise, or -1 where exact inversion must decide
 * (lambda < 32 and u > P(0)). Single precision (24-bit: whole electrons are
 * exact below 16.7 M e-), selects and no branches, so that it vectorises. */
__attribute__((target_clones("avx2", "default")))
static void charge_row(const float *restrict lam, const float *restrict p0, const float *restrict u,
                       const float *restrict zs, int W, int shot, float *restrict q)
{
    for (int x = 0; x < W; x++) {
        /* variance lambda - 1/12: rounding to whole electrons adds 1/12 back */
        float hi = floorf(lam[x] + sqrtf(lam[x] - 0.083333333f) * zs[x] + 0.5f);
        hi = hi > 0 ? hi : 0.0f;
        float lo = u[x] <= p0[x] ? 0.0f : -1.0f;
        q[x] = !shot ? lam[x] : lam[x] >= 32.0f ? hi : lo;
    }
}

/* DN = round(bias + (min(q, full well) + read noise z) g), clipped. */
__attribute__((target_clones("avx2", "default")))
static void digitise_row(const float *restrict q, const float *restrict zr, int W, float fw, float rn_e, float bias,
                         float g, float top, uint16_t *restrict dn)
{
    for (int x = 0; x < W; x++) {
        float v = floorf(bias + ((q[x] < fw ? q[x] : fw) + rn_e * zr[x]) * g + 0.5f);
        v = v < 0 ? 0 : v > top ? top : v;
        dn[x] = (uint16_t)(int32_t)v;
    }
}

/* The random numbers of one image row: for each pair of pixels one Philox
 * call keyed by (seed, frame, pair) gives four 24-bit uniforms in (0, 1):
 * Box-Muller pair A (u0, u1) gives both pixels' read-noise normals, pair B
 * (u2, u3) their shot-noise normals at high counts; a call of block 1 for
 * each four pixels gives each its own uniform for exact Poisson sampling at
 * low counts (poisson_uniforms; only in rows that have such a pixel).
 * No draw serves two pixels' charges (a dim pixel's uniform was its bright
 * neighbour's Box-Muller radius or angle: where the dim one read 0, the
 * bright one's variance was six times its mean). Single precision and vector
 * batches: plenty for noise, and the whole frame takes a few milliseconds. */
struct row_rng {
    uint32_t *w;                 /* 4 words per pair */
    float *u, *lr, *ang, *s, *c; /* 2 per pixel each */
    float *zr, *zs;              /* per pixel: read-noise and shot-noise normals */
};

__attribute__((target_clones("avx2", "default")))
static void row_normals(const struct nc_camsys *cs, uint64_t frame, int y, int W, struct row_rng *b)
{
    const int pairs = (W + 1) / 2;
    uint32_t *const w[4] = {b->w, b->w + pairs, b->w + 2 * pairs, b->w + 3 * pairs};
    const float scale = 0x1.0p-24f;
    nc_rng_words(cs->sensor.seed, NC_RNG_PIXEL_NOISE, frame, (uint32_t)((size_t)y * (size_t)pairs), 0,
                 (size_t)pairs, w);
    for (int k = 0; k < pairs; k++) {
        float u0 = ((float)(w[0][k] >> 8) + 0.5f) * scale, u1 = ((float)(w[1][k] >> 8) + 0.5f) * scale;
        float u2 = ((float)(w[2][k] >> 8) + 0.5f) * scale, u3 = ((float)(w[3][k] >> 8) + 0.5f) * scale;
        b->lr[2 * k] = u0;
        b->lr[2 * k + 1] = u2;
        b->ang[2 * k] = 2.0f * u1;
        b->ang[2 * k + 1] = 2.0f * u3;
    }
    nc_vlogf(b->lr, (size_t)2 * pairs);
    nc_vsincospif(b->ang, b->s, b->c, (size_t)2 * pairs);
    for (int i = 0; i < 2 * pairs; i++)
        b->lr[i] = sqrtf(-2.0f * b->lr[i]);
    /* Even pixels take the cosines, odd pixels the sines. */
    for (int k = 0; k < pairs; k++) {
        b->zr[2 * k] = b->lr[2 * k] * b->c[2 * k];
        b->zr[2 * k + 1] = b->lr[2 * k] * b->s[2 * k];
        b->zs[2 * k] = b->lr[2 * k + 1] * b->c[2 * k + 1];
        b->zs[2 * k + 1] = b->lr[2 * k + 1] * b->s[2 * k + 1];
    }
}

/* Row y's uniforms of exact Poisson sampling into b->u, one per pixel:
 * Philox block 1, four pixels a call (b->w holds the words). */
static void poisson_uniforms(const struct nc_camsys *cs, uint64_t frame, int y, int W, struct row_rng *b)
{
    const int quads = (W + 3) / 4;
    uint32_t *const w[4] = {b->w, b->w + quads, b->w + 2 * quads, b->w + 3 * quads};
    nc_rng_words(cs->sensor.seed, NC_RNG_PIXEL_NOISE, frame, (uint32_t)((size_t)y * (size_t)quads), 1, (size_t)quads,
                 w);
    for (int x = 0; x < W; x++)
        b->u[x] = ((float)(w[x & 3][x >> 2] >> 8) + 0.5f) * 0x1.0p-24f;
}

int nc_camsys_digitise(const struct nc_camsys *cs, const float *electrons, double exposure_s, uint64_t frame,
                       uint16_t *dn)
{
    const struct nc_sensor *s = &cs->sensor;
    const int W = cs->width_px, H = cs->height_px;
    const size_t n = (size_t)W * (size_t)H;
    const double fw = s->full_well_e, g = nc_camsys_dn_per_e(cs), top = ldexp(1.0, s->adc_bits) - 1.0;
    const int pairs = (W + 1) / 2, nb = 2 * pairs;
    /* Charge and read-noise normals for the whole frame only when charge moves
     * between pixels (cosmic rays, blooming); otherwise row by row. */
    const int whole = s->blooming || s->cosmic_rate_cm2_s > 0;
    double *e = whole ? malloc(n * sizeof *e) : NULL;
    float *rn = whole ? malloc(n * sizeof *rn) : NULL;
    float *buf = calloc((size_t)nb * 8, sizeof *buf); /* b.u read (not used) in rows without low counts */
    uint32_t *words = malloc((size_t)pairs * 4 * sizeof *words);
    float *lam = malloc((size_t)nb * 2 * sizeof *lam), *q = lam + nb;
    if (!buf || !words || !lam || (whole && (!e || !rn))) {
        free(e);
        free(rn);
        free(buf);
        free(words);
        free(lam);
        return nc_error(-ENOMEM, "out of memory");
    }
    struct row_rng b = {words, buf, buf + nb, buf + 2 * nb, buf + 3 * nb, buf + 4 * nb, buf + 6 * nb, buf + 7 * nb};
    float *p0 = buf + 5 * nb;
    for (int y = 0; y < H; y++) {
        const size_t o = (size_t)y * (size_t)W;
        row_normals(cs, frame, y, W, &b);
        /* Charge: response pattern and dark current; exp(-lambda) for the
         * low-count pixels in one batch. */
        const float t = (float)exposure_s;
        int low = 0;
        for (int x = 0; x < W; x++) {
            const float c = electrons[o + x] * cs->prnu_map[o + x] + cs->dark_map[o + x] * t;
            lam[x] = c < CHARGE_MAX_E ? c : CHARGE_MAX_E; /* a charge beyond any well, kept finite */
            p0[x] = lam[x] < 40.0f ? -lam[x] : -40.0f;
            low |= lam[x] < 32.0f;
        }
        if (s->shot_noise && low)
            poisson_uniforms(cs, frame, y, W, &b);
        if (s->shot_noise)
            nc_vexpf(p0, (size_t)W);
        /* Charge after shot noise, branch-free for the common cases: the
         * normal approximation at >= 32 e-, and k = 0 at low counts when
         * u <= P(0); the rest (low counts, k >= 1) by exact inversion below. */
        charge_row(lam, p0, b.u, b.zs, W, s->shot_noise, q);
        for (int x = 0; x < W; x++)
            if (q[x] < 0)
                q[x] = poisson_inversion(lam[x], p0[x], b.u[x]);
        if (whole) {
            for (int x = 0; x < W; x++) {
                e[o + x] = q[x];
                rn[o + x] = b.zr[x];
            }
            continue;
        }
        digitise_row(q, b.zr, W, (float)fw, (float)s->read_noise_e, (float)s->bias_dn, (float)g, (float)top, dn + o);
    }
    free(buf);
    free(words);
    if (!whole) {
        free(lam);
        return 0;
    }
    if (s->cosmic_rate_cm2_s > 0)
        cosmic_rays(cs, exposure_s, frame, e);
    /* Full well: the excess is lost, or with blooming spills half up and half
     * down the column, cascading through saturated pixels. */
    if (s->blooming) {
        double *up = malloc((size_t)H * sizeof *up);
        if (!up) {
            free(e);
            free(rn);
            free(lam);
            return nc_error(-ENOMEM, "out of memory");
        }
        for (int x = 0; x < W; x++) {
            double carry = 0;
            for (int y = 0; y < H; y++) {
                double *v = &e[(size_t)y * W + x];
                double ex = *v > fw ? *v - fw : 0;
                *v -= ex;
                up[y] = 0.5 * ex;
                *v += carry;
                carry = 0.5 * ex;
                if (*v > fw) {
                    carry += *v - fw;
                    *v = fw;
                }
            }
            carry = 0;
            for (int y = H - 1; y >= 0; y--) {
                double *v = &e[(size_t)y * W + x];
                *v += carry;
                carry = up[y];
                if (*v > fw) {
                    carry += *v - fw;
                    *v = fw;
                }
            }
        }
        free(up);
    }
    /* the row path's ADC (single precision): a pixel no charge reached or
     * left is the same DN with and without blooming and cosmic rays */
    for (int y = 0; y < H; y++) {
        const size_t o = (size_t)y * (size_t)W;
        for (int x = 0; x < W; x++)
            q[x] = (float)e[o + x];
        digitise_row(q, rn + o, W, (float)fw, (float)s->read_noise_e, (float)s->bias_dn, (float)g, (float)top, dn + o);
    }
    free(lam);
    free(e);
    free(rn);
    return 0;
}
