/* test_smear.c - motion during the exposure: a point moving a known number of
 * pixels spreads into a streak of that length with its total signal
 * conserved; a rolling shutter skews a vertical bar by the rate times the
 * readout time; without motion neither changes the image; a camera inside
 * a body's bounding sphere takes the time samples its view needs; the
 * rocks a frame's rock_id plane names are those at mid-exposure. */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "testutil.h"

/* A sphere 4 px across at 10 km (fx = 1000 px), lit from behind the camera. */
static const char yaml[] =
    "bodies:\n"
    "  - shape: {type: sphere, radius_m: 20}\n"
    "    material: {model: lambert, A: 1}\n"
    "sun: {direction: [0, 0, -1]}\n"
    "camera: {width_px: 96, height_px: 64, fx_px: 1000, fy_px: 1000,\n"
    "         position_m: [0, 0, -10000], attitude_q: [1, 0, 0, 0]}\n"
    "render: {samples_per_pixel: 64}\n";

static double total(const struct nc_frame *f)
{
    double s = 0;
    for (int i = 0; i < f->width_px * f->height_px; i++)
        s += f->radiance[i];
    return s;
}

static void extent(const struct nc_frame *f, double thresh, int *x0, int *x1, int *y0, int *y1)
{
    *x0 = *y0 = 1 << 30;
    *x1 = *y1 = -1;
    for (int y = 0; y < f->height_px; y++)
        for (int x = 0; x < f->width_px; x++)
            if (f->radiance[y * f->width_px + x] > thresh) {
                *x0 = x < *x0 ? x : *x0;
                *x1 = x > *x1 ? x : *x1;
                *y0 = y < *y0 ? y : *y0;
                *y1 = y > *y1 ? y : *y1;
            }
}

static void count_rays(void *user, int shadow, const struct nc_ray16 *ray, int frame) /* from the render threads */
{
    (void)frame;
    unsigned long n = 0;
    for (int i = 0; !shadow && i < NC_PACKET; i++)
        n += ray->valid[i] != 0;
    atomic_fetch_add((atomic_ulong *)user, n);
}

static void render(const struct nc_scene *s, const struct nc_exposure *ex, struct nc_frame *f, int *k)
{
    struct nc_renderer r;
    nc_renderer_init(&r, s, 2);
    nc_frame_alloc(f, s->camera.width_px, s->camera.height_px);
    CHECK(nc_render_exposure(&r, s, ex, f, k) == 0, "render");
    nc_renderer_free(&r);
}

/* The rock_id plane of an exposure with time samples is the rocks seen at its middle, as a still frame sees them
 * there: with an odd K its middle sample, with an even K (no sample there) a pass of its own (it was sample K / 2's,
 * T / 2K later: 0.2 px of the turn here, 345 of 5462 rock pixels named differently). */
static void rock_id_mid_exposure(void)
{
    const char *sets[] = {"bodies[0].boulders={preset: bennu, min_diameter_m: 0.5, seed: 9}",
                          "camera={width_px: 128, height_px: 128, fx_px: 6000, fy_px: 6000, position_m: [0, -830, 0], "
                          "look_at_m: [0, 0, 0], up: [0, 0, 1]}",
                          "render.samples_per_pixel=1", "render.boulder_min_px=0", NULL};
    const char *turns[] = {"camera.angular_velocity_rad_s=[0, 0, 0]", "camera.angular_velocity_rad_s=[0.0133, 0, 0]",
                           "camera.angular_velocity_rad_s=[0.02, 0, 0]"}; /* 0, 0.8 and 1.2 px in 0.01 s */
    int32_t *still = NULL;
    const size_t n = 128 * 128;
    for (int t = 0; t < 3; t++) {
        sets[4] = turns[t];
        struct nc_scene s;
        nc_test_scene(nc_test_asteroid_yaml, sets, 5, &s);
        struct nc_exposure ex = {.exposure_s = 0.01};
        struct nc_frame f = {0};
        struct nc_renderer r;
        int k = 0;
        CHECK(nc_renderer_init(&r, &s, 2) == 0 && nc_frame_alloc(&f, 128, 128) == 0 &&
                  (f.rock_id = malloc(n * sizeof *f.rock_id)) != NULL && nc_render_exposure(&r, &s, &ex, &f, &k) == 0,
              "%s", nc_errmsg());
        size_t rocks = 0, differ = 0;
        for (size_t i = 0; i < n; i++)
            rocks += f.rock_id[i] >= 0, differ += still && f.rock_id[i] != still[i];
        printf("rock_id, %s: %d time samples, %zu rock pixels, %zu named unlike the still frame's\n", turns[t], k,
               rocks, differ);
        CHECK(k == t + 1 && rocks > 1000 && differ == 0, "%d time samples: %zu of %zu rock pixels differ", k, differ,
              rocks);
        if (!still)
            still = f.rock_id, f.rock_id = NULL;
        nc_frame_free(&f);
        nc_renderer_free(&r);
        nc_scene_free(&s);
    }
    free(still);
    /* The renderer's state after such a frame, the rock cut the frame records (navcam:boulder_min_m) included, is
     * its last sample's with the plane or without it (the pass of its own came last at first: a camera moving
     * toward the body recorded another cut when the plane was asked for). */
    sets[3] = "render.boulder_min_px=20", sets[4] = "camera.velocity_m_s=[0, 20000, 0]";
    double cut[2] = {0};
    int ks[2] = {0};
    for (int w = 0; w < 2; w++) {
        struct nc_scene s;
        nc_test_scene(nc_test_asteroid_yaml, sets, 5, &s);
        struct nc_exposure ex = {.exposure_s = 0.01};
        struct nc_frame f = {0};
        struct nc_renderer r;
        CHECK(nc_renderer_init(&r, &s, 2) == 0 && nc_frame_alloc(&f, 128, 128) == 0 &&
                  (!w || (f.rock_id = malloc(n * sizeof *f.rock_id)) != NULL) &&
                  nc_render_exposure(&r, &s, &ex, &f, &ks[w]) == 0,
              "%s", nc_errmsg());
        cut[w] = nc_rt_boulder_min_m(r.rt);
        nc_frame_free(&f);
        nc_renderer_free(&r);
        nc_scene_free(&s);
    }
    printf("moving toward the body, %d time samples: the recorded rock cut %.6f m without the rock_id plane, %.6f m "
           "with it\n", ks[0], cut[0], cut[1]);
    CHECK(ks[0] % 2 == 0 && ks[1] == ks[0] && cut[0] == cut[1], "K %d, %d: the cut %.6f m, %.6f m", ks[0], ks[1],
          cut[0], cut[1]);
}

/* The least-squares slope over the rows of each 96-px row's centroid of
 * signal in f, relative to still's (which cancels the sampling pattern
 * common to both), px per row. */
static double shear_px(const struct nc_frame *f, const struct nc_frame *still)
{
    double cx[64];
    for (int y = 0; y < 64; y++) {
        double m = 0, mx = 0, m0 = 0, mx0 = 0;
        for (int x = 0; x < 96; x++) {
            m += f->radiance[y * 96 + x];
            mx += x * f->radiance[y * 96 + x];
            m0 += still->radiance[y * 96 + x];
            mx0 += x * still->radiance[y * 96 + x];
        }
        cx[y] = m > 0 && m0 > 0 ? mx / m - mx0 / m0 : NAN;
    }
    double sy = 0, sc = 0, syy = 0, syc = 0;
    for (int y = 0; y < 64; y++)
        sy += y, sc += cx[y], syy += (double)y * y, syc += y * cx[y];
    return (64 * syc - sy * sc) / (64 * syy - sy * sy);
}

int main(void)
{
    rock_id_mid_exposure();
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    struct nc_exposure ex = {.exposure_s = 0.1};
    struct nc_frame still, moving;
    int k;
    render(&s, &ex, &still, &k);
    CHECK(k == 1, "no motion: one time sample, got %d", k);
    /* Turning about the camera's y axis at 0.2 rad/s for 0.1 s moves the image
     * by 0.02 rad * 1000 px = 20 px along x. */
    s.camera.angular_velocity_rad_s = nc_v3(0, 0.2, 0);
    render(&s, &ex, &moving, &k);
    /* Analytic: a Lambert sphere at zero phase gives p J (R/D)^2, p = 2A/3;
     * each pixel subtends 1/(fx fy) sr. */
    double want = 2.0 / 3.0 * s.sun.irradiance_w_m2 * pow(20.0 / 10000.0, 2) * 1e6;
    double s0 = total(&still), s1 = total(&moving);
    int ax0, ax1, ay0, ay1, bx0, bx1, by0, by1;
    extent(&still, 1e-9, &ax0, &ax1, &ay0, &ay1);
    double peak = 0;
    for (int i = 0; i < moving.width_px * moving.height_px; i++)
        peak = fmax(peak, moving.radiance[i]);
    extent(&moving, 0.05 * peak, &bx0, &bx1, &by0, &by1);
    int still_w = ax1 - ax0 + 1, streak = bx1 - bx0 + 1;
    printf("point: %d px wide still; moving 20 px in %d time samples: streak %d px (x %d..%d), rows %d..%d vs %d..%d; "
           "total signal still/analytic %.5f, moving/analytic %.5f\n",
           still_w, k, streak, bx0, bx1, by0, by1, ay0, ay1, s0 / want, s1 / want);
    CHECK(k >= 40, "20 px of motion needs >= 40 time samples, got %d", k);
    CHECK(abs(streak - (20 + still_w)) <= 1, "streak %d px, expected 20 + %d", streak, still_w);
    CHECK(by0 >= ay0 && by1 <= ay1, "the streak left the point's rows");
    /* Still: 64 samples a pixel at one time; moving: 64 samples a pixel over
     * 64 time samples (one each), so a single frame is noisier (below). */
    CHECK(fabs(s0 / want - 1) < 0.01 && fabs(s1 / want - 1) < 0.05, "total signal still %.4f, moving %.4f of analytic",
          s0 / want, s1 / want);
    /* One budget: 64 time samples and 64 strata cost 64 camera rays a pixel
     * (every block traced: no culling), not 64 * 64. */
    struct nc_renderer rr;
    atomic_ulong rays = 0;
    nc_renderer_init(&rr, &s, 2);
    rr.no_cull = 1;
    rr.ray_hook = count_rays;
    rr.ray_hook_user = &rays;
    struct nc_frame h;
    nc_frame_alloc(&h, 96, 64);
    CHECK(nc_render_exposure(&rr, &s, &ex, &h, &k) == 0 && k == 64, "render");
    printf("one sample budget: %d time samples x %d strata, %.1f camera rays a pixel\n", k, 64, atomic_load(&rays) / (96.0 * 64));
    CHECK(atomic_load(&rays) == 96ul * 64 * 64, "camera rays %lu, expected 64 a pixel", atomic_load(&rays));
    nc_frame_free(&h);
    nc_renderer_free(&rr);
    /* ... and unbiased: each pixel's 64 samples are dealt to the time samples
     * by a random permutation per pixel; over 16 seeds the total signal's
     * mean is within 1 % of the analytic value, each within 5 %. */
    double sum = 0, worst = 0;
    for (int seed = 1; seed <= 16; seed++) {
        struct nc_frame m;
        s.render.seed = (uint64_t)seed;
        render(&s, &ex, &m, &k);
        sum += total(&m) / want;
        worst = fmax(worst, fabs(total(&m) / want - 1));
        nc_frame_free(&m);
    }
    printf("moving, 16 seeds: total signal mean %.5f of analytic, worst single frame off by %.4f\n", sum / 16, worst);
    CHECK(fabs(sum / 16 - 1) < 0.01 && worst < 0.05, "seeds: mean %.4f, worst %.4f", sum / 16, worst);
    /* The pose is the mid-exposure pose: the streak is centred on the still point. */
    CHECK(fabs(0.5 * (bx0 + bx1) - 0.5 * (ax0 + ax1)) <= 1.0, "streak centre %.1f vs still %.1f", 0.5 * (bx0 + bx1),
          0.5 * (ax0 + ax1));
    nc_frame_free(&still);
    nc_frame_free(&moving);
    nc_scene_free(&s);

    /* Rolling shutter: a vertical bar (a prolate ellipsoid) and a camera turning
     * about y: row y is exposed (y - 31.5) * line_time later than mid-frame, so
     * the bar shears by 1 rad/s * 1e-4 s * 1000 px = 0.1 px per row, 6.3 px
     * over the image. Without rotation the rolling shutter changes nothing. */
    const char *bar[] = {"bodies.0.shape={type: ellipsoid, radii_m: [8, 400, 8]}", "render.samples_per_pixel=64"};
    nc_test_scene(yaml, bar, 2, &s);
    struct nc_exposure g = {.exposure_s = 1e-4}, rs = {.exposure_s = 1e-4, .rolling = 1, .line_time_s = 1e-4};
    struct nc_frame fg, fr;
    render(&s, &g, &fg, &k);
    render(&s, &rs, &fr, &k);
    CHECK(!memcmp(fg.radiance, fr.radiance, sizeof(float) * 96 * 64), "a still scene: rolling = global shutter");
    nc_frame_free(&fr);
    s.camera.angular_velocity_rad_s = nc_v3(0, 1.0, 0);
    render(&s, &rs, &fr, &k);
    double shear = shear_px(&fr, &fg), expect = -1.0 * 1e-4 * 1000;
    printf("rolling shutter: bar centroid moves %.4f px per row (expected %.4f)\n", shear, expect);
    CHECK(fabs(shear - expect) < 0.02 * fabs(expect), "rolling-shutter shear %.4f px/row, expected %.4f", shear, expect);
    /* A view whose stored image is mirrored top to bottom (a SUM camera's K22 < 0) is read out in the stored
     * image's order, from the view's last row: the view shears the other way (it was timed by the view's rows,
     * as an outside check found) */
    nc_frame_free(&fr);
    s.camera.flip_rows = 1;
    render(&s, &rs, &fr, &k);
    shear = shear_px(&fr, &fg);
    printf("rolling shutter, the stored image mirrored: the view's bar moves %.4f px per row (expected %.4f)\n",
           shear, -expect);
    CHECK(fabs(shear + expect) < 0.02 * fabs(expect), "mirrored rows' shear %.4f px/row, expected %.4f", shear,
          -expect);
    nc_frame_free(&fg);
    nc_frame_free(&fr);
    nc_scene_free(&s);

    /* Inside a body's bounding sphere (a flat ellipsoid 800 m long, 16 m
     * thick; the camera 100 m from its centre, 92 m from its face): the
     * motion comes from the range the camera sees, not from no range at all
     * (before, every exposure in there took the 256 time samples of an
     * unbounded motion, even one of 0 s). At 1 m/s for 10 ms the face moves
     * 0.11 px: one time sample; at 100 m/s 10.9 px, which needs 22 samples
     * (K is estimated from half the least range seen: 64 at 64 strata); and
     * 0 s takes one. */
    const char *slab[] = {"bodies.0.shape={type: ellipsoid, radii_m: [400, 8, 8]}", "camera.position_m=[0, 0, -100]"};
    const double speed[3] = {1, 100, 100}, expo[3] = {0.01, 0.01, 0};
    const int kmin[3] = {1, 22, 1}, kmax[3] = {1, 64, 1};
    for (int c = 0; c < 3; c++) {
        nc_test_scene(yaml, slab, 2, &s);
        s.camera.velocity_m_s = nc_v3(speed[c], 0, 0);
        struct nc_exposure e = {.exposure_s = expo[c]};
        struct nc_frame fs;
        render(&s, &e, &fs, &k);
        printf("inside a bounding sphere, 92 m from the face, %g m/s for %g s: %d time samples\n", speed[c], expo[c],
               k);
        CHECK(k >= kmin[c] && k <= kmax[c], "%g m/s for %g s: %d time samples, expected %d to %d", speed[c], expo[c],
              k, kmin[c], kmax[c]);
        nc_frame_free(&fs);
        nc_scene_free(&s);
    }
    return nc_test_end();
}
