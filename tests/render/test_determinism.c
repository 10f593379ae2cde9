/* test_determinism.c - the same scene gives bit-identical frames for any
 * thread count, for repeated renders, and for a freshly built renderer. */
#include <stdio.h>
#include <string.h>

#include "testutil.h"

static int same(const struct nc_frame *a, const struct nc_frame *b)
{
    size_t n = (size_t)a->width_px * a->height_px * sizeof(float);
    return !memcmp(a->radiance, b->radiance, n) && !memcmp(a->iof, b->iof, n) && !memcmp(a->range_m, b->range_m, n) &&
           !memcmp(a->coverage, b->coverage, n);
}

int main(void)
{
    /* The built-in default scene (procedural mesh, 4 jittered samples) at a
     * reduced size, with a width that is not a multiple of the tile size. */
    const char *sets[] = {"camera.width_px=203", "camera.height_px=157", "camera.focal_length_m=0.012",
                          "bodies.0.shape.subdivisions=5"};
    struct nc_scene s;
    nc_test_scene(nc_default_scene_yaml, sets, 4, &s);
    struct nc_frame ref;
    nc_test_render(&s, 1, &ref);
    double sum = 0;
    for (int i = 0; i < ref.width_px * ref.height_px; i++)
        sum += ref.radiance[i];
    CHECK(sum > 0, "the reference frame is black");
    const int threads[] = {2, 3, 8};
    for (int k = 0; k < 3; k++) {
        struct nc_frame f;
        nc_test_render(&s, threads[k], &f);
        CHECK(same(&ref, &f), "%d threads differ from 1 thread", threads[k]);
        nc_frame_free(&f);
    }
    /* One renderer, two frames, the camera moved away and back in between. */
    struct nc_renderer r;
    struct nc_frame f;
    CHECK(nc_renderer_init(&r, &s, 2) == 0, "renderer");
    nc_frame_alloc(&f, s.camera.width_px, s.camera.height_px);
    nc_render_frame(&r, &s, &f);
    CHECK(same(&ref, &f), "first frame of a reused renderer differs");
    struct nc_vec3 keep = s.camera.position_m;
    s.camera.position_m = nc_v3(keep.x + 37.0, keep.y + 11.0, keep.z);
    nc_render_frame(&r, &s, &f);
    CHECK(!same(&ref, &f), "moving the camera did not change the frame");
    s.camera.position_m = keep;
    nc_render_frame(&r, &s, &f);
    CHECK(same(&ref, &f), "returning the camera to its pose does not reproduce the frame");
    /* A pose reached through a nearby one (1 mm away, same geometry cell or
     * not) renders exactly as a fresh renderer does: pixels depend on the
     * pose alone, never on the path. */
    for (int k = 0; k < 3; k++) {
        const double step_m[] = {1e-3, 0.7, 3.0};
        s.camera.position_m = nc_v3(keep.x + step_m[k], keep.y - step_m[k], keep.z + step_m[k]);
        nc_render_frame(&r, &s, &f);
        s.camera.position_m = keep;
        nc_render_frame(&r, &s, &f);
        CHECK(same(&ref, &f), "pose reached from %g m away renders differently from a fresh renderer", step_m[k]);
    }
    nc_frame_free(&f);
    nc_renderer_free(&r);
    /* An exposure with motion smear and a rolling shutter: the same for any
     * thread count too. */
    s.camera.angular_velocity_rad_s = nc_v3(0.01, 0.2, -0.03);
    s.body[0].angular_velocity_rad_s = nc_v3(0, 0, 0.01);
    struct nc_exposure ex = {.exposure_s = 0.01, .rolling = 1, .line_time_s = 2e-5};
    struct nc_frame e1, e3;
    struct nc_renderer r1, r3;
    int k1 = 0, k3 = 0;
    nc_renderer_init(&r1, &s, 1);
    nc_renderer_init(&r3, &s, 3);
    nc_frame_alloc(&e1, s.camera.width_px, s.camera.height_px);
    nc_frame_alloc(&e3, s.camera.width_px, s.camera.height_px);
    nc_render_exposure(&r1, &s, &ex, &e1, &k1);
    nc_render_exposure(&r3, &s, &ex, &e3, &k3);
    CHECK(k1 > 1 && k1 == k3 && same(&e1, &e3), "smeared rolling-shutter exposure differs between 1 and 3 threads (%d, %d samples)",
          k1, k3);
    nc_frame_free(&e1);
    nc_frame_free(&e3);
    nc_renderer_free(&r1);
    nc_renderer_free(&r3);
    nc_frame_free(&ref);
    nc_scene_free(&s);
    return nc_test_end();
}
