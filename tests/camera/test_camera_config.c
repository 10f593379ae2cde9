/* test_camera_config.c - the camera model where independent checks found
 * it wrong (issue 12), each against the physics it must follow:
 * - a flat field stays flat to the very edge through the PSF (the lens
 *   spreads light from outside the field into the edge pixels), and the
 *   margin the renderer draws is the same camera, shifted;
 * - the dark current, its non-uniformity and the hot pixels follow the
 *   doubling law together: the mean equals the configured law at every
 *   temperature, and the per-pixel spread keeps its relative size;
 * - a passband given by its edges is integrated through the 5772 K solar
 *   spectrum (500-700 nm: 0.241 of the power, effective wavelength 596 nm),
 *   like the same band as a table, and the example camera uses it;
 * - one pixel pitch: a sensor pitch that disagrees with the camera's is an
 *   error naming the file and line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camsys.h"
#include "camera/load.h"
#include "core/error.h"
#include "render/image_io.h"
#include "testutil.h"

static const char base_yaml[] =
    "camera: {width_px: 64, height_px: 48, focal_length_m: 0.025, pixel_pitch_m: 5.5e-6}\n"
    "optics: {f_number: 4, vignetting: none, psf: {type: gaussian, sigma_px: 0.7}}\n"
    "sensor: {shot_noise: false, read_noise_e: 0, prnu: 0, full_well_e: 1e9, gain_e_per_dn: 1, adc_bits: 16}\n";

static int load(const char *yaml, const char *const *sets, int nsets, struct nc_camera *g, struct nc_camsys *cs)
{
    const char *path = nc_test_path("camera.yaml");
    nc_test_write(path, yaml);
    return nc_camsys_load(path, sets, nsets, g, cs);
}

static void flat_to_the_edge(void)
{
    const char *psfs[] = {"optics.psf={type: gaussian, sigma_px: 0.7}", "optics.psf={type: gaussian, sigma_px: 3}",
                          "optics.psf={type: airy}"};
    for (int k = 0; k < 3; k++) {
        struct nc_camera g;
        struct nc_camsys cs;
        if (load(base_yaml, &psfs[k], 1, &g, &cs) < 0) {
            CHECK(0, "%s: %s", psfs[k], nc_errmsg());
            continue;
        }
        int W = cs.width_px, H = cs.height_px, m = cs.margin_px;
        CHECK(m == cs.optics.psf.size / 2 && cs.render_width_px == W + 2 * m && cs.render_height_px == H + 2 * m,
              "%s: margin %d for a %d px kernel", psfs[k], m, cs.optics.psf.size);
        size_t nr = (size_t)cs.render_width_px * cs.render_height_px;
        float *rad = malloc(nr * sizeof *rad), *e = malloc((size_t)W * H * sizeof *e);
        for (size_t i = 0; i < nr; i++)
            rad[i] = 2.0f;
        CHECK(nc_camsys_electrons(&cs, rad, 0.002, e) == 0, "electrons: %s", nc_errmsg());
        double centre = e[(H / 2) * W + W / 2], worst = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                worst = fmax(worst, fabs(e[y * W + x] / centre - 1));
        printf("%-44s margin %2d px: flat field, worst pixel %.2e from the centre (column 0 %.6f, corner %.6f)\n",
               psfs[k], m, worst, e[(H / 2) * W] / centre, e[0] / centre);
        CHECK(worst < 1e-5, "%s: a flat field is not flat: worst pixel %.3g off the centre", psfs[k], worst);
        /* The margin is the same camera: rendered pixel (x + m, y + m) looks
         * where sensor pixel (x, y) does. */
        struct nc_camera r;
        nc_camsys_render_camera(&cs, &g, &r);
        struct nc_vec3 a = nc_camera_ray(&g, 0, 0), b = nc_camera_ray(&r, m, m);
        struct nc_vec3 c = nc_camera_ray(&g, W - 1, H - 1), d = nc_camera_ray(&r, W - 1 + m, H - 1 + m);
        CHECK(nc_v3_norm(nc_v3_sub(a, b)) < 1e-12 && nc_v3_norm(nc_v3_sub(c, d)) < 1e-12,
              "%s: the render camera is not the sensor's camera shifted by the margin", psfs[k]);
        free(rad);
        free(e);
        nc_camsys_free(&cs);
    }
}

/* Mean and relative rms of the dark map (e-/s per pixel). */
static void dark_stats(const struct nc_camsys *cs, double *mean, double *rel_rms)
{
    size_t n = (size_t)cs->width_px * cs->height_px;
    double s = 0, s2 = 0;
    for (size_t i = 0; i < n; i++)
        s += cs->dark_map[i];
    *mean = s / n;
    for (size_t i = 0; i < n; i++)
        s2 += (cs->dark_map[i] - *mean) * (cs->dark_map[i] - *mean);
    *rel_rms = sqrt(s2 / (n - 1)) / *mean;
}

static void dark_current_at_temperature(void)
{
    const char *yaml = "camera: {width_px: 256, height_px: 256, focal_length_m: 0.025, pixel_pitch_m: 5.5e-6}\n"
                       "optics: {f_number: 4}\n"
                       "sensor: {dark_current_e_s: 30, dark_ref_temp_k: 293.15, dark_doubling_k: 6.5, dsnu_e_s: 6,\n"
                       "         read_noise_e: 0, gain_e_per_dn: 1, full_well_e: 1e6, adc_bits: 16, bias_dn: 100}\n";
    const double temps[] = {250, 283.15, 293.15, 320};
    for (int k = 0; k < 4; k++) {
        char set[64];
        snprintf(set, sizeof set, "sensor.temperature_k=%g", temps[k]);
        const char *sets[] = {set};
        struct nc_camera g;
        struct nc_camsys cs;
        if (load(yaml, sets, 1, &g, &cs) < 0) {
            CHECK(0, "%s", nc_errmsg());
            return;
        }
        double law = 30 * exp2((temps[k] - 293.15) / 6.5), mean, rel;
        dark_stats(&cs, &mean, &rel);
        /* The measurement: 0 s and long darks, difference of means
         * (100 s, or shorter when that would fill the 16-bit ADC). */
        double t = fmin(100, 3000 / law);
        int n = 256 * 256;
        float *e = calloc((size_t)n, sizeof *e);
        uint16_t *d0 = malloc((size_t)n * 2), *d1 = malloc((size_t)n * 2);
        nc_camsys_digitise(&cs, e, 0, 1, d0);
        nc_camsys_digitise(&cs, e, t, 2, d1);
        double s = 0;
        for (int i = 0; i < n; i++)
            s += (double)d1[i] - d0[i];
        double measured = s / n / t;
        printf("T %6.2f K: dark law %8.4f e-/s, pixel mean %8.4f (%+.2f%%), from %5.1f s darks %8.4f (%+.2f%%), "
               "DSNU %.3f of the mean\n",
               temps[k], law, mean, 100 * (mean / law - 1), t, measured, 100 * (measured / law - 1), rel);
        CHECK(fabs(mean / law - 1) < 0.01, "T %g K: mean dark %g e-/s, law %g", temps[k], mean, law);
        CHECK(fabs(measured / law - 1) < 0.02, "T %g K: dark from frames %g e-/s, law %g", temps[k], measured, law);
        CHECK(fabs(rel - 0.2) < 0.01, "T %g K: DSNU %g of the mean, configured 6/30 = 0.2", temps[k], rel);
        free(e);
        free(d0);
        free(d1);
        nc_camsys_free(&cs);
    }
    /* Hot pixels follow the same law. */
    const char *sets[] = {"sensor.dsnu_e_s=0", "sensor.hot_pixel_fraction=1", "sensor.hot_pixel_dark_e_s=1000",
                          "sensor.temperature_k=280.15"};
    struct nc_camera g;
    struct nc_camsys cs;
    if (load(yaml, sets, 4, &g, &cs) == 0) {
        double mean, rel, want = 1030 * exp2(-13 / 6.5);
        dark_stats(&cs, &mean, &rel);
        CHECK(fabs(mean / want - 1) < 1e-5, "hot pixels at 280.15 K: %g e-/s, want %g", mean, want);
        nc_camsys_free(&cs);
    }
    /* PRNU as large as its range allows: a log-normal factor, mean 1, never 0 (a normal one clipped at 0 had a
     * mean of 1.087 and 16 % of the pixels dead); a rolling shutter of line time 0 reads every row at once. */
    const char *prnu[] = {"sensor.dsnu_e_s=0", "sensor.prnu=1", "sensor.shutter=rolling", "sensor.line_time_s=0"};
    if (load(yaml, prnu, 4, &g, &cs) == 0) {
        double sum = 0, sum2 = 0, lo = INFINITY;
        for (int i = 0; i < 256 * 256; i++)
            sum += cs.prnu_map[i], sum2 += (double)cs.prnu_map[i] * cs.prnu_map[i], lo = fmin(lo, cs.prnu_map[i]);
        const double mean = sum / (256 * 256), rms = sqrt(sum2 / (256 * 256) - mean * mean) / mean;
        printf("prnu 1: mean response %.4f, relative rms %.4f, least %.3g\n", mean, rms, lo);
        CHECK(fabs(mean - 1) < 0.02 && fabs(rms - 1) < 0.06 && lo > 0, "prnu 1: mean response %g, rms %g, least %g",
              mean, rms, lo);
        nc_camsys_free(&cs);
    } else
        CHECK(0, "prnu 1, rolling shutter of line time 0: %s", nc_errmsg());
    /* A non-uniformity of nothing is a configuration error. */
    const char *zero[] = {"sensor.dark_current_e_s=0"};
    CHECK(load(yaml, zero, 1, &g, &cs) < 0 && nc_test_contains(nc_errmsg(), "sensor.dsnu_e_s") &&
              nc_test_contains(nc_errmsg(), "dark_current_e_s > 0"),
          "DSNU without dark current: %s", nc_errmsg());
    /* A dark current beyond a float's range (4e38 e-/s: half the pixels read the bias) is a configuration error. */
    const char *hot[] = {"sensor.temperature_k=1000", "sensor.dark_doubling_k=5.7"};
    CHECK(load(yaml, hot, 2, &g, &cs) < 0 && nc_test_contains(nc_errmsg(), "sensor.temperature_k: the dark current at "
                                                                            "1000 K") &&
              nc_test_contains(nc_errmsg(), "e-/s a pixel: more than 1e+15"),
          "dark current out of range: %s", nc_errmsg());
}

static void passband_from_edges(void)
{
    struct nc_camera g;
    struct nc_camsys cs;
    const char *edges[] = {"optics.passband={from_m: 5.0e-7, to_m: 7.0e-7}"};
    CHECK(load(base_yaml, edges, 1, &g, &cs) == 0, "%s", nc_errmsg());
    double bf = cs.optics.band_fraction, wl = cs.optics.wavelength_m;
    nc_camsys_free(&cs);
    const char *table[] = {"optics.passband_table=[[5.0e-7, 1], [7.0e-7, 1]]"};
    CHECK(load(base_yaml, table, 1, &g, &cs) == 0, "%s", nc_errmsg());
    printf("500-700 nm of a 5772 K Sun: band fraction %.4f, effective wavelength %.1f nm (table form %.4f, %.1f nm)\n",
           bf, wl * 1e9, cs.optics.band_fraction, cs.optics.wavelength_m * 1e9);
    CHECK(fabs(bf - 0.2408) < 0.0005 && fabs(wl - 596.0e-9) < 0.5e-9, "500-700 nm: %g, %g m", bf, wl);
    CHECK(fabs(cs.optics.band_fraction - bf) < 1e-12 && fabs(cs.optics.wavelength_m - wl) < 1e-18,
          "edges and table disagree");
    nc_camsys_free(&cs);
    /* The example camera and the default scene now say what they mean. */
    char path[4096];
    snprintf(path, sizeof path, "%s/configs/examples/navcam_camera.yaml", NC_SOURCE_DIR);
    CHECK(nc_camsys_load(path, NULL, 0, &g, &cs) == 0, "%s", nc_errmsg());
    CHECK(fabs(cs.optics.band_fraction - 0.2408) < 0.0005, "example camera: band fraction %g", cs.optics.band_fraction);
    nc_camsys_free(&cs);
    /* Errors: both forms, one edge, reversed edges. */
    const char *both[] = {"optics.passband={band_fraction: 0.3, wavelength_m: 6e-7, from_m: 5e-7, to_m: 7e-7}"};
    CHECK(load(base_yaml, both, 1, &g, &cs) < 0 && nc_test_contains(nc_errmsg(), "not both"), "%s", nc_errmsg());
    const char *one[] = {"optics.passband={from_m: 5e-7}"};
    CHECK(load(base_yaml, one, 1, &g, &cs) < 0 && nc_test_contains(nc_errmsg(), "optics.passband.to_m"), "%s",
          nc_errmsg());
    const char *rev[] = {"optics.passband={from_m: 7e-7, to_m: 5e-7}"};
    CHECK(load(base_yaml, rev, 1, &g, &cs) < 0 && nc_test_contains(nc_errmsg(), "to_m > from_m"), "%s", nc_errmsg());
}

static void one_pixel_pitch(void)
{
    struct nc_camera g;
    struct nc_camsys cs;
    const char *same[] = {"sensor.pixel_pitch_m=5.5e-6"};
    CHECK(load(base_yaml, same, 1, &g, &cs) == 0, "the same pitch twice: %s", nc_errmsg());
    nc_camsys_free(&cs);
    const char *clash =
        "camera: {width_px: 64, height_px: 48, focal_length_m: 0.025, pixel_pitch_m: 5.5e-6}\n"
        "sensor:\n"
        "  qe: 0.5\n"
        "  pixel_pitch_m: 6.0e-6\n";
    CHECK(load(clash, NULL, 0, &g, &cs) < 0 && nc_test_contains(nc_errmsg(), "camera.yaml:4: sensor.pixel_pitch_m") &&
              nc_test_contains(nc_errmsg(), "disagrees with the camera's pixel pitch"),
          "a second, different pitch: %s", nc_errmsg());
    /* A camera given in pixels (fx_px) has no pitch: the sensor gives it. */
    const char *px = "camera: {width_px: 64, height_px: 48, fx_px: 4000, fy_px: 4000}\nsensor: {pixel_pitch_m: 6.0e-6}\n";
    CHECK(load(px, NULL, 0, &g, &cs) == 0 && cs.sensor.pixel_pitch_m == 6e-6, "fx_px camera: %s", nc_errmsg());
    nc_camsys_free(&cs);
}

/* A PSF kernel file named relative to the configuration file is found
 * beside it, wherever the program runs. */
static void psf_file_beside_the_config(void)
{
    const float k[9] = {0, 1, 0, 1, 4, 1, 0, 1, 0};
    CHECK(nc_image_write(nc_test_path("kern.fits"), k, 3, 3, NULL, 0, NULL) == 0, "%s", nc_errmsg());
    struct nc_camera g;
    struct nc_camsys cs;
    const char *rel = "camera: {width_px: 64, height_px: 48, focal_length_m: 0.025, pixel_pitch_m: 5.5e-6}\n"
                      "optics: {f_number: 4, psf: {type: image, file: kern.fits}}\n";
    CHECK(load(rel, NULL, 0, &g, &cs) == 0 && cs.optics.psf.size == 3 && fabs(cs.optics.psf.kernel[4] - 0.5) < 1e-12,
          "a kernel beside the configuration file: %s", nc_errmsg());
    nc_camsys_free(&cs);
}

int main(void)
{
    flat_to_the_edge();
    dark_current_at_temperature();
    passband_from_edges();
    one_pixel_pitch();
    psf_file_beside_the_config();
    return nc_test_end();
}
