/* test_determinism.c - the same scene gives bit-identical frames for any
 * thread count, for repeated renders, and for a freshly built renderer; a
 * camera model's margin changes none of the sensor's pixels. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"

#include "testutil.h"

static int same(const struct nc_frame *a, const struct nc_frame *b)
{
    size_t n = (size_t)a->width_px * a->height_px * sizeof(float);
    return !memcmp(a->radiance, b->radiance, n) && !memcmp(a->iof, b->iof, n) && !memcmp(a->range_m, b->range_m, n) &&
           !memcmp(a->coverage, b->coverage, n);
}

static void count_packet(void *user, int shadow, const struct nc_ray16 *ray, int frame)
{
    (void)ray, (void)frame;
    ((long *)user)[shadow]++;
}

/* Skipping the blocks whose rays cannot reach a body changes no pixel and
 * does skip some: the same exposure traced with and without the test. */
static void check_cull(struct nc_scene *s, const struct nc_exposure *ex, const char *what, int expect_skip)
{
    struct nc_frame a, b;
    struct nc_renderer ra, rb;
    long packets[2][2] = {{0, 0}, {0, 0}};
    int ka = 0, kb = 0;
    nc_renderer_init(&ra, s, 1);
    nc_renderer_init(&rb, s, 1);
    rb.no_cull = 1;
    ra.ray_hook = rb.ray_hook = count_packet;
    ra.ray_hook_user = packets[0];
    rb.ray_hook_user = packets[1];
    nc_frame_alloc(&a, s->camera.width_px, s->camera.height_px);
    nc_frame_alloc(&b, s->camera.width_px, s->camera.height_px);
    nc_render_exposure(&ra, s, ex, &a, &ka);
    nc_render_exposure(&rb, s, ex, &b, &kb);
    double sum = 0;
    for (int i = 0; i < a.width_px * a.height_px; i++)
        sum += a.coverage[i];
    CHECK(sum > 0 && ka == kb && same(&a, &b), "%s: skipping empty blocks changed the frame", what);
    CHECK(packets[0][1] == packets[1][1], "%s: shadow packets %ld with the test, %ld without", what, packets[0][1],
          packets[1][1]);
    CHECK(expect_skip ? packets[0][0] < packets[1][0] : packets[0][0] == packets[1][0],
          "%s: %ld camera packets traced with the test, %ld without", what, packets[0][0], packets[1][0]);
    nc_frame_free(&a);
    nc_frame_free(&b);
    nc_renderer_free(&ra);
    nc_renderer_free(&rb);
}

/* A camera model's margin (a PSF's) changes no sample of the sensor's
 * pixels: the same camera drawn m pixels wider on every side gives the
 * frame's pixels at (x + m, y + m), up to the rounding of the shifted pixel
 * coordinates (the samples were keyed to the drawn image's pixels once: a
 * PSF made the limb's pixels differ by up to 38 %). */
static void check_margin(struct nc_scene *s, const struct nc_frame *ref, const char *what)
{
    const int m = 5;
    struct nc_scene wide = *s;
    wide.camera.width_px += 2 * m;
    wide.camera.height_px += 2 * m;
    wide.camera.cx_px += m;
    wide.camera.cy_px += m;
    wide.camera.margin_px = m;
    struct nc_frame f;
    nc_test_render(&wide, 2, &f);
    long differ = 0, far = 0, lit = 0;
    for (int y = 0; y < ref->height_px; y++)
        for (int x = 0; x < ref->width_px; x++) {
            const float a = ref->radiance[y * ref->width_px + x], b = f.radiance[(y + m) * f.width_px + x + m];
            lit += a > 0;
            differ += a != b;
            far += fabsf(a - b) > 1e-5f * fmaxf(a, b);
        }
    printf("%s: with a %d-pixel margin, %ld of %ld lit pixels differ (%ld by more than 1e-5)\n", what, m, differ, lit,
           far);
    CHECK(lit > 1000 && far == 0 && differ <= lit / 1000, "%s: a margin changed %ld pixels (%ld by more than 1e-5)",
          what, differ, far);
    nc_frame_free(&f);
}

/* The widest angle between two rays of any camera packet, rad. */
struct spread {
    long packets;
    double max_rad;
};

static void packet_spread(void *user, int shadow, const struct nc_ray16 *ray, int frame)
{
    (void)frame;
    struct spread *sp = user;
    if (shadow)
        return;
    sp->packets++;
    for (int a = 0; a < NC_PACKET; a++)
        for (int b = a + 1; b < NC_PACKET; b++) {
            if (!ray->valid[a] || !ray->valid[b])
                continue;
            double c = ray->dx[a] * ray->dx[b] + ray->dy[a] * ray->dy[b] + ray->dz[a] * ray->dz[b];
            double ang = acos(c > 1 ? 1 : c);
            if (ang > sp->max_rad)
                sp->max_rad = ang;
        }
}

/* Camera packets through Embree (where the camera-ray bins do not serve:
 * a moving or distorting camera, analytic bodies, boulders) of 2x2 pixels x
 * 4 samples (the default) and of one sample of 4x4 pixels give the same
 * frame, with as many packets, the former narrower: at 4 samples (2x2
 * strata), 9 (a packet takes parts of two pixels) and 16 samples over 2
 * time samples (8 a pass). */
static void check_grouped(struct nc_scene *s, int spp, const struct nc_exposure *ex, const char *what)
{
    struct nc_frame a, b;
    struct nc_renderer ra, rb;
    struct spread sa = {0, 0}, sb = {0, 0};
    int ka = 0, kb = 0, keep = s->render.samples_per_pixel;
    s->render.samples_per_pixel = spp;
    nc_renderer_init(&ra, s, 1);
    nc_renderer_init(&rb, s, 1);
    rb.one_sample_packets = 1;
    ra.no_bins = rb.no_bins = 1;
    ra.ray_hook = rb.ray_hook = packet_spread;
    ra.ray_hook_user = &sa;
    rb.ray_hook_user = &sb;
    nc_frame_alloc(&a, s->camera.width_px, s->camera.height_px);
    nc_frame_alloc(&b, s->camera.width_px, s->camera.height_px);
    nc_render_exposure(&ra, s, ex, &a, &ka);
    nc_render_exposure(&rb, s, ex, &b, &kb);
    CHECK(ka == kb && ka == (ex->max_time_samples ? ex->max_time_samples : 1) && same(&a, &b),
          "%s: grouped camera packets changed the frame (%d, %d time samples)", what, ka, kb);
    CHECK(sa.packets == sb.packets, "%s: %ld grouped camera packets, %ld of one sample", what, sa.packets, sb.packets);
    /* a 4x4 block spans about 4.2 pixels corner to corner, a 2x2 quad 2.8 */
    CHECK(sa.max_rad < 0.8 * sb.max_rad, "%s: grouped packets span %.3g rad, one-sample packets %.3g", what,
          sa.max_rad, sb.max_rad);
    printf("%s: %ld camera packets; widest %.3g mrad grouped, %.3g mrad one sample a packet\n", what, sa.packets,
           1e3 * sa.max_rad, 1e3 * sb.max_rad);
    s->render.samples_per_pixel = keep;
    nc_frame_free(&a);
    nc_frame_free(&b);
    nc_renderer_free(&ra);
    nc_renderer_free(&rb);
}

/* The branch-free lane loops (surface points, hard-shadow rays) and the
 * general loops lane by lane give the same frame: the scene as set, and
 * with rocks (their hits go through the same loops). */
static void check_lanes(struct nc_scene *s, const char *what)
{
    struct nc_frame a, b;
    struct nc_renderer ra, rb;
    CHECK(nc_renderer_init(&ra, s, 2) == 0 && nc_renderer_init(&rb, s, 2) == 0, "%s: renderers", what);
    rb.lane_by_lane = 1;
    nc_frame_alloc(&a, s->camera.width_px, s->camera.height_px);
    nc_frame_alloc(&b, s->camera.width_px, s->camera.height_px);
    CHECK(nc_render_frame(&ra, s, &a) == 0 && nc_render_frame(&rb, s, &b) == 0, "%s: render", what);
    double sum = 0;
    for (int i = 0; i < a.width_px * a.height_px; i++)
        sum += a.radiance[i];
    CHECK(sum > 0 && same(&a, &b), "%s: the branch-free lane loops changed the frame", what);
    nc_frame_free(&a);
    nc_frame_free(&b);
    nc_renderer_free(&ra);
    nc_renderer_free(&rb);
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
    check_lanes(&s, "default scene");
    {
        const char *rs[] = {"camera.width_px=160", "camera.height_px=120", "camera.position_m=[0,-1500,0]",
                            "bodies.0.boulders={preset: bennu, min_diameter_m: 2}"};
        struct nc_scene rocky;
        nc_test_scene(nc_default_scene_yaml, rs, 4, &rocky);
        check_lanes(&rocky, "rocks from 2 m at 1.5 km");
        nc_scene_free(&rocky);
    }
    {
        /* Within a bounding radius of the surface the mesh's hits near the
         * camera are recomputed in double (nc_rt_refine_mesh16), on every
         * path a camera ray takes (here 4 samples without the bins' path,
         * and a bounce): the same frame on 1 and 3 threads. */
        const char *cs[] = {"camera.width_px=96", "camera.height_px=80", "camera.position_m=[0,-400,0]",
                            "render.bounces=1"};
        struct nc_scene close;
        nc_test_scene(nc_default_scene_yaml, cs, 4, &close);
        struct nc_renderer rc;
        CHECK(nc_renderer_init(&rc, &close, 1) == 0, "renderer");
        struct nc_frame c1, c3;
        nc_frame_alloc(&c1, close.camera.width_px, close.camera.height_px);
        CHECK(nc_render_frame(&rc, &close, &c1) == 0 && nc_rt_refine_on(rc.rt), "close: refinement on: %s",
              nc_errmsg());
        nc_test_render(&close, 3, &c3);
        CHECK(same(&c1, &c3), "close camera, refined mesh hits: 3 threads differ from 1");
        nc_frame_free(&c1);
        nc_frame_free(&c3);
        nc_renderer_free(&rc);
        nc_scene_free(&close);
    }
    const int threads[] = {2, 3, 8};
    for (int k = 0; k < 3; k++) {
        struct nc_frame f;
        nc_test_render(&s, threads[k], &f);
        CHECK(same(&ref, &f), "%d threads differ from 1 thread", threads[k]);
        nc_frame_free(&f);
    }
    check_margin(&s, &ref, "default scene");
    {
        struct nc_scene soft = s;
        soft.render.soft_shadows = 1;
        soft.render.bounces = 1;
        struct nc_frame sref;
        nc_test_render(&soft, 2, &sref);
        check_margin(&soft, &sref, "soft shadows, 1 bounce");
        nc_frame_free(&sref);
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
    /* Again with the same renderer: its time-sample buffers (kept between
     * exposures) start each exposure afresh. */
    nc_render_exposure(&r3, &s, &ex, &e3, &k3);
    CHECK(k1 == k3 && same(&e1, &e3), "a second smeared exposure with the same renderer differs from the first");
    nc_frame_free(&e1);
    nc_frame_free(&e3);
    /* Empty blocks: the body in view, still and smeared (rolling shutter,
     * the camera moving and turning); the limb cut by the frame's edge; a
     * second body; the camera inside the bounding sphere (nothing skipped). */
    struct nc_exposure still = {.exposure_s = 0.001};
    struct nc_vec3 w = s.camera.angular_velocity_rad_s;
    s.camera.angular_velocity_rad_s = nc_v3(0, 0, 0);
    s.body[0].angular_velocity_rad_s = nc_v3(0, 0, 0);
    check_cull(&s, &still, "body in view", 1);
    s.camera.angular_velocity_rad_s = w;
    s.camera.velocity_m_s = nc_v3(300, 0, 200);
    check_cull(&s, &ex, "rolling shutter, moving camera", 1);
    s.camera.angular_velocity_rad_s = nc_v3(0, 0, 0);
    s.camera.velocity_m_s = nc_v3(0, 0, 0);
    s.body[0].position_m = nc_v3(250, 0, 120); /* the limb leaves the frame */
    check_cull(&s, &still, "limb at the edge", 1);
    s.body[1] = s.body[0];
    s.body[1].position_m = nc_v3(-200, 900, -100);
    s.nbodies = 2;
    check_cull(&s, &still, "two bodies", 1);
    s.nbodies = 1;
    s.body[0].position_m = nc_v3(0, 0, 0);
    s.camera.position_m = nc_v3(0, -s.body[0].bounding_radius_m * 0.9, 0);
    check_cull(&s, &still, "camera inside the bounding sphere", 0);
    s.camera.position_m = keep;
    check_grouped(&s, 4, &still, "4 samples");
    check_grouped(&s, 9, &still, "9 samples");
    struct nc_exposure turning = {.exposure_s = 0.01, .max_time_samples = 2};
    s.camera.angular_velocity_rad_s = nc_v3(0, 0.05, 0);
    check_grouped(&s, 16, &turning, "16 samples, 2 time samples");
    s.camera.angular_velocity_rad_s = nc_v3(0, 0, 0);
    nc_renderer_free(&r1);
    nc_renderer_free(&r3);
    nc_frame_free(&ref);
    nc_scene_free(&s);
    return nc_test_end();
}
