/* test_psf_distortion.c - PSF kernels sum to 1 and conserve signal through
 * both the direct and the FFT path; the Airy pattern's first dark ring sits at
 * 1.22 lambda N and it is cut at its 12th, a circle; a point source lands where the kernel says; Brown-Conrady
 * project/unproject round trip within 1e-3 px; distorted camera rays match
 * the projection. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camsys.h"
#include "camera/load.h"
#include "core/error.h"
#include "render/image_io.h"
#include "testutil.h"

static double sum(const float *v, int n)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += v[i];
    return s;
}

static void check_kernel(const char *label, const struct nc_psf *psf)
{
    double s = 0;
    for (int i = 0; i < psf->size * psf->size; i++)
        s += psf->kernel[i];
    CHECK(fabs(s - 1) < 1e-12, "%s: kernel sums to %.15f", label, s);
    /* Signal conservation: a random image far from the edges keeps its total. */
    enum { N = 192 };
    static float in[N * N], out[N * N];
    memset(in, 0, sizeof in);
    uint64_t z = 7;
    for (int y = 78; y < 114; y++) /* 78 px margins: wider than any kernel radius here */
        for (int x = 78; x < 114; x++) {
            z = z * 6364136223846793005ull + 1442695040888963407ull;
            in[y * N + x] = (float)((z >> 40) % 1000);
        }
    nc_psf_apply(psf, in, out, N, N);
    double rel = fabs(sum(out, N * N) / sum(in, N * N) - 1);
    CHECK(rel < 1e-6, "%s: total signal changed by %.3g", label, rel);
    /* A point source at (40, 50) reproduces the kernel around it. */
    memset(in, 0, sizeof in);
    in[100 * N + 90] = 1000.0f;
    nc_psf_apply(psf, in, out, N, N);
    int r = psf->size / 2;
    double worst = 0;
    for (int j = -r; j <= r; j++)
        for (int i = -r; i <= r; i++) {
            int x = 90 + i, y = 100 + j;
            if (x < 0 || y < 0 || x >= N || y >= N)
                continue;
            worst = fmax(worst, fabs(out[y * N + x] - 1000.0 * psf->kernel[(j + r) * psf->size + (i + r)]));
        }
    CHECK(worst < 1e-3, "%s: point source image differs from the kernel by %.3g", label, worst);
    printf("%-28s %3dx%-3d sum-1 %.1e, signal change %.1e, point image error %.1e\n", label, psf->size, psf->size,
           s - 1, rel, worst);
}

/* The electrons of a Lambert sphere 6 px across, 30 deg off the axis, seen
 * through distortion k1 (no PSF, 64 samples a pixel), summed. */
static double sphere_electrons(double k1)
{
    char yaml[1024];
    const double th = 30 * M_PI / 180, d = 1e4, radius = d * sin(atan(3.0 / 100));
    snprintf(yaml, sizeof yaml,
             "bodies: [{shape: {type: sphere, radius_m: %.17g}, material: {model: lambert, A: 0.5},\n"
             "          position_m: [%.17g, 0, %.17g]}]\n"
             "sun: {direction: [%.17g, 0, %.17g]}\n"
             "camera: {width_px: 128, height_px: 96, focal_length_m: 0.001, pixel_pitch_m: 1.0e-5,\n"
             "         distortion: {k1: %g}, position_m: [0, 0, 0], attitude_q: [1, 0, 0, 0]}\n"
             "render: {samples_per_pixel: 64}\n"
             "optics: {f_number: 2.8, vignetting: cos4, psf: {type: none}}\n",
             radius, d * sin(th), d * cos(th), -sin(th), -cos(th), k1);
    const char *path = nc_test_path("resolved.yaml");
    nc_test_write(path, yaml);
    struct nc_scene s;
    struct nc_camsys cs;
    double sum = 0;
    if (nc_setup_load(path, NULL, 0, &s, &cs) < 0) {
        CHECK(0, "k1 %g: %s", k1, nc_errmsg());
        return 0;
    }
    struct nc_scene drawn = s;
    nc_camsys_render_camera(&cs, &s.camera, &drawn.camera);
    struct nc_renderer r;
    struct nc_frame f;
    struct nc_exposure ex = {.exposure_s = 0.01};
    const size_t n = (size_t)drawn.camera.width_px * drawn.camera.height_px;
    float *e = malloc(n * sizeof *e);
    CHECK(e && nc_renderer_init(&r, &drawn, 2) == 0 && nc_frame_alloc(&f, drawn.camera.width_px,
                                                                      drawn.camera.height_px) == 0 &&
              nc_render_exposure(&r, &drawn, &ex, &f, NULL) == 0 && nc_camsys_electrons(&cs, f.radiance, 0.01, e) == 0,
          "k1 %g: %s", k1, nc_errmsg());
    for (size_t i = 0; e && i < n; i++)
        sum += e[i];
    free(e);
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
    return sum;
}

/* A 64 x 64 camera of fx 44 px with set refused, the message holding want. */
static void refused_64(const char *set, const char *want)
{
    struct nc_scene s;
    int rc = nc_test_scene_rc("bodies: [{shape: {type: sphere, radius_m: 1}, material: {model: lambert, A: 0.1}}]\n"
                              "sun: {direction: [1, 0, 0]}\n"
                              "camera: {width_px: 64, height_px: 64, fx_px: 44, fy_px: 44,\n"
                              "         position_m: [0, 0, -10], attitude_q: [1, 0, 0, 0]}\n",
                              &set, 1, &s);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), want), "%s: %s", set, rc < 0 ? nc_errmsg() : "accepted");
    if (rc == 0)
        nc_scene_free(&s);
}

int main(void)
{
    struct nc_psf g = {0}, a = {0}, im = {0};
    CHECK(nc_psf_gaussian(1.3, &g) == 0, "gaussian");
    check_kernel("Gaussian sigma 1.3 px", &g);
    /* Pixel-integrated Gaussian: its second moment is sigma^2 + 1/12 px^2. */
    double m2 = 0;
    int r = g.size / 2;
    for (int j = 0; j < g.size; j++)
        for (int i = 0; i < g.size; i++)
            m2 += g.kernel[j * g.size + i] * (i - r) * (i - r);
    CHECK(fabs(m2 - (1.3 * 1.3 + 1.0 / 12)) < 1e-4, "Gaussian variance %.6f vs %.6f", m2, 1.3 * 1.3 + 1.0 / 12);

    /* Airy: lambda N = 2.5 px, so the first dark ring is at 3.05 px. */
    CHECK(nc_psf_airy(5e-7, 10, 2e-6, &a) == 0, "airy");
    check_kernel("Airy lambda N = 2.5 px (FFT)", &a);
    nc_psf_free(&a);
    /* The first dark ring, from the kernel itself: with lambda N = 10 px
     * (0.5 um, f/40, 2 um pixels) pixel integration barely shifts it, and the
     * minimum of the centre row between 6 and 18 px must sit at 1.22 lambda N
     * = 12.2 px, i.e. on pixel 12. */
    CHECK(nc_psf_airy(5e-7, 40, 2e-6, &a) == 0, "airy");
    r = a.size / 2;
    int mini = 6;
    for (int i = 6; i <= 18; i++)
        if (a.kernel[r * a.size + r + i] < a.kernel[r * a.size + r + mini])
            mini = i;
    CHECK(mini == 12, "Airy kernel's first minimum at %d px from the centre, expected 12 (1.22 lambda N = 12.2 px)", mini);
    printf("Airy lambda N = 10 px: kernel %dx%d, first dark ring on pixel %d (1.22 lambda N = 12.2 px)\n", a.size,
           a.size, mini);
    /* Cut at the 12th dark ring (12.247 lambda N = 122.5 px), a circle: the
     * kernel reaches pixel 122 along the axes, and its corners (173 px from
     * the centre) are dark. */
    CHECK(r == 123 && a.kernel[r * a.size + a.size - 2] > 0 && a.kernel[0] == 0 &&
              a.kernel[(r - 90) * a.size + r - 90] == 0 && a.kernel[(r - 80) * a.size + r - 80] > 0,
          "Airy kernel of lambda N = 10 px: half-width %d px (want 123), pixel 122 %g, corner %g, (90, 90) %g, "
          "(80, 80) %g", r, a.kernel[r * a.size + a.size - 2], a.kernel[0], a.kernel[(r - 90) * a.size + r - 90],
          a.kernel[(r - 80) * a.size + r - 80]);

    /* Small against the pixel: f/0.3 at 0.55 um on 55 um pixels (lambda N =
     * 0.003 px, the whole pattern in the middle pixel) is a delta, not an
     * error ("sums to 0": no sample hit its core); lambda N = 0.1 px (the
     * first ring at 0.12 px) keeps over 97 % in the middle pixel. */
    nc_psf_free(&a);
    CHECK(nc_psf_airy(5.5e-7, 0.3, 5.5e-5, &a) == 0 && a.kernel[(a.size / 2) * a.size + a.size / 2] == 1,
          "Airy of lambda N = 0.003 px: %s", nc_errmsg());
    nc_psf_free(&a);
    CHECK(nc_psf_airy(5e-7, 10, 5e-5, &a) == 0 && a.kernel[(a.size / 2) * a.size + a.size / 2] > 0.97,
          "Airy of lambda N = 0.1 px: middle %g", a.kernel[(a.size / 2) * a.size + a.size / 2]);
    printf("Airy lambda N = 0.1 px: %.4f of the light in the middle pixel\n",
           a.kernel[(a.size / 2) * a.size + a.size / 2]);
    nc_psf_free(&a);

    /* A user kernel image, asymmetric, through the direct path (5x5). */
    float k[25] = {0};
    k[2 * 5 + 2] = 4;
    k[2 * 5 + 3] = 2;
    k[1 * 5 + 2] = 1;
    k[4 * 5 + 0] = 1;
    const char *kp = nc_test_path("kernel.exr");
    nc_image_write(kp, k, 5, 5, NULL, 0, NULL);
    CHECK(nc_psf_image(kp, &im) == 0, "image kernel: %s", nc_errmsg());
    check_kernel("user kernel 5x5 (direct)", &im);
    /* The same asymmetric kernel, padded to 11x11 to force the FFT path. */
    struct nc_psf big = {.kind = NC_PSF_IMAGE, .size = 11};
    big.kernel = calloc(121, sizeof(double));
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++)
            big.kernel[(j + 3) * 11 + i + 3] = im.kernel[j * 5 + i];
    check_kernel("user kernel 11x11 (FFT)", &big);
    float bad[9] = {0, 1, 0, 1, -1, 1, 0, 1, 0};
    const char *bp = nc_test_path("bad_kernel.exr");
    nc_image_write(bp, bad, 3, 3, NULL, 0, NULL);
    struct nc_psf b = {0};
    CHECK(nc_psf_image(bp, &b) < 0 && nc_test_contains(nc_errmsg(), "(1, 1) is negative"), "negative kernel: %s",
          nc_errmsg());
    nc_image_write(bp, bad, 3, 2, NULL, 0, NULL);
    CHECK(nc_psf_image(bp, &b) < 0 && nc_test_contains(nc_errmsg(), "square with an odd size"), "even kernel");
    nc_psf_free(&g);
    nc_psf_free(&a);
    nc_psf_free(&im);
    nc_psf_free(&big);

    /* Brown-Conrady round trip over the whole image, barrel and pincushion. */
    const char *dists[] = {"{k1: -0.25, k2: 0.08, k3: -0.01, p1: 0.001, p2: -0.0015}",
                           "{k1: 0.12, k2: 0.02, k3: 0.0, p1: -0.0005, p2: 0.0008}"};
    for (int d = 0; d < 2; d++) {
        char yaml[512];
        snprintf(yaml, sizeof yaml,
                 "bodies: [{shape: {type: sphere, radius_m: 1}, material: {model: lambert, A: 0.1}}]\n"
                 "sun: {direction: [1, 0, 0]}\n"
                 "camera: {width_px: 1024, height_px: 768, fx_px: 800, fy_px: 790, cx_px: 515.3, cy_px: 380.2,\n"
                 "         distortion: %s, position_m: [0, 0, -10], attitude_q: [1, 0, 0, 0]}\n",
                 dists[d]);
        struct nc_scene s;
        nc_test_scene(yaml, NULL, 0, &s);
        const struct nc_camera *c = &s.camera;
        double worst = 0, maxshift = 0;
        for (double y = 0; y <= 767; y += 7.3)
            for (double x = 0; x <= 1023; x += 9.1) {
                double px, py;
                struct nc_vec3 ray = nc_camera_ray(c, x, y);
                nc_camera_project(c, ray, &px, &py);
                worst = fmax(worst, hypot(px - x, py - y));
                maxshift = fmax(maxshift, hypot(c->fx_px * ray.x + c->cx_px - x, c->fy_px * ray.y + c->cy_px - y));
            }
        CHECK(worst < 1e-3, "distortion %d: round trip error %.3g px", d, worst);
        CHECK(maxshift > 10, "distortion %d: the lens should move pixels (max %.3g px)", d, maxshift);
        printf("distortion %s: max displacement %.1f px, round trip error %.2e px\n", dists[d], maxshift, worst);
        nc_scene_free(&s);
    }
    /* A distortion that folds inside the image is refused. */
    struct nc_scene s;
    const char *fold[] = {"camera.distortion={k1: -2.0}"};
    int rc = nc_test_scene_rc("bodies: [{shape: {type: sphere, radius_m: 1}, material: {model: lambert, A: 0.1}}]\n"
                              "sun: {direction: [1, 0, 0]}\n"
                              "camera: {width_px: 1024, height_px: 768, fx_px: 300, fy_px: 300,\n"
                              "         position_m: [0, 0, -10], attitude_q: [1, 0, 0, 0]}\n",
                              fold, 1, &s);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "camera.distortion: this distortion cannot be inverted"),
          "folding distortion: %s", nc_errmsg());
    /* One that folds between the centre and the edge, while every tested pixel's ray projects back onto it (the
     * inverse found a root beyond the fold: pixels 48 and 49 of the middle row saw radii 0.55 and 1.22). */
    refused_64("camera.distortion={k1: -1.2, k2: 0.5}",
               "camera.distortion: this distortion folds over inside the image");
    /* Samples reach half a pixel beyond the pixels' centres, and the PSF's
     * margin more: k1 -0.1424 at fx 44 over 64 x 64 inverts at every pixel
     * centre but not at the image's corner (-0.5, -0.5), where the inverse
     * found the ray on the other side of the field (an outside check: 1162
     * e- in a corner from a sphere 72 deg off the other way); k1 -0.12 is
     * unfolded over the image but not over a sigma 2 px PSF's 10 px margin,
     * and is over a 0.3 px one's. */
    refused_64("camera.distortion={k1: -0.1424}", "cannot be inverted at pixel (-0.5, -0.5)");
    /* The lens conserves flux: a barrel (k1 -0.15) or pincushion (+0.1)
     * lens changes how many pixels a body 30 deg off the axis covers and the
     * solid angle each sees, not the electrons it gives (an outside check:
     * 0.807 and 1.136 of them before the pixels' solid angle came into the
     * response, when the same body drawn as a point gave 1.000). */
    const double e0 = sphere_electrons(0), eb = sphere_electrons(-0.15), ep = sphere_electrons(0.1);
    printf("a sphere 6 px across 30 deg off the axis: electrons through k1 -0.15 and +0.1 are %.4f and %.4f of "
           "those without distortion\n", eb / e0, ep / e0);
    CHECK(fabs(eb / e0 - 1) < 0.005 && fabs(ep / e0 - 1) < 0.005, "flux through distortion: %.4f, %.4f", eb / e0,
          ep / e0);
    for (int m = 0; m < 2; m++) {
        char yaml[1024];
        snprintf(yaml, sizeof yaml,
                 "bodies: [{shape: {type: sphere, radius_m: 1}, material: {model: lambert, A: 0.1}}]\n"
                 "sun: {direction: [1, 0, 0]}\n"
                 "camera: {width_px: 64, height_px: 64, fx_px: 44, fy_px: 44, distortion: {k1: -0.12},\n"
                 "         position_m: [0, 0, -10], attitude_q: [1, 0, 0, 0]}\n"
                 "optics: {f_number: 4, psf: {type: gaussian, sigma_px: %s}}\n"
                 "sensor: {pixel_pitch_m: 5.5e-6}\n",
                 m ? "0.3" : "2.0");
        const char *path = nc_test_path("margin.yaml");
        nc_test_write(path, yaml);
        struct nc_camsys cs;
        rc = nc_setup_load(path, NULL, 0, &s, &cs);
        if (m == 0)
            CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "optics.psf: the PSF's margin (10 px around the image") &&
                      nc_test_contains(nc_errmsg(), "camera.distortion folds over (towards pixel (-10.5, -10.5))"),
                  "a fold in the PSF's margin: %s", rc < 0 ? nc_errmsg() : "accepted");
        else
            CHECK(rc >= 0, "unfolded over a 0.3 px PSF's margin: %s", nc_errmsg());
        if (rc >= 0) {
            nc_camsys_free(&cs);
            nc_scene_free(&s);
        }
    }
    return nc_test_end();
}
