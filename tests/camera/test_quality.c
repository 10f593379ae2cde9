/* test_quality.c - render.quality: auto (camera/quality.h) on a small
 * body, the case pilots on every fourth row of 16-pixel tiles (as they
 * were) missed: a 250 m Hapke sphere 75 km away, about 30 px across in a 256 x 256
 * frame, its image wholly between pilot rows 0 and 4, and centred on row 4.
 * In both places auto must see the limb and pick samples whose error,
 * against a 1024-sample reference through the camera model, is within
 * its bound: an RMS over the body's pixels of each one's error over its
 * own camera noise (shot and read) under k = 0.25 and not below half of
 * what auto aims at (0.7 k, a margin for the pilots' sampling error): 0.35
 * k to k; one sample a pixel, what auto chose when its pilots missed the
 * body, is over 2 k. The choice is the same on a second call.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "camera/load.h"
#include "camera/quality.h"
#include "core/error.h"
#include "testutil.h"

#define D_M 75000.0 /* camera range, m */

/* Noise-free electrons of the scene's frame through the camera model. */
static float *electrons(struct nc_renderer *r, const struct nc_scene *s, const struct nc_camsys *cs)
{
    struct nc_frame f = {0};
    float *e = malloc((size_t)cs->width_px * (size_t)cs->height_px * sizeof *e);
    int rc = e ? nc_frame_alloc(&f, s->camera.width_px, s->camera.height_px) : -1;
    if (rc >= 0)
        rc = nc_render_frame(r, s, &f);
    if (rc >= 0)
        rc = nc_camsys_electrons(cs, f.radiance, cs->exposure_s, e);
    nc_frame_free(&f);
    if (rc < 0) {
        fprintf(stderr, "render: %s\n", nc_errmsg());
        exit(2);
    }
    return e;
}

/* The default scene with sets, its camera model, and the scene as the
 * renderer draws it (the camera model's render camera). */
static void load(const char *const *sets, int n, struct nc_scene *s, struct nc_camsys *cs, struct nc_scene *drawn)
{
    if (nc_setup_load(NULL, sets, n, s, cs) < 0) {
        fprintf(stderr, "scene: %s\n", nc_errmsg());
        exit(2);
    }
    *drawn = *s;
    nc_camsys_render_camera(cs, &s->camera, &drawn->camera);
}

/* RMS over pixels with light in either frame of |e - e_ref| over the
 * camera's noise there, sqrt(e_ref + read^2). */
static double sigma_rms(const struct nc_camsys *cs, const float *e_ref, const float *e)
{
    const double rn2 = cs->sensor.read_noise_e * cs->sensor.read_noise_e;
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < (size_t)cs->width_px * (size_t)cs->height_px; i++) {
        double a = fmin(e_ref[i], cs->sensor.full_well_e), b = fmin(e[i], cs->sensor.full_well_e);
        if (a >= cs->sensor.gain_e_per_dn || b >= cs->sensor.gain_e_per_dn) {
            sum += (b - a) * (b - a) / (a + rn2);
            n++;
        }
    }
    return n ? sqrt(sum / (double)n) : INFINITY;
}

/* Auto's choice with the camera looking z_m below the sphere's centre; the
 * image rows the sphere spans in y0, y1; the sigma RMS of auto's frame and
 * of one sample a pixel against the reference. */
static struct nc_quality_choice choose(double z_m, double *y0, double *y1, double *sigma_auto, double *sigma_one)
{
    char look[96];
    snprintf(look, sizeof look, "camera.look_at_m=[0, 0, %.17g]", z_m);
    const char *sets[] = {"bodies.0.shape={type: sphere, radius_m: 250}",
                          "camera.width_px=256",
                          "camera.height_px=256",
                          "camera.position_m=[0, -75000, 0]",
                          look,
                          "render.quality=auto"};
    struct nc_scene s, drawn;
    struct nc_camsys cs;
    load(sets, 6, &s, &cs, &drawn);
    /* the sphere's image rows in the frame the pilots render */
    const struct nc_mat3 R = nc_quat_to_mat(drawn.camera.attitude_q);
    *y0 = INFINITY;
    *y1 = -INFINITY;
    for (int k = 0; k < 360; k++) {
        double a = k * M_PI / 180, x, y;
        struct nc_vec3 p = nc_v3(250 * cos(a), 0, 250 * sin(a)); /* the limb seen from -y */
        nc_camera_project(&drawn.camera, nc_mat_tmul_v(&R, nc_v3_sub(p, drawn.camera.position_m)), &x, &y);
        *y0 = fmin(*y0, y);
        *y1 = fmax(*y1, y);
    }
    struct nc_renderer r;
    struct nc_quality_choice q = {0}, q2 = {0};
    int rc = nc_renderer_init(&r, &drawn, 2);
    struct nc_scene a = drawn, b = drawn, ref = drawn, one = drawn;
    if (rc >= 0)
        rc = nc_quality_auto(&r, &a, &cs, cs.exposure_s, &q);
    if (rc >= 0)
        rc = nc_quality_auto(&r, &b, &cs, cs.exposure_s, &q2);
    CHECK(rc >= 0, "auto: %s", nc_errmsg());
    CHECK(q.samples_per_pixel == q2.samples_per_pixel && q.mc_to_noise_var == q2.mc_to_noise_var &&
              q.soft_shadows == q2.soft_shadows,
          "two calls chose %d and %d samples (variance %g, %g)", q.samples_per_pixel, q2.samples_per_pixel,
          q.mc_to_noise_var, q2.mc_to_noise_var);
    ref.render.samples_per_pixel = 1024;
    ref.render.seed = 99;
    one.render.samples_per_pixel = 1;
    float *e_ref = electrons(&r, &ref, &cs), *e_auto = electrons(&r, &a, &cs), *e_one = electrons(&r, &one, &cs);
    *sigma_auto = sigma_rms(&cs, e_ref, e_auto);
    *sigma_one = sigma_rms(&cs, e_ref, e_one);
    free(e_ref);
    free(e_auto);
    free(e_one);
    char why[512];
    nc_quality_describe(&q, 1, why, sizeof why);
    printf("look %.0f m below: sphere on rows %.1f-%.1f: %s; sigma RMS %.3f (1 sample: %.3f)\n", -z_m, *y0, *y1,
           why, *sigma_auto, *sigma_one);
    nc_renderer_free(&r);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
    return q;
}

/* The pilots draw into the renderer's scratch frames, which keep the last
 * call's pixels; what a call reads must be its own. On the icy asteroid
 * with boulders and a level of detail (a bounce, the second checkerboard
 * half, the boulder cut's and the level of detail's variants: every
 * scratch frame), auto through a renderer whose scratch frames hold NaN
 * chooses what it chooses through a fresh one. */
static void check_scratch(void)
{
    const char *sets[] = {"camera.width_px=128", "camera.height_px=128", "camera.position_m=[0, -1500, 0]",
                          "bodies.0.boulders={preset: bennu}", "render.quality=auto", "render.lod_error_px=1",
                          "bodies.0.material={model: hapke, w: 0.97, b: 0.3, c: 0.3, B_S0: 0.6, h_S: 0.06, "
                          "theta_bar: 20}"};
    struct nc_scene s, drawn, a, b;
    struct nc_camsys cs;
    load(sets, 7, &s, &cs, &drawn);
    struct nc_renderer fresh, dirty;
    struct nc_quality_choice qa = {0}, qb = {0};
    int rc = nc_renderer_init(&fresh, &drawn, 2);
    if (rc >= 0)
        rc = nc_renderer_init(&dirty, &drawn, 2);
    for (int i = 0; i < NC_SCRATCH_FRAMES && rc >= 0; i++) {
        const int W = drawn.camera.width_px, H = drawn.camera.height_px;
        struct nc_frame *f = nc_renderer_scratch(&dirty, i, W, H, NC_PLANE_DIRECT | NC_PLANE_DIRECT_HARD | NC_PLANE_ONE);
        float *plane[] = {f->radiance, f->iof, f->range_m, f->coverage, f->direct, f->direct_hard, f->one};
        for (int k = 0; k < 7; k++)
            for (size_t p = 0; p < (size_t)W * (size_t)H; p++)
                plane[k][p] = NAN;
    }
    a = b = drawn;
    if (rc >= 0)
        rc = nc_quality_auto(&fresh, &a, &cs, cs.exposure_s, &qa);
    if (rc >= 0)
        rc = nc_quality_auto(&dirty, &b, &cs, cs.exposure_s, &qb);
    CHECK(rc >= 0, "auto: %s", nc_errmsg());
    char why[512];
    nc_quality_describe(&qb, 1, why, sizeof why);
    printf("icy asteroid with boulders, scratch frames full of NaN: %s\n", why);
    CHECK(qb.bounces > 0 && qb.lod_rms > 0, "the case should take a bounce (%d) and see the level of detail (%g)",
          qb.bounces, qb.lod_rms);
    CHECK(isfinite(qb.mc_to_noise_var) && isfinite(qb.cut_rms) && isfinite(qb.indirect_sigma) &&
              qa.samples_per_pixel == qb.samples_per_pixel && qa.mc_to_noise_var == qb.mc_to_noise_var &&
              qa.cut_rms == qb.cut_rms && qa.lod_rms == qb.lod_rms && qa.indirect_sigma == qb.indirect_sigma &&
              qa.bounces == qb.bounces,
          "fresh renderer: %d samples, variance %g, cut %g; stale scratch: %d, %g, %g", qa.samples_per_pixel,
          qa.mc_to_noise_var, qa.cut_rms, qb.samples_per_pixel, qb.mc_to_noise_var, qb.cut_rms);
    nc_renderer_free(&fresh);
    nc_renderer_free(&dirty);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
}

int main(void)
{
    check_scratch();
    /* fx = 0.025 / 5.5e-6 px: z below the centre puts the sphere's image
     * that many pixels above the frame's centre row (127.5) */
    const double fx = 0.025 / 5.5e-6, z[2] = {-(127.5 - 40) / fx * D_M, -(127.5 - 72) / fx * D_M};
    for (int i = 0; i < 2; i++) {
        double y0, y1, sa, s1;
        struct nc_quality_choice q = choose(z[i], &y0, &y1, &sa, &s1);
        if (i == 0)
            CHECK(y0 > 16 + 2 && y1 < 64 - 2, "the sphere spans rows %.1f-%.1f, not within tile rows 1-3", y0, y1);
        else
            CHECK(y0 < 64 && y1 > 80, "the sphere spans rows %.1f-%.1f, not across tile row 4", y0, y1);
        CHECK(y1 - y0 > 25, "the sphere spans %.1f rows", y1 - y0);
        CHECK(q.samples_per_pixel >= 4 && q.mc_to_noise_var > 0.25 * 0.25,
              "auto chose %d samples (variance %g at one) for the sphere on rows %.0f-%.0f", q.samples_per_pixel,
              q.mc_to_noise_var, y0, y1);
        CHECK(sa >= 0.35 * 0.25 && sa <= 0.25, "auto's frame is %.3f sigma RMS off (k = 0.25)", sa);
        CHECK(s1 > 2 * 0.25, "one sample a pixel is only %.3f sigma RMS off: the check cannot fail", s1);
    }
    return nc_test_end();
}
