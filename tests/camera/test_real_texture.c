/* test_real_texture.c - a rendered rubble pile at 20 cm per pixel has the
 * texture of real ones: configs/examples/rubble_closeup.yaml (rocks of the
 * Bennu preset from 0.3 m, lit and seen as OSIRIS-REx MapCam saw Bennu at
 * about 9 deg phase) rendered and put through its camera model to a DN
 * frame, as `navcam render -q dn` does (frame 0), measured as `navcam texture
 * --band 0.03125,0.25` does. Every figure must lie in the range of eleven
 * 256x256 crops of three MapCam frames of Bennu at 0.25 and 0.33 m per pixel
 * (docs/terrain.md, "Texture": the frames, where they come from, the crops),
 * the median of five surfaces (the boulders' seeds 5 to 9).
 * The scene's albedo spread and PSF were set from those frames' brightness
 * distribution and their spectrum's fall near the Nyquist frequency; the
 * figures below were not fitted. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camsys.h"
#include "camera/load.h"
#include "core/error.h"
#include "core/texture.h"
#include "render/render.h"
#include "testutil.h"

/* docs/terrain.md, "Texture": the lowest and highest of the eleven crops */
static const struct {
    const char *name;
    double lo, hi;
} real[] = {
    {"corners per Mpx", 53741, 70557}, {"psd_beta", 1.37, 2.58},      {"grad_mean", 0.048, 0.106},
    {"grad_rms", 0.064, 0.136},        {"grad_kurtosis", 5.49, 9.78},
};

#define NFIG (sizeof real / sizeof real[0])

/* The config with the boulders' seed given, rendered and digitised: its
 * five figures in got. */
static void measure(const char *path, int seed, double *got)
{
    char set[64];
    snprintf(set, sizeof set, "bodies.0.boulders.seed=%d", seed);
    const char *sets[] = {set};
    struct nc_scene s;
    struct nc_camsys cs;
    CHECK(nc_setup_load(path, sets, 1, &s, &cs) == 0, "%s", nc_errmsg());
    if (nc_test_failed)
        return;
    const int w = cs.width_px, h = cs.height_px;
    const size_t n = (size_t)w * (size_t)h;
    nc_camsys_render_camera(&cs, &s.camera, &s.camera);
    struct nc_renderer r;
    struct nc_frame f;
    float *el = malloc(n * sizeof *el), *img = malloc(n * sizeof *img);
    uint16_t *dn = malloc(n * sizeof *dn);
    CHECK(el && img && dn, "out of memory");
    if (nc_test_failed)
        return;
    CHECK(nc_renderer_init(&r, &s, 2) == 0 && nc_frame_alloc(&f, s.camera.width_px, s.camera.height_px) == 0 &&
              nc_render_frame(&r, &s, &f) == 0,
          "%s", nc_errmsg());
    CHECK(nc_camsys_electrons(&cs, f.radiance, cs.exposure_s, el) == 0 &&
              nc_camsys_digitise(&cs, el, cs.exposure_s, 0, dn) == 0,
          "%s", nc_errmsg());
    if (nc_test_failed)
        return;

    /* the ground sample distance: the mean range over the render (all of it
     * on the surface) over the focal length in pixels */
    double sum = 0;
    size_t on = 0, all = (size_t)f.width_px * (size_t)f.height_px, top = 0;
    for (size_t i = 0; i < all; i++)
        if (f.range_m[i] > 0)
            sum += f.range_m[i], on++;
    CHECK(on == all, "the surface fills the frame (%zu of %zu px)", on, all);
    const double gsd_m = sum / (double)on / s.camera.fx_px;
    CHECK(fabs(gsd_m / 0.2 - 1) < 0.03, "ground sample %.3f m", gsd_m);
    for (size_t i = 0; i < n; i++) {
        img[i] = dn[i];
        top += dn[i] >= (1u << cs.sensor.adc_bits) - 1;
    }
    CHECK(top == 0, "%zu pixels saturated", top);

    struct nc_texture_opts o;
    nc_texture_defaults(&o);
    o.f_lo = 1.0 / 32; /* 8 cycles across 256 px (docs/compare.md) */
    struct nc_texture t;
    CHECK(nc_texture_measure(img, w, h, &o, &t) == 0, "%s", nc_errmsg());
    const double fig[NFIG] = {t.corners_per_mpx, t.psd_beta, t.grad_mean, t.grad_rms, t.grad_kurtosis};
    memcpy(got, fig, sizeof fig);
    printf("seed %d, %dx%d DN at %.3f m/px:", seed, w, h, gsd_m);
    for (size_t k = 0; k < NFIG; k++)
        printf(" %s %.5g%s", real[k].name, got[k], k + 1 < NFIG ? "," : "\n");
    free(el);
    free(img);
    free(dn);
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/configs/examples/rubble_closeup.yaml", NC_SOURCE_DIR);
    /* Five surfaces (the boulders' seeds 5, the config's, to 9): a 256 px
     * crop's spectrum turns on which large rocks fall in it (psd_beta 1.36
     * to 1.86 over these, as the real crops' 1.37 to 2.58), so each
     * figure's median is set against the real range. */
    enum { NSEEDS = 5 };
    double got[NFIG][NSEEDS];
    for (int k = 0; k < NSEEDS && !nc_test_failed; k++) {
        double g[NFIG];
        measure(path, 5 + k, g);
        for (size_t j = 0; j < NFIG; j++)
            got[j][k] = g[j];
    }
    if (nc_test_failed)
        return nc_test_end();
    for (size_t j = 0; j < NFIG; j++) {
        qsort(got[j], NSEEDS, sizeof got[j][0], cmp_double);
        const double med = got[j][NSEEDS / 2];
        printf("%s: median %.5g (%.5g .. %.5g), real %.5g .. %.5g\n", real[j].name, med, got[j][0],
               got[j][NSEEDS - 1], real[j].lo, real[j].hi);
        CHECK(med >= real[j].lo && med <= real[j].hi, "%s %.4g outside the real frames' %.4g .. %.4g", real[j].name,
              med, real[j].lo, real[j].hi);
    }
    return nc_test_end();
}
