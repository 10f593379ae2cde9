/* test_rubble_texture.c - boulders give a rubble pile the texture feature
 * trackers lock onto: the procedural asteroid at 20 cm per pixel, with
 * rocks of the Bennu preset from 1 m (rough faces) and bare (every rock cut,
 * nothing folded), measured by core/texture.h as `navcam texture` does.
 * Asserted: the ground sample distance, and that the rocks raise the FAST
 * corner density and the gradient and flatten the power spectrum by at
 * least the margins below (the example scenes at 20 cm per pixel show 1.9
 * and 6.4 times the corners, 1.9 and 11 times the gradient and slopes 1.0
 * and 2.5 lower: docs/terrain.md, "Texture"). That a rubble pile's figures lie
 * in the range of real images is tests/camera/test_real_texture.c's. */
#include <math.h>

#include "core/error.h"
#include "core/texture.h"
#include "testutil.h"

enum { N = 256 };


static void measure(struct nc_scene *s, int bare, struct nc_texture *t, double *gsd_m)
{
    s->render.boulder_min_px = bare ? 1000 : 0.5;
    s->render.boulder_fold = !bare;
    struct nc_renderer r;
    struct nc_frame f;
    CHECK(nc_renderer_init(&r, s, 2) == 0 && nc_frame_alloc(&f, N, N) == 0 && nc_render_frame(&r, s, &f) == 0, "%s",
          nc_errmsg());
    /* the ground sample distance at the mean range: range / focal length in pixels */
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < (size_t)N * N; i++)
        if (f.range_m[i] > 0)
            sum += f.range_m[i], n++;
    CHECK(n == (size_t)N * N, "the surface fills the frame (%zu of %d px)", n, N * N);
    *gsd_m = sum / (double)n / s->camera.fx_px;
    struct nc_texture_opts o;
    nc_texture_defaults(&o);
    CHECK(nc_texture_measure(f.radiance, N, N, &o, t) == 0, "%s", nc_errmsg());
    printf("%s at %.3f m/px: %.0f corners per Mpx, psd_beta %.2f (R^2 %.3f), grad mean %.4f rms %.4f, kurtosis %.1f\n",
           bare ? "bare" : "rubble", *gsd_m, t->corners_per_mpx, t->psd_beta, t->psd_r2, t->grad_mean, t->grad_rms,
           t->grad_kurtosis);
    nc_frame_free(&f);
    nc_renderer_free(&r);
}

int main(void)
{
    /* 909 m from the surface (y = -230 m) at 5.5 um / 25 mm: 0.20 m per pixel */
    const char *sets[] = {"camera.width_px=256", "camera.height_px=256", "camera.position_m=[0,-1139,0]",
                          "bodies.0.boulders={preset: bennu, min_diameter_m: 1, roughness_deg: 20}"};
    struct nc_scene s;
    nc_test_scene(nc_default_scene_yaml, sets, 4, &s);
    struct nc_texture rubble, bare;
    double gsd_r, gsd_b;
    measure(&s, 0, &rubble, &gsd_r);
    measure(&s, 1, &bare, &gsd_b);
    CHECK(fabs(gsd_r / 0.2 - 1) < 0.05 && fabs(gsd_b / 0.2 - 1) < 0.05, "ground sample %.3f, %.3f m", gsd_r, gsd_b);
    CHECK(rubble.corners_per_mpx > 1.5 * bare.corners_per_mpx, "corners: %.0f with rocks, %.0f bare",
          rubble.corners_per_mpx, bare.corners_per_mpx);
    CHECK(rubble.grad_mean > 1.5 * bare.grad_mean, "gradient: %.4f with rocks, %.4f bare", rubble.grad_mean,
          bare.grad_mean);
    CHECK(rubble.psd_beta < bare.psd_beta - 0.2, "spectral slope: %.2f with rocks, %.2f bare", rubble.psd_beta,
          bare.psd_beta);
    nc_scene_free(&s);
    return nc_test_end();
}
