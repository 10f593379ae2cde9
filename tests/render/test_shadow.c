/* test_shadow.c - one body shadows another: a small sphere hovering over a
 * large one casts a shadow whose every pixel is checked geometrically (is the
 * segment from the visible point toward the Sun blocked by the small sphere?). */
#include <math.h>
#include <stdio.h>

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

int main(void)
{
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
