/* test_shadow.c - one body shadows another: a small sphere hovering over a
 * large one casts a shadow whose every pixel is checked geometrically (is the
 * segment from the visible point toward the Sun blocked by the small sphere?).
 * With render.soft_shadows and a Sun 0.05 au away (5.3 deg in radius), the
 * umbra is dark, the ground beyond the penumbra is lit exactly as with hard
 * shadows, and in the penumbra the lit fraction follows the visible part of
 * the solar disk (two overlapping disks). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "testutil.h"

static const char yaml[] =
    "bodies:\n"
    "  - name: ground\n"
    "    shape: {type: sphere, radius_m: 1000}\n"
    "    material: {model: lambert, A: 0.2}\n"
    "  - name: boulder\n"
    "    shape: {type: sphere, radius_m: 80}\n"
    "    material: {model: lambert, A: 0.2}\n"
    "    position_m: [0, 0, -1200]\n"
    "sun: {direction: [0.25, 0.1, -1]}\n"
    "camera:\n"
    "  width_px: 200\n"
    "  height_px: 200\n"
    "  fx_px: 260\n"
    "  fy_px: 260\n"
    "  position_m: [-900, 300, -1700]\n"
    "  look_at_m: [40, 0, -990]\n"
    "  up: [0, 0, -1]\n";

/* Nearest positive root of |o + t d - c| = r, or INFINITY. */
static double ray_sphere(struct nc_vec3 o, struct nc_vec3 d, struct nc_vec3 c, double r)
{
    struct nc_vec3 oc = nc_v3_sub(o, c);
    double b = nc_v3_dot(oc, d), cc = nc_v3_dot(oc, oc) - r * r, disc = b * b - cc;
    if (disc < 0)
        return INFINITY;
    double t = -b - sqrt(disc);
    if (t > 0)
        return t;
    t = -b + sqrt(disc);
    return t > 0 ? t : INFINITY;
}

/* Visible fraction of a disk of angular radius a whose centre is g from
 * that of an occluding disk of radius b (small angles: plane circles). */
static double disk_visible(double a, double b, double g)
{
    if (g >= a + b)
        return 1;
    if (g <= b - a)
        return 0;
    if (g <= a - b)
        return 1 - (b * b) / (a * a);
    double lens = a * a * acos((g * g + a * a - b * b) / (2 * g * a)) + b * b * acos((g * g + b * b - a * a) / (2 * g * b)) -
                  0.5 * sqrt((-g + a + b) * (g + a - b) * (g - a + b) * (g + a + b));
    return 1 - lens / (M_PI * a * a);
}

static void check_soft(void)
{
    const char *hard_sets[] = {"sun.distance_au=0.05", "render.samples_per_pixel=16"};
    const char *soft_sets[] = {"sun.distance_au=0.05", "render.samples_per_pixel=16", "render.soft_shadows=true"};
    /* the ground alone (the boulder far out of view): no shadow at all */
    const char *bare_sets[] = {"sun.distance_au=0.05", "render.samples_per_pixel=16", "bodies[1].position_m=[0, 0, 1e7]"};
    struct nc_scene hs, ss, bs;
    nc_test_scene(yaml, hard_sets, 2, &hs);
    nc_test_scene(yaml, soft_sets, 3, &ss);
    nc_test_scene(yaml, bare_sets, 3, &bs);
    struct nc_frame hf, sf, bf;
    nc_test_render(&hs, 2, &hf);
    nc_test_render(&ss, 2, &sf);
    nc_test_render(&bs, 2, &bf);
    const struct nc_camera *c = &ss.camera;
    const double alpha = nc_scene_sun_radius_rad(&ss);
    struct nc_vec3 sun = ss.sun.direction, small_c = ss.body[1].position_m;
    double small_r = ss.body[1].radii_m.x, big_r = ss.body[0].radii_m.x;
    int umbra = 0, beyond = 0, partial = 0, wrong = 0;
    double bias = 0, sq = 0;
    for (int y = 0; y < c->height_px; y++)
        for (int x = 0; x < c->width_px; x++) {
            struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
            double tb = ray_sphere(c->position_m, d, nc_v3(0, 0, 0), big_r), ts = ray_sphere(c->position_m, d, small_c, small_r);
            if (!(tb < ts) || !isfinite(tb))
                continue;
            struct nc_vec3 p = nc_v3_add(c->position_m, nc_v3_scale(d, tb)), n = nc_v3_unit(p);
            if (nc_v3_dot(n, sun) <= alpha + 0.02 || -nc_v3_dot(n, d) < 0.05)
                continue; /* the disk wholly above the horizon */
            struct nc_vec3 pc = nc_v3_sub(small_c, p);
            double dist = nc_v3_norm(pc), beta = asin(small_r / dist), gamma = acos(nc_v3_dot(pc, sun) / dist);
            double margin = 2.0 * tb / c->fx_px / dist; /* a pixel's footprint, as an angle from the occluder */
            size_t i = (size_t)y * c->width_px + x;
            float L = sf.radiance[i], Lh = hf.radiance[i], Lb = bf.radiance[i];
            if (gamma + alpha < beta - margin) {
                umbra++;
                wrong += L != 0.0f;
            } else if (gamma > beta + alpha + margin) {
                beyond++;
                wrong += L != Lh; /* every shadow ray reaches the disk: the hard frame's value */
            } else if (fabs(gamma - beta) < 0.5 * alpha && Lb > 0) {
                partial++;
                double e = L / Lb - disk_visible(alpha, beta, gamma);
                bias += e, sq += e * e;
            }
        }
    bias /= partial;
    double rms = sqrt(sq / partial);
    printf("soft shadows, Sun radius %.4f rad: %d umbra pixels, %d beyond the penumbra, %d in its middle: lit "
           "fraction against the disks' overlap %+.4f on average, %.3f RMS (16 samples a pixel); %d wrong\n",
           alpha, umbra, beyond, partial, bias, rms, wrong);
    CHECK(umbra > 50 && beyond > 3000 && partial > 200, "too few pixels: %d %d %d", umbra, beyond, partial);
    CHECK(wrong == 0, "%d pixels in the umbra lit or beyond the penumbra not as with hard shadows", wrong);
    CHECK(fabs(bias) < 0.02 && rms < 0.2, "penumbra: bias %g, RMS %g", bias, rms);

    /* The same samples with a bounce, its direct sunlight and hard-shadow twin planes. */
    struct nc_scene ps = ss;
    ps.render.bounces = 1;
    struct nc_frame pf;
    struct nc_renderer r;
    const size_t n = (size_t)c->width_px * (size_t)c->height_px;
    if (nc_renderer_init(&r, &ps, 2) < 0 || nc_frame_alloc(&pf, c->width_px, c->height_px) < 0 ||
        !(pf.direct = malloc(n * sizeof *pf.direct)) || !(pf.direct_hard = malloc(n * sizeof *pf.direct_hard)) ||
        nc_render_frame(&r, &ps, &pf) < 0) {
        fprintf(stderr, "render: %s\n", nc_errmsg());
        exit(2);
    }
    size_t differ_dir = 0, differ_hard = 0, bounce_lit = 0, penumbra = 0;
    for (size_t i = 0; i < n; i++) {
        differ_dir += memcmp(&pf.direct[i], &sf.radiance[i], sizeof(float)) != 0;
        differ_hard += memcmp(&pf.direct_hard[i], &hf.radiance[i], sizeof(float)) != 0;
        bounce_lit += pf.radiance[i] > pf.direct[i];
        penumbra += pf.direct[i] != pf.direct_hard[i];
    }
    printf("with a bounce: %zu pixels gain bounce light, %zu differ soft from hard; direct plane unlike the soft "
           "render's radiance in %zu pixels, direct_hard unlike the hard render's in %zu\n",
           bounce_lit, penumbra, differ_dir, differ_hard);
    CHECK(differ_dir == 0 && differ_hard == 0, "planes differ from the renders they stand for: %zu, %zu", differ_dir,
          differ_hard);
    CHECK(bounce_lit > 1000 && penumbra > 200, "the planes should differ from radiance (%zu) and each other (%zu)",
          bounce_lit, penumbra);
    nc_renderer_free(&r);
    nc_frame_free(&pf);
    nc_frame_free(&hf);
    nc_frame_free(&sf);
    nc_frame_free(&bf);
    nc_scene_free(&hs);
    nc_scene_free(&ss);
    nc_scene_free(&bs);
}

int main(void)
{
    check_soft();
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    struct nc_frame f;
    nc_test_render(&s, 2, &f);
    const struct nc_camera *c = &s.camera;
    struct nc_vec3 sun = s.sun.direction, small_c = s.body[1].position_m, big_c = nc_v3(0, 0, 0);
    double small_r = s.body[1].radii_m.x, big_r = s.body[0].radii_m.x;
    int shadowed = 0, lit = 0, wrong = 0, margin_skipped = 0;
    for (int y = 0; y < c->height_px; y++)
        for (int x = 0; x < c->width_px; x++) {
            struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
            double tb = ray_sphere(c->position_m, d, big_c, big_r), ts = ray_sphere(c->position_m, d, small_c, small_r);
            if (!(tb < ts) || !isfinite(tb))
                continue; /* only points on the ground */
            struct nc_vec3 p = nc_v3_add(c->position_m, nc_v3_scale(d, tb));
            struct nc_vec3 n = nc_v3_unit(p);
            if (nc_v3_dot(n, sun) <= 0.01 || -nc_v3_dot(n, d) < 0.05)
                continue;
            /* Distance from the small sphere's centre to the shadow ray. */
            struct nc_vec3 pc = nc_v3_sub(small_c, p);
            double along = nc_v3_dot(pc, sun);
            double miss = nc_v3_norm(nc_v3_sub(pc, nc_v3_scale(sun, along)));
            /* A pixel footprint here is about tb/fx; skip the penumbra-free edge band. */
            double foot = 2.0 * tb / c->fx_px;
            if (along > 0 && fabs(miss - small_r) < foot) {
                margin_skipped++;
                continue;
            }
            int expect_shadow = along > 0 && miss < small_r;
            float L = f.radiance[y * c->width_px + x];
            if (expect_shadow) {
                shadowed++;
                wrong += L != 0.0f;
            } else {
                lit++;
                wrong += !(L > 0.0f);
            }
        }
    printf("ground pixels: %d in the boulder's shadow, %d lit, %d on the shadow edge skipped\n", shadowed, lit,
           margin_skipped);
    CHECK(shadowed > 300, "the shadow should cover a few hundred pixels, got %d", shadowed);
    CHECK(lit > 3000, "lit ground pixels %d", lit);
    CHECK(wrong == 0, "%d ground pixels disagree with the geometric shadow", wrong);
    nc_frame_free(&f);
    nc_scene_free(&s);
    return nc_test_end();
}
