/* test_precision.c - a camera 1 m above a Moon-sized body renders without
 * float precision artefacts, because geometry is stored relative to an anchor
 * near the camera. In body-fixed float coordinates a Moon-radius position is
 * quantised to 0.125 m, which would put 10% errors on a 1 m range; here range
 * and radiance must match the exact double-precision answer to 5e-7.
 *  A: exact analytic sphere of the Moon's radius.
 *  B: a triangle mesh patch (given in km) lying on z = -R_moon.
 *  C: the same patch seen from about one Moon radius beyond the body's
 *     bounding sphere, on either side of the point where the mesh's anchor
 *     becomes the body's origin (render/rt_embree.c): range within 2e-7.
 *  D: a patch of the same 100 m facets tangent to the sphere off every axis,
 *     the camera 1 m and 1.3 m above it: its float vertices, up to an edge
 *     from the anchor, alone would err by 3e-6 of the range and shadow a
 *     lit pixel (false self-shadowing); the hits are recomputed in double
 *     from the mesh's vertices (nc_rt_refine_mesh16).
 *  E: a 5 120-facet sphere seen from 6000 km (60 px across): each pixel's
 *     shading that of the facet its centre's ray meets, found in double
 *     here, to 1e-5 (Embree's facet normal, from float vertices relative to
 *     the ray's origin, erred with the range: an outside check found a 67P
 *     model's shading 2e-3 off at 6000 km, its median). */
#include <math.h>
#include <string.h>
#include <stdio.h>
#include <stdlib.h>

#include "testutil.h"

#define R_MOON 1737400.0

static const char yaml_sphere[] =
    "bodies:\n"
    "  - shape: {type: sphere, radius_m: 1737400}\n"
    "    material: {model: lambert, A: 0.12}\n"
    "sun: {direction: [0.85, 0.2, -0.5]}\n"
    "camera:\n"
    "  width_px: 200\n"
    "  height_px: 150\n"
    "  fx_px: 300\n"
    "  fy_px: 300\n"
    "  position_m: [0.25, -0.5, -1737401.3]\n"
    "  look_at_m: [3.25, -0.5, -1737400]\n"
    "  up: [0, 0, -1]\n";

struct stats {
    int n, black;
    double worst_range, worst_L;
};

static void check_pixel(struct stats *st, const struct nc_frame *f, int x, int y, double t_exact, double L_exact)
{
    size_t k = (size_t)y * f->width_px + x;
    st->n++;
    if (!(t_exact > 0 && L_exact > 0)) {
        st->worst_range = INFINITY; /* a broken reference must fail, not pass */
        return;
    }
    double er = fabs(f->range_m[k] - t_exact) / t_exact, el = fabs(f->radiance[k] - L_exact) / L_exact;
    st->worst_range = fmax(st->worst_range, er);
    st->worst_L = fmax(st->worst_L, el);
    st->black += f->radiance[k] == 0.0f;
}

static void report(const char *label, const struct stats *st)
{
    printf("%s: %d pixels, worst range error %.2e, worst radiance error %.2e, black %d\n", label, st->n,
           st->worst_range, st->worst_L, st->black);
    CHECK(st->n > 10000, "%s: only %d pixels checked", label, st->n);
    /* relative, against the exact answer in double precision: float32
     * radiance rounds at 6e-8; measured up to 1.7e-7 (range, mesh patch) */
    CHECK(st->worst_range < 5e-7, "%s: range error %.3g", label, st->worst_range);
    CHECK(st->worst_L < 5e-7, "%s: radiance error %.3g", label, st->worst_L);
    CHECK(st->black == 0, "%s: %d lit pixels rendered black (self-shadowing acne)", label, st->black);
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void shading_at_range(void)
{
    const char *yaml = "bodies:\n"
                       "  - shape: {type: asteroid, radii_m: [1000, 1000, 1000], subdivisions: 4, craters: 0, "
                       "lump_amplitude: 0}\n"
                       "    material: {model: lambert, A: 0.2}\n"
                       "sun: {direction: [0.6427876, -0.7660444, 0]}\n"
                       "camera: {width_px: 96, height_px: 96, fx_px: 180000, fy_px: 180000,\n"
                       "         position_m: [0, -6000000, 0], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n"
                       "render: {samples_per_pixel: 1}\n";
    struct nc_scene s;
    struct nc_frame f;
    nc_test_scene(yaml, NULL, 0, &s);
    nc_test_render(&s, 2, &f);
    const struct nc_vec3 o = s.camera.position_m, sun = nc_v3_unit(s.sun.direction);
    double rel[96 * 96];
    size_t n = 0;
    for (int y = 0; y < 96; y++)
        for (int x = 0; x < 96; x++) {
            const struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(s.camera.attitude_q, nc_camera_dir(&s.camera, x, y)));
            double t, inside = 0;
            struct nc_vec3 nrm;
            const double mu0 = nc_test_mesh_hit(&s.body[0].mesh, o, d, &t, &nrm, &inside) ? nc_v3_dot(nrm, sun) : 0;
            if (inside > 0.02 && mu0 > 0.05) /* Lambert: L = A J mu0 / pi */
                rel[n++] = fabs(f.radiance[y * 96 + x] / (0.2 * s.sun.irradiance_w_m2 * mu0 / M_PI) - 1);
        }
    qsort(rel, n, sizeof *rel, cmp_double);
    const double median = n ? rel[n / 2] : 1, p90 = n ? rel[n * 9 / 10] : 1;
    printf("E: 5120 facets from 6000 km: %zu lit pixels inside facets, shading off the exact facet's by %.2g "
           "(median), %.2g (90th percentile)\n", n, median, p90);
    CHECK(n > 1000 && median < 1e-5 && p90 < 1e-4, "E: shading at 6000 km: median %.3g, 90th percentile %.3g", median,
          p90);
    nc_frame_free(&f);
    nc_scene_free(&s);
}

int main(void)
{
    shading_at_range();
    /* A: analytic sphere. */
    struct nc_scene s;
    nc_test_scene(yaml_sphere, NULL, 0, &s);
    struct nc_frame f;
    nc_test_render(&s, 2, &f);
    const struct nc_camera *c = &s.camera;
    struct stats st = {0};
    for (int y = 0; y < c->height_px; y++)
        for (int x = 0; x < c->width_px; x++) {
            struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
            struct nc_vec3 o = c->position_m;
            double b = nc_v3_dot(o, d), on = nc_v3_norm(o);
            double cc = (on - R_MOON) * (on + R_MOON); /* no cancellation */
            double disc = b * b - cc;
            if (disc < 0)
                continue;
            double q = -(b + copysign(sqrt(disc), b)), t = fmin(q, cc / q);
            if (!(t > 0))
                continue;
            struct nc_vec3 n = nc_v3_unit(nc_v3_add(o, nc_v3_scale(d, t)));
            double mu0 = nc_v3_dot(n, s.sun.direction), mu = -nc_v3_dot(n, d);
            if (mu < 0.05 || mu0 <= 0)
                continue;
            check_pixel(&st, &f, x, y, t, 0.12 / M_PI * mu0 * s.sun.irradiance_w_m2);
        }
    report("analytic Moon sphere, camera 1 m up", &st);
    nc_frame_free(&f);
    nc_scene_free(&s);

    /* B: mesh patch 2 km x 2 km at the Moon's radius, vertices in km. */
    const char *obj = nc_test_path("moon_patch.obj");
    FILE *fo = fopen(obj, "w");
    const int N = 20;
    for (int j = 0; j <= N; j++)
        for (int i = 0; i <= N; i++)
            fprintf(fo, "v %.17g %.17g %.17g\n", -1.0 + 2.0 * i / N, -1.0 + 2.0 * j / N, -R_MOON / 1000);
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            int a = j * (N + 1) + i + 1, b = a + 1, cc = a + N + 1, dd = cc + 1;
            fprintf(fo, "f %d %d %d\nf %d %d %d\n", a, b, dd, a, dd, cc);
        }
    fclose(fo);
    char shape[1200];
    snprintf(shape, sizeof shape, "bodies.0.shape={type: mesh, file: '%s', unit: km}", obj);
    const char *sets[] = {shape};
    nc_test_scene(yaml_sphere, sets, 1, &s);
    nc_test_render(&s, 2, &f);
    memset(&st, 0, sizeof st);
    for (int y = 0; y < c->height_px; y++)
        for (int x = 0; x < c->width_px; x++) {
            struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
            if (d.z <= 0.05)
                continue;
            double t = (-R_MOON - c->position_m.z) / d.z; /* plane z = -R */
            struct nc_vec3 p = nc_v3_add(c->position_m, nc_v3_scale(d, t));
            if (fabs(p.x) > 990 || fabs(p.y) > 990)
                continue;
            double mu0 = -s.sun.direction.z;
            check_pixel(&st, &f, x, y, t, 0.12 / M_PI * mu0 * s.sun.irradiance_w_m2);
        }
    report("mesh patch at the Moon's radius, camera 1 m up", &st);
    nc_frame_free(&f);
    nc_scene_free(&s);

    /* C: far out. 2 km patch, 258 px across; float vertices about the
     * body's origin are quantised to 0.125 m, 1/60 of a pixel's footprint. */
    for (int side = 0; side < 2; side++) {
        const double z = -(side ? 1.99 : 2.01) * R_MOON;
        char pos[200], look[200];
        snprintf(pos, sizeof pos, "camera.position_m=[0.25, -0.5, %.17g]", z);
        snprintf(look, sizeof look, "camera.look_at_m=[3.25, -0.5, %.17g]", -R_MOON);
        const char *far[] = {shape, pos, look, "camera.up=[0, 1, 0]", "camera.fx_px=400000", "camera.fy_px=400000"};
        nc_test_scene(yaml_sphere, far, 6, &s);
        nc_test_render(&s, 2, &f);
        memset(&st, 0, sizeof st);
        for (int y = 0; y < c->height_px; y++)
            for (int x = 0; x < c->width_px; x++) {
                struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
                double t = (-R_MOON - c->position_m.z) / d.z;
                struct nc_vec3 p = nc_v3_add(c->position_m, nc_v3_scale(d, t));
                if (fabs(p.x) > 990 || fabs(p.y) > 990)
                    continue;
                check_pixel(&st, &f, x, y, t, 0.12 / M_PI * -s.sun.direction.z * s.sun.irradiance_w_m2);
            }
        report(side ? "mesh patch, camera 0.99 R beyond its bounding sphere (anchor near the camera)"
                    : "mesh patch, camera 1.01 R beyond its bounding sphere (anchor at the body's origin)",
               &st);
        CHECK(st.worst_range < 2e-7, "far mesh: range error %.3g", st.worst_range);
        nc_frame_free(&f);
        nc_scene_free(&s);
    }

    /* D: tangent at u, off every axis; t1, t2 along the patch. */
    const struct nc_vec3 u = nc_v3_unit(nc_v3(1, 2, 3)), t1 = nc_v3_unit(nc_v3_cross(u, nc_v3(0, 0, 1))),
                         t2 = nc_v3_cross(u, t1), sun = nc_v3_unit(nc_v3_add(nc_v3_scale(u, 0.6), nc_v3_scale(t2, 0.8)));
    const char *tilted = nc_test_path("moon_patch_tilted.obj");
    fo = fopen(tilted, "w");
    for (int j = 0; j <= N; j++)
        for (int i = 0; i <= N; i++) {
            struct nc_vec3 v = nc_v3_add(nc_v3_scale(u, R_MOON), nc_v3_add(nc_v3_scale(t1, -1000 + 2000.0 * i / N),
                                                                            nc_v3_scale(t2, -1000 + 2000.0 * j / N)));
            fprintf(fo, "v %.17g %.17g %.17g\n", v.x / 1000, v.y / 1000, v.z / 1000);
        }
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            int a = j * (N + 1) + i + 1, b = a + 1, cc = a + N + 1, dd = cc + 1;
            fprintf(fo, "f %d %d %d\nf %d %d %d\n", a, b, dd, a, dd, cc);
        }
    fclose(fo);
    snprintf(shape, sizeof shape, "bodies.0.shape={type: mesh, file: '%s', unit: km}", tilted);
    for (int k = 0; k < 2; k++) {
        const double h = k ? 1.3 : 1.0;
        const struct nc_vec3 cam = nc_v3_scale(u, R_MOON + h), at = nc_v3_add(nc_v3_scale(u, R_MOON), nc_v3_scale(t1, 3));
        char pos[200], look[200], up[200], sd[200];
        snprintf(pos, sizeof pos, "camera.position_m=[%.17g, %.17g, %.17g]", cam.x, cam.y, cam.z);
        snprintf(look, sizeof look, "camera.look_at_m=[%.17g, %.17g, %.17g]", at.x, at.y, at.z);
        snprintf(up, sizeof up, "camera.up=[%.17g, %.17g, %.17g]", u.x, u.y, u.z);
        snprintf(sd, sizeof sd, "sun.direction=[%.17g, %.17g, %.17g]", sun.x, sun.y, sun.z);
        const char *tl[] = {shape, pos, look, up, sd};
        nc_test_scene(yaml_sphere, tl, 5, &s);
        nc_test_render(&s, 2, &f);
        memset(&st, 0, sizeof st);
        for (int y = 0; y < c->height_px; y++)
            for (int x = 0; x < c->width_px; x++) {
                struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
                double ud = nc_v3_dot(u, d);
                if (ud >= -0.05)
                    continue;
                double t = -h / ud; /* the plane through R u, normal u */
                struct nc_vec3 p = nc_v3_sub(nc_v3_add(cam, nc_v3_scale(d, t)), nc_v3_scale(u, R_MOON));
                if (fabs(nc_v3_dot(p, t1)) > 990 || fabs(nc_v3_dot(p, t2)) > 990)
                    continue;
                check_pixel(&st, &f, x, y, t, 0.12 / M_PI * nc_v3_dot(u, sun) * s.sun.irradiance_w_m2);
            }
        report(k ? "mesh patch off every axis, camera 1.3 m up" : "mesh patch off every axis, camera 1 m up", &st);
        nc_frame_free(&f);
        nc_scene_free(&s);
    }
    return nc_test_end();
}
