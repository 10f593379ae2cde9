/* test_camsys.c - the camera model, characterised like a real camera:
 * photon transfer in the style of EMVA 1288 (system gain, read noise, dark
 * current, saturation capacity, linearity) from flat and dark frames of the
 * same code path `navcam expose` uses; the radiometric chain against its
 * equation; vignetting against its formula; non-square pixels' area;
 * neighbours' shot noise independent; determinism; blooming without
 * saturation leaving the frame as it was; and no NaN/Inf for zero, tiny and
 * saturating exposures. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camsys.h"
#include "camera/load.h"
#include "core/config.h"
#include "core/error.h"
#include "testutil.h"

#define W 256
#define H 256

static const char camera_yaml[] =
    "camera: {width_px: 256, height_px: 256, focal_length_m: 0.05, pixel_pitch_m: 1.0e-5}\n"
    "optics:\n"
    "  f_number: 4\n"
    "  transmission: 0.8\n"
    "  passband: {band_fraction: 0.35, wavelength_m: 6.5e-7}\n"
    "  vignetting: none\n"
    "sensor:\n"
    "  qe: 0.6\n"
    "  dark_current_e_s: 40\n"
    "  dsnu_e_s: 4\n"
    "  prnu: 0.01\n"
    "  read_noise_e: 6\n"
    "  full_well_e: 20000\n"
    "  gain_e_per_dn: 2.5\n"
    "  bias_dn: 100\n"
    "  adc_bits: 14\n"
    "  seed: 42\n"
    "exposure: {time_s: 0.01}\n";

static void load(const char *const *sets, int nsets, struct nc_camera *g, struct nc_camsys *cs)
{
    const char *path = nc_test_path("camera.yaml");
    nc_test_write(path, camera_yaml);
    if (nc_camsys_load(path, sets, nsets, g, cs) < 0) {
        fprintf(stderr, "camera: %s\n", nc_errmsg());
        exit(2);
    }
}

/* Mean and temporal variance (EMVA 1288: half the variance of the difference
 * of two frames, which cancels the fixed patterns), in DN. */
static void frame_pair_stats(const struct nc_camsys *cs, const float *e, double t, uint64_t frame, double *mean,
                             double *var)
{
    static uint16_t a[W * H], b[W * H];
    nc_camsys_digitise(cs, e, t, frame, a);
    nc_camsys_digitise(cs, e, t, frame + 1, b);
    double s = 0, d2 = 0, dm = 0;
    for (int i = 0; i < W * H; i++) {
        s += a[i] + b[i];
        dm += (double)a[i] - b[i];
    }
    dm /= W * H;
    for (int i = 0; i < W * H; i++) {
        double d = (double)a[i] - b[i] - dm;
        d2 += d * d;
    }
    *mean = s / (2.0 * W * H);
    *var = d2 / (W * H - 1) / 2.0;
}

/* Saturation capacity (EMVA 1288: the mean at the maximum of the temporal
 * variance), in e-, from exposures stepped by 0.25% of full well around it.
 * Measured without PRNU: a response spread makes some pixels saturate early
 * and lowers the measured capacity (1% PRNU: 19450 e- for a 20000 e- well),
 * which is right for such a camera but not the configured well. */
static double saturation_capacity(double Kfit)
{
    const char *sets[] = {"sensor.prnu=0"};
    struct nc_camera g;
    struct nc_camsys cs;
    load(sets, 1, &g, &cs);
    static float rad[W * H], e[W * H];
    for (int i = 0; i < W * H; i++)
        rad[i] = 1.0f;
    double fw = cs.sensor.full_well_e, best = -1, at = 0;
    for (double f = 0.9; f <= 1.05; f += 0.0025) {
        double t = f * fw / cs.response[0], m, v, md, vd;
        nc_camsys_electrons(&cs, rad, t, e);
        frame_pair_stats(&cs, e, t, 20000 + (uint64_t)(f * 1e4), &m, &v);
        memset(e, 0, sizeof e);
        frame_pair_stats(&cs, e, t, 40000 + (uint64_t)(f * 1e4), &md, &vd);
        if (v > best)
            best = v, at = (m - md) / Kfit;
    }
    nc_camsys_free(&cs);
    return at;
}

static void photon_transfer(void)
{
    struct nc_camera g;
    struct nc_camsys cs;
    load(NULL, 0, &g, &cs);
    static float rad[W * H], e[W * H];
    /* A radiance that gives 1.2 full wells at the longest exposure. */
    const double L = 1.0, k = cs.response[0], fw = cs.sensor.full_well_e, K = nc_camsys_dn_per_e(&cs);
    const double tmax = 1.2 * fw / (L * k);
    enum { NT = 48 };
    double t[NT], mu_y[NT], var_y[NT], mu_d[NT], var_d[NT], mu_e_true[NT];
    for (int i = 0; i < W * H; i++)
        rad[i] = (float)L;
    for (int j = 0; j < NT; j++) {
        t[j] = tmax * j / (NT - 1);
        nc_camsys_electrons(&cs, rad, t[j], e);
        mu_e_true[j] = e[0];
        frame_pair_stats(&cs, e, t[j], 1000 + 2 * j, &mu_y[j], &var_y[j]);
        memset(e, 0, sizeof e);
        frame_pair_stats(&cs, e, t[j], 5000 + 2 * j, &mu_d[j], &var_d[j]);
    }
    /* System gain: slope of the temporal variance (minus dark) against the
     * mean (minus dark) below 70% of saturation. */
    double sxx = 0, sxy = 0, sx = 0, sy = 0;
    int n = 0;
    for (int j = 1; j < NT; j++) {
        if (mu_e_true[j] > 0.7 * fw)
            break;
        double x = mu_y[j] - mu_d[j], y = var_y[j] - var_d[j];
        sx += x, sy += y, sxx += x * x, sxy += x * y, n++;
    }
    double Kfit = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    double gain_fit = 1.0 / Kfit;
    /* Read noise from the dark temporal variance at zero exposure, less the
     * quantisation noise 1/12 DN^2. */
    double read_fit = sqrt(var_d[0] - 1.0 / 12.0) / Kfit;
    /* Dark current: slope of the dark mean against exposure time, over dark
     * frames long enough to collect a measurable dark signal (0 to 20 s). */
    double tx = 0, ty = 0, txx = 0, txy = 0;
    memset(e, 0, sizeof e);
    for (int j = 0; j < 11; j++) {
        double td = 2.0 * j, m, v;
        frame_pair_stats(&cs, e, td, 9000 + 2 * j, &m, &v);
        tx += td, ty += m, txx += td * td, txy += td * m;
    }
    double dark_fit = (11 * txy - tx * ty) / (11 * txx - tx * tx) / Kfit;
    double sat_fit = saturation_capacity(Kfit);
    /* Linearity: mean (minus dark) against exposure, fitted between 5% and 95%
     * of saturation; the error up to 90% of full well. */
    double lx = 0, ly = 0, lxx = 0, lxy = 0;
    int ln = 0;
    for (int j = 0; j < NT; j++) {
        double m = mu_y[j] - mu_d[j];
        if (mu_e_true[j] < 0.05 * fw || mu_e_true[j] > 0.95 * fw)
            continue;
        lx += t[j], ly += m, lxx += t[j] * t[j], lxy += t[j] * m, ln++;
    }
    double slope = (ln * lxy - lx * ly) / (ln * lxx - lx * lx), icpt = (ly - slope * lx) / ln, lin = 0;
    for (int j = 0; j < NT; j++) {
        if (mu_e_true[j] < 0.05 * fw || mu_e_true[j] > 0.9 * fw)
            continue;
        double m = mu_y[j] - mu_d[j], fit = icpt + slope * t[j];
        lin = fmax(lin, fabs(m - fit) / fit);
    }
    printf("photon transfer (%dx%d, %d exposures up to %.3g s):\n", W, H, NT, tmax);
    printf("  system gain      %.4f e-/DN (configured %.4f)\n", gain_fit, cs.sensor.gain_e_per_dn);
    printf("  read noise       %.4f e-    (configured %.4f)\n", read_fit, cs.sensor.read_noise_e);
    printf("  dark current     %.4f e-/s  (configured %.4f)\n", dark_fit, cs.sensor.dark_current_e_s);
    printf("  saturation       %.1f e-    (full well %.1f)\n", sat_fit, fw);
    printf("  linearity error  %.4f %% up to 90%% of full well\n", 100 * lin);
    CHECK(fabs(gain_fit / cs.sensor.gain_e_per_dn - 1) < 0.02, "system gain %.4f vs %.4f", gain_fit,
          cs.sensor.gain_e_per_dn);
    CHECK(fabs(read_fit / cs.sensor.read_noise_e - 1) < 0.02, "read noise %.4f vs %.4f", read_fit,
          cs.sensor.read_noise_e);
    CHECK(fabs(dark_fit / cs.sensor.dark_current_e_s - 1) < 0.02, "dark current %.4f vs %.4f", dark_fit,
          cs.sensor.dark_current_e_s);
    CHECK(fabs(sat_fit / fw - 1) < 0.02, "saturation capacity %.1f vs full well %.1f", sat_fit, fw);
    CHECK(lin < 0.005, "linearity error %.4f%%", 100 * lin);
    CHECK(fabs(K - 1 / cs.sensor.gain_e_per_dn) < 1e-15, "0 dB analog gain");
    nc_camsys_free(&cs);
}

static void radiometry(void)
{
    /* The camera equation, by hand: e-/s = QE band tau pi/(4 N^2) A_pix lambda/(h c) L. */
    struct nc_camera g;
    struct nc_camsys cs;
    load(NULL, 0, &g, &cs);
    double want = 0.6 * 0.35 * 0.8 * M_PI / (4 * 16) * 1e-10 * 6.5e-7 / (6.62607015e-34 * 299792458.0);
    CHECK(fabs(cs.response[0] / want - 1) < 1e-6 && fabs(cs.response[W * H - 1] / want - 1) < 1e-6,
          "response %.9g vs %.9g e-/s per W m^-2 sr^-1", cs.response[0], want);
    /* Analog gain scales as 10^(dB/20). */
    const char *sets[] = {"sensor.analog_gain_db=6"};
    struct nc_camsys c6;
    struct nc_camera g6;
    load(sets, 1, &g6, &c6);
    CHECK(fabs(nc_camsys_dn_per_e(&c6) / nc_camsys_dn_per_e(&cs) - pow(10, 0.3)) < 1e-12, "6 dB");
    nc_camsys_free(&c6);
    nc_camsys_free(&cs);

    /* cos^4 vignetting against its formula, with an off-centre pixel. */
    const char *v[] = {"optics.vignetting=cos4", "camera.focal_length_m=0.005"};
    load(v, 2, &g, &cs);
    double worst = 0;
    for (int y = 0; y < H; y += 17)
        for (int x = 0; x < W; x += 13) {
            double dx = (x - g.cx_px) * 1e-5, dy = (y - g.cy_px) * 1e-5, th = atan(sqrt(dx * dx + dy * dy) / 0.005);
            double c4 = pow(cos(th), 4);
            worst = fmax(worst, fabs(cs.response[y * W + x] / (want * c4) - 1));
        }
    CHECK(worst < 1e-6, "cos^4 vignetting off by %.3g", worst);
    nc_camsys_free(&cs);
    /* A vignetting table, linearly interpolated in field angle. */
    const char *vt[] = {"optics.vignetting=[[0, 1.0], [10, 0.9], [30, 0.5]]", "camera.focal_length_m=0.005"};
    load(vt, 2, &g, &cs);
    worst = 0;
    for (int x = 0; x < W; x += 7) {
        int y = H / 2;
        double dx = (x - g.cx_px) * 1e-5, dy = (y - g.cy_px) * 1e-5,
               th = atan(sqrt(dx * dx + dy * dy) / 0.005) * 180 / M_PI;
        double f = th <= 10 ? 1 - 0.01 * th : 0.9 - 0.02 * (th - 10);
        worst = fmax(worst, fabs(cs.response[y * W + x] / (want * f) - 1));
    }
    CHECK(worst < 1e-6, "vignetting table off by %.3g", worst);
    nc_camsys_free(&cs);
    /* A table of one row: that factor everywhere (it was refused as no table) */
    const char *v1[] = {"optics.vignetting=[[5, 0.5]]"};
    load(v1, 1, &g, &cs);
    CHECK(cs.response[0] == cs.response[W * H / 2 + W / 2] && fabs(cs.response[0] / (0.5 * want) - 1) < 1e-6,
          "a one-row vignetting table: %g and %g, want %g", cs.response[0], cs.response[W * H / 2 + W / 2],
          0.5 * want);
    nc_camsys_free(&cs);
}

static void robustness(void)
{
    struct nc_camera g;
    struct nc_camsys cs;
    const char *sets[] = {"sensor.blooming=true", "sensor.cosmic_rays={rate_cm2_s: 5, track_length_px: 8, e_per_px: 3000}",
                          "sensor.hot_pixel_fraction=0.001", "sensor.hot_pixel_dark_e_s=5000",
                          "optics.psf={type: gaussian, sigma_px: 1.2}"};
    load(sets, 5, &g, &cs);
    /* Radiance images are the render size: the sensor and the PSF's margin. */
    static float rad[(W + 64) * (H + 64)], e[W * H];
    const int nr = cs.render_width_px * cs.render_height_px;
    static uint16_t a[W * H], b[W * H];
    const double exposures[] = {0, 1e-12, 1e-6, 0.01, 10, 1e4};
    const float radiances[] = {0, 1e-30f, 1, 1e6f, 3e38f, NAN, INFINITY};
    int bad = 0;
    for (int k = 0; k < 7; k++)
        for (int j = 0; j < 6; j++) {
            for (int i = 0; i < nr; i++)
                rad[i] = radiances[k];
            nc_camsys_electrons(&cs, rad, exposures[j], e);
            for (int i = 0; i < W * H; i++)
                bad += !isfinite(e[i]) || e[i] < 0;
            nc_camsys_digitise(&cs, e, exposures[j], 7, a);
            for (int i = 0; i < W * H; i++)
                bad += a[i] > (1 << cs.sensor.adc_bits) - 1;
        }
    CHECK(bad == 0, "%d non-finite, negative or out-of-range values", bad);
    /* Saturation: everything at the top of the ADC or the full well. */
    for (int i = 0; i < nr; i++)
        rad[i] = 1e6f;
    nc_camsys_electrons(&cs, rad, 1.0, e);
    nc_camsys_digitise(&cs, e, 1.0, 3, a);
    double fw_dn = cs.sensor.bias_dn + cs.sensor.full_well_e / cs.sensor.gain_e_per_dn;
    int off = 0;
    for (int i = 0; i < W * H; i++)
        off += fabs(a[i] - fw_dn) > 6 * cs.sensor.read_noise_e / cs.sensor.gain_e_per_dn + 1;
    CHECK(off == 0, "%d saturated pixels away from full well", off);
    /* Determinism: the same frame number gives the same frame; another does not. */
    for (int i = 0; i < nr; i++)
        rad[i] = 0.2f;
    nc_camsys_electrons(&cs, rad, 0.01, e);
    nc_camsys_digitise(&cs, e, 0.01, 11, a);
    nc_camsys_digitise(&cs, e, 0.01, 11, b);
    CHECK(!memcmp(a, b, sizeof a), "frame 11 twice differs");
    nc_camsys_digitise(&cs, e, 0.01, 12, b);
    CHECK(memcmp(a, b, sizeof a) != 0, "frames 11 and 12 are identical");
    nc_camsys_free(&cs);
    /* Blooming moves charge only from saturated pixels: with none, the frame
     * is the one without blooming, DN for DN (its ADC was another path's: 68
     * pixels of a 1024x1024 frame 1 DN apart). */
    const char *gain[] = {"sensor.gain_e_per_dn=5", "sensor.analog_gain_db=3.7", "sensor.read_noise_e=8"};
    const char *bloom[] = {"sensor.gain_e_per_dn=5", "sensor.analog_gain_db=3.7", "sensor.read_noise_e=8",
                           "sensor.blooming=true"};
    struct nc_camsys c0, c1;
    load(gain, 3, &g, &c0);
    load(bloom, 4, &g, &c1);
    for (int i = 0; i < W * H; i++)
        e[i] = (float)(50 + 97 * (i % 101)); /* up to 9750 e-, under the 20000 e- well */
    nc_camsys_digitise(&c0, e, 0.01, 21, a);
    nc_camsys_digitise(&c1, e, 0.01, 21, b);
    int differ = 0;
    for (int i = 0; i < W * H; i++)
        differ += a[i] != b[i];
    CHECK(differ == 0, "blooming on, nothing saturated: %d pixels differ from the frame without it", differ);
    nc_camsys_free(&c0);
    nc_camsys_free(&c1);
}

static void shot_noise_statistics(void)
{
    /* Exact Poisson at low counts: mean and variance at 0.5, 3 and 20 e-,
     * with every other noise off. */
    const char *sets[] = {"sensor={qe: 1, read_noise_e: 0, gain_e_per_dn: 1, full_well_e: 1000, adc_bits: 16, seed: 9}"};
    struct nc_camera g;
    struct nc_camsys cs;
    load(sets, 1, &g, &cs);
    static float e[W * H];
    static uint16_t a[W * H];
    const double lam[] = {0.5, 3, 20, 100};
    for (int k = 0; k < 4; k++) {
        for (int i = 0; i < W * H; i++)
            e[i] = (float)lam[k];
        double s = 0, s2 = 0, p0 = 0;
        for (int f = 0; f < 4; f++) {
            nc_camsys_digitise(&cs, e, 0.0, 100 + f, a);
            for (int i = 0; i < W * H; i++) {
                s += a[i];
                s2 += (double)a[i] * a[i];
                p0 += a[i] == 0;
            }
        }
        double n = 4.0 * W * H, m = s / n, v = s2 / n - m * m;
        CHECK(fabs(m / lam[k] - 1) < 4 / sqrt(n * lam[k]) + 1e-3, "Poisson mean %.5f vs %g", m, lam[k]);
        CHECK(fabs(v / lam[k] - 1) < 0.02, "Poisson variance %.5f vs %g", v, lam[k]);
        if (lam[k] < 5)
            CHECK(fabs(p0 / n - exp(-lam[k])) < 0.004, "P(0) %.5f vs %.5f", p0 / n, exp(-lam[k]));
        printf("shot noise at %5.1f e-: mean %.4f, variance %.4f, P(0) %.4f (Poisson %.4f)\n", lam[k], m, v, p0 / n,
               exp(-lam[k]));
    }
    nc_camsys_free(&cs);
}

/* Neighbours' shot noise is independent: columns alternating 5 and 1000 e-
 * (a dim pixel beside a bright one at a limb or a star): the bright
 * pixels' variance is their mean whether the dim neighbour read 0 or not,
 * and their mean does not move with it (a dim pixel's uniform was its
 * neighbour's Box-Muller radius or angle: variance 6049 e-^2 beside a 0,
 * or a bias of +40 e-). Both orders of the pair. */
static void shot_noise_of_neighbours(void)
{
    const char *sets[] = {
        "sensor={qe: 1, read_noise_e: 0, gain_e_per_dn: 1, full_well_e: 60000, adc_bits: 16, seed: 3}"};
    struct nc_camera g;
    struct nc_camsys cs;
    load(sets, 1, &g, &cs);
    static float e[W * H];
    static uint16_t a[W * H];
    for (int odd = 0; odd < 2; odd++) {
        for (int i = 0; i < W * H; i++)
            e[i] = i % 2 == odd ? 1000.0f : 5.0f;
        double n[2] = {0, 0}, s[2] = {0, 0}, s2[2] = {0, 0}; /* bright pixels beside a dim 0, beside the rest */
        for (int f = 0; f < 8; f++) {
            nc_camsys_digitise(&cs, e, 0.0, 200 + (uint64_t)f, a);
            for (int i = 0; i < W * H; i += 2) {
                const int bright = i + odd, dim = i + 1 - odd, k = a[dim] != 0;
                const double d = a[bright] - 1000.0;
                n[k]++, s[k] += d, s2[k] += d * d;
            }
        }
        const double var0 = s2[0] / n[0] - (s[0] / n[0]) * (s[0] / n[0]), var1 = s2[1] / n[1];
        printf("shot noise, bright %s beside dim: beside a 0 (%.0f pairs) mean %+.2f e-, variance %.0f; beside the "
               "rest variance %.0f (Poisson 1000)\n", odd ? "odd" : "even", n[0], s[0] / n[0], var0, var1);
        CHECK(fabs(var0 / 1000 - 1) < 0.15 && fabs(var1 / 1000 - 1) < 0.02 && fabs(s[0] / n[0]) < 4 * sqrt(1000 / n[0]),
              "bright pixels beside dim ones: variance %.0f beside a 0, %.0f else, mean %+.2f e- beside a 0", var0,
              var1, s[0] / n[0]);
    }
    nc_camsys_free(&cs);
}

/* Non-square pixels (a SUM file's camera with |K11| != |K22|): a pixel is
 * f / fx wide and f / fy tall, its signal in proportion to its area. */
static void pixel_area(void)
{
    struct nc_camera g;
    struct nc_camsys sq, tall = {0};
    load(NULL, 0, &g, &sq);
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    struct nc_camera g2 = g; /* as a SUM file's camera with K22 = K11 / 2 makes it */
    g2.fy_px = g.fx_px / 2;
    CHECK(nc_cfg_load_string(&cfg, camera_yaml, "camera_yaml") == 0 &&
              nc_camsys_from_config(cfg.root, &g2, g.focal_length_m, &tall) == 0,
          "non-square pixels: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    const double ratio = tall.response ? tall.response[W * H / 2] / sq.response[W * H / 2] : 0;
    printf("pixels twice as tall as wide: %.6f times the signal of square ones\n", ratio);
    CHECK(fabs(ratio - 2) < 1e-9, "a pixel f/fx wide and f/fy tall (fy = fx / 2): %.9f times the signal, want 2",
          ratio);
    nc_camsys_free(&sq);
    nc_camsys_free(&tall);
}

/* Cosmic rays: the number of tracks follows rate x area x exposure, the
 * area W H pitch^2 fx / fy (pixels twice as tall as wide: twice the tracks;
 * an outside check found the same count for any fy). */
static void cosmic_ray_rate(void)
{
    for (int tall = 0; tall < 2; tall++) {
        const char *sets[] = {"sensor={read_noise_e: 0, shot_noise: false, gain_e_per_dn: 1, full_well_e: 60000, "
                              "seed: 5, cosmic_rays: {rate_cm2_s: 20, track_length_px: 0.01, e_per_px: 5000}}",
                              "camera={width_px: 256, height_px: 256, fx_px: 5000, fy_px: 2500}",
                              "sensor.pixel_pitch_m=1e-5"};
        struct nc_camera g;
        struct nc_camsys cs;
        load(sets, 1 + 2 * tall, &g, &cs);
        static float e[W * H];
        static uint16_t a[W * H];
        memset(e, 0, sizeof e);
        /* 256 x 256 x (10 um)^2 = 0.065536 cm^2; 20 /cm^2/s x 2 s: 2.62 tracks a
         * frame; tracks this short deposit one pixel each. */
        long hits = 0;
        const int frames = 400;
        for (int f = 0; f < frames; f++) {
            nc_camsys_digitise(&cs, e, 2.0, (uint64_t)f, a);
            for (int i = 0; i < W * H; i++)
                hits += a[i] > 2500;
        }
        double want = 20 * 0.065536 * (1 + tall) * 2.0 * frames, sd = sqrt(want);
        printf("cosmic rays, pixels %s: %ld hit pixels in %d frames, expected %.0f +- %.0f\n",
               tall ? "twice as tall as wide" : "square", hits, frames, want, sd);
        CHECK(fabs(hits - want) < 4 * sd, "cosmic ray hits %ld, expected %.0f", hits, want);
        nc_camsys_free(&cs);
    }
}

/* Cosmic-ray tracks share their charge by the length inside each pixel:
 * e_per_px for a pixel crossed straight, more diagonally (up to sqrt 2
 * times), less across a corner. Point samples along the track gave each
 * pixel whole multiples of about e_per_px / 2: none under 300 e- of 1000,
 * 8.6 % over 1414 (an outside check). */
static void cosmic_ray_tracks(void)
{
    const char *sets[] = {"sensor={read_noise_e: 0, shot_noise: false, gain_e_per_dn: 1, full_well_e: 60000, "
                          "adc_bits: 16, seed: 3, cosmic_rays: {rate_cm2_s: 30, track_length_px: 60, e_per_px: 1000}}"};
    struct nc_camera g;
    struct nc_camsys cs;
    load(sets, 1, &g, &cs);
    static float e[W * H];
    static uint16_t a[W * H];
    memset(e, 0, sizeof e);
    long lit = 0, low = 0, high = 0;
    for (int f = 0; f < 100; f++) { /* about 4 tracks a frame */
        nc_camsys_digitise(&cs, e, 2.0, (uint64_t)f, a);
        for (int i = 0; i < W * H; i++) {
            lit += a[i] > 0;
            low += a[i] > 0 && a[i] < 300;
            high += a[i] > 1415; /* sqrt(2) e_per_px, rounded up: only where two tracks cross */
        }
    }
    printf("cosmic-ray tracks: %ld pixels hit, %.1f %% under 300 e-, %.2f %% over 1415 e-\n", lit,
           100.0 * low / fmax(1, lit), 100.0 * high / fmax(1, lit));
    CHECK(lit > 5000 && low > 0.05 * lit && high < 0.005 * lit,
          "charge by length: %ld hit, %ld under 300, %ld over 1415", lit, low, high);
    nc_camsys_free(&cs);
}

int main(void)
{
    cosmic_ray_rate();
    cosmic_ray_tracks();
    photon_transfer();
    radiometry();
    shot_noise_statistics();
    shot_noise_of_neighbours();
    pixel_area();
    robustness();
    return nc_test_end();
}
