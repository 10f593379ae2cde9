/* bench/sensor.c - the whole camera model on a 1024x1024 frame on one core:
 * radiance -> electrons (optics, vignetting) -> PSF -> fixed patterns, dark
 * current, shot noise -> full well -> read noise -> gain, bias, ADC.
 * Usage: bench_sensor [--frames N] [--psf gaussian|airy|none]
 * Last line: sensor_ms=...
 */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera/camsys.h"
#include "camera/load.h"
#include "bench_util.h"
#include "core/error.h"

int main(int argc, char **argv)
{
    int frames = 15, c;
    const char *psf = "gaussian";
    static const struct option opts[] = {{"frames", required_argument, NULL, 'n'},
                                         {"psf", required_argument, NULL, 'p'},
                                         {"help", no_argument, NULL, 'h'},
                                         {NULL, 0, NULL, 0}};
    while ((c = getopt_long(argc, argv, "n:p:h", opts, NULL)) != -1) {
        switch (c) {
        case 'n': frames = atoi(optarg); break;
        case 'p': psf = optarg; break;
        default: puts("Usage: bench_sensor [--frames N] [--psf gaussian|airy|none]"); return c == 'h' ? 0 : 2;
        }
    }
    if (frames < 3 || frames > 1000)
        frames = 15;
    char yaml[2048];
    snprintf(yaml, sizeof yaml,
             "camera: {width_px: 1024, height_px: 1024, focal_length_m: 0.025, pixel_pitch_m: 5.5e-6}\n"
             "optics: {f_number: 4, transmission: 0.9, passband: {band_fraction: 0.4, wavelength_m: 6.0e-7},\n"
             "         vignetting: cos4, psf: {type: %s%s}}\n"
             "sensor: {qe: 0.6, dark_current_e_s: 20, dsnu_e_s: 2, prnu: 0.01, hot_pixel_fraction: 1.0e-4,\n"
             "         hot_pixel_dark_e_s: 2000, read_noise_e: 10, full_well_e: 20000, gain_e_per_dn: 5,\n"
             "         bias_dn: 50, adc_bits: 12}\n"
             "exposure: {time_s: 0.002}\n",
             psf, !strcmp(psf, "gaussian") ? ", sigma_px: 1.0" : "");
    FILE *f = fopen("/tmp/navcam_bench_sensor.yaml", "w");
    if (!f || fputs(yaml, f) < 0 || fclose(f) != 0)
        return 1;
    struct nc_camera g;
    struct nc_camsys cs;
    if (nc_camsys_load("/tmp/navcam_bench_sensor.yaml", NULL, 0, &g, &cs) < 0) {
        fprintf(stderr, "bench: %s\n", nc_errmsg());
        return 1;
    }
    const size_t n = 1024 * 1024;
    const int RW = cs.render_width_px; /* the sensor and the PSF's margin */
    const size_t nr = (size_t)RW * (size_t)cs.render_height_px;
    float *rad = malloc(nr * sizeof *rad), *e = malloc(n * sizeof *e);
    uint16_t *dn = malloc(n * sizeof *dn);
    /* A radiance image with structure: a disk with a gradient, dark sky. */
    for (size_t i = 0; i < nr; i++) {
        double x = (double)(i % RW) - RW / 2, y = (double)(i / RW) - RW / 2;
        rad[i] = x * x + y * y < 300.0 * 300.0 ? (float)(2.0 + 3.0 * (x + 300) / 600) : 0.0f;
    }
    double *te = calloc((size_t)frames, sizeof *te), *td = calloc((size_t)frames, sizeof *td),
           *tt = calloc((size_t)frames, sizeof *tt);
    for (int k = 0; k < frames; k++) {
        double a = now_ms();
        nc_camsys_electrons(&cs, rad, cs.exposure_s, e);
        double b = now_ms();
        nc_camsys_digitise(&cs, e, cs.exposure_s, (uint64_t)k, dn);
        double c2 = now_ms();
        te[k] = b - a;
        td[k] = c2 - b;
        tt[k] = c2 - a;
    }
    double me = median(te, frames), md = median(td, frames), mt = median(tt, frames);
    printf("camera model, 1024x1024, 1 core, PSF %s (%dx%d kernel), median of %d frames:\n", psf, cs.optics.psf.size,
           cs.optics.psf.size, frames);
    printf("  radiance -> electrons incl. PSF   %.2f ms\n", me);
    printf("  noise, full well, read noise, ADC %.2f ms\n", md);
    printf("sensor_ms=%.3f\n", mt);
    free(rad);
    free(e);
    free(dn);
    free(te);
    free(td);
    free(tt);
    nc_camsys_free(&cs);
    return 0;
}
