/* test_far_shadow.c - shadows of a body seen from afar through a narrow
 * field (nc_rt_far_frame): its shadow rays go relative to its own origin,
 * so a shadow ray starts 4e-6 of the body's size off the surface, not 4e-6
 * of the range (which left relief lower than that without a shadow and
 * moved every shadow edge by about 4e-6 fx / tan(e) pixels).
 *  A: a 30 m sphere 60 m over a 1 km sphere, the Sun 60 deg from the
 *     vertical, 10 m pixels seen from 2e5, 2e6 and 2e7 m (fx = range / 10 m):
 *     the small sphere's shadow (the shadowed fraction of each pixel's light,
 *     from frames with and without it) against a double-precision reference
 *     of the two spheres (8 x 8 points a pixel). Before the far frames: 0.23,
 *     2.2 and 13.9 px off, 0.93 and 0.34 of the area at 2e6 and 2e7 m.
 *  B: a mesh plate with a ridge 0.5 m high and 1 m wide, seen from 2e5 m
 *     with 0.25 m pixels (fx 8e5 px: a shadow ray started 0.8 m up), the Sun
 *     20 deg over the plate across the ridge: the ridge's shadow on the
 *     plate 0.874 m wide (0.5 / tan 20 deg less the ridge's half width; none
 *     before), and the plate lit beyond it (no false self-shadowing).
 *  C: bounce light in a valley from 2 km and from 230 km: a bounce's
 *     shadow ray keeps the camera's frame (below).
 *  D, E, F: what outside checks of the far frames found (below): grooves,
 *     rocks at zero phase, and a ball at zero phase. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "testutil.h"

static const char spheres[] = "bodies:\n"
                              "  - name: big\n"
                              "    shape: {type: sphere, radius_m: 1000}\n"
                              "    material: {model: lambert, A: 0.5}\n"
                              "  - name: small\n"
                              "    shape: {type: sphere, radius_m: 30}\n"
                              "    position_m: [0, 0, 1090]\n"
                              "    material: {model: lambert, A: 0.5}\n"
                              "sun: {direction: [0.8660254037844386, 0, 0.5]}\n"
                              "camera: {width_px: 64, height_px: 64, fx_px: 20000, fy_px: 20000,\n"
                              "         position_m: [-160, 0, 200000], look_at_m: [-160, 0, 1000], up: [1, 0, 0]}\n"
                              "render: {samples_per_pixel: 16}\n";

/* A mesh body (bodies.0.shape set by the test) under the Sun overhead,
 * seen by a 256 x 256 camera. */
static const char plate[] = "bodies:\n"
                            "  - {shape: {type: sphere, radius_m: 1}, material: {model: lambert, A: 0.5}}\n"
                            "sun: {direction: [0, 0, 1]}\n"
                            "camera: {width_px: 256, height_px: 256, fx_px: 1000, fy_px: 1000,\n"
                            "         position_m: [0, 0, 1000], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n"
                            "render: {samples_per_pixel: 4}\n";

/* Shadow rays traced in a far frame from near the side of a ball (radius
 * u[0] about that frame's origin) turned away from the Sun (the unit
 * u[2..4]): points no camera ray should reach at zero phase (test F;
 * threads = 1). (A float hit on the limb can also be kilometres off along
 * its ray; its shadow ray, not refined, starts 4e-6 of the range off.) */
static void count_inside(void *user, int kind, const struct nc_ray16 *ray, int frame)
{
    double *u = user; /* radius, count, the Sun's direction */
    for (int i = 0; kind == 1 && frame >= 0 && i < NC_PACKET; i++)
        if (ray->valid[i] && ray->ox[i] * u[2] + ray->oy[i] * u[3] + ray->oz[i] * u[4] < -0.1 * u[0] &&
            hypot(hypot(ray->ox[i], ray->oy[i]), ray->oz[i]) < 2 * u[0])
            u[1]++;
}

/* An icosphere of radius r: an icosahedron's faces split in 4, n times,
 * the new vertices pushed out to the sphere, into an OBJ file. */
static void icosphere(const char *path, double r, int n)
{
    const double t = (1 + sqrt(5)) / 2;
    static double v[2562][3];
    static int f[2][5120][3];
    const double v0[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const int f0[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                           {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                           {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    int nv = 12, nf = 20, cur = 0;
    for (int i = 0; i < 12; i++) {
        const double l = sqrt(v0[i][0] * v0[i][0] + v0[i][1] * v0[i][1] + v0[i][2] * v0[i][2]);
        for (int c = 0; c < 3; c++)
            v[i][c] = v0[i][c] / l;
    }
    memcpy(f[0], f0, sizeof f0);
    for (int k = 0; k < n; k++, cur ^= 1) {
        int m = 0;
        for (int q = 0; q < nf; q++) {
            int mid[3];
            for (int e = 0; e < 3; e++) { /* each edge's midpoint, shared with the neighbour: looked for */
                const int a = f[cur][q][e], b = f[cur][q][(e + 1) % 3];
                double p[3];
                for (int c = 0; c < 3; c++)
                    p[c] = (v[a][c] + v[b][c]) / 2;
                const double l = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                for (int c = 0; c < 3; c++)
                    p[c] /= l;
                int w = 12;
                while (w < nv && !(v[w][0] == p[0] && v[w][1] == p[1] && v[w][2] == p[2]))
                    w++;
                if (w == nv)
                    memcpy(v[nv++], p, sizeof p);
                mid[e] = w;
            }
            const int *g = f[cur][q];
            const int nf4[4][3] = {{g[0], mid[0], mid[2]}, {g[1], mid[1], mid[0]}, {g[2], mid[2], mid[1]},
                                   {mid[0], mid[1], mid[2]}};
            memcpy(f[cur ^ 1][m], nf4, sizeof nf4);
            m += 4;
        }
        nf = m;
    }
    FILE *fo = fopen(path, "w");
    for (int i = 0; i < nv; i++)
        fprintf(fo, "v %.17g %.17g %.17g\n", r * v[i][0], r * v[i][1], r * v[i][2]);
    for (int q = 0; q < nf; q++)
        fprintf(fo, "f %d %d %d\n", f[cur][q][0] + 1, f[cur][q][1] + 1, f[cur][q][2] + 1);
    fclose(fo);
}

/* The nearest t > 0 of ray o + t d (d unit) on the sphere (c, r), or
 * INFINITY: from the line's point nearest the centre (no cancellation for
 * an origin 2e7 m away). */
static double sphere_hit(struct nc_vec3 o, struct nc_vec3 d, struct nc_vec3 c, double r)
{
    const struct nc_vec3 oc = nc_v3_sub(o, c);
    const double b = nc_v3_dot(oc, d);
    const struct nc_vec3 l = nc_v3_sub(oc, nc_v3_scale(d, b));
    const double h2 = r * r - nc_v3_dot(l, l);
    if (!(h2 >= 0))
        return INFINITY;
    const double t0 = -b - sqrt(h2), t1 = -b + sqrt(h2);
    return t0 > 0 ? t0 : t1 > 0 ? t1 : INFINITY;
}

/* The two spheres' frame in double precision, 8 x 8 points a pixel: each
 * point's Lambert radiance (1/sr of the irradiance) where a camera ray
 * meets a sphere lit by the Sun unblocked; small: whether the small sphere
 * is there. */
static void reference(const struct nc_scene *s, int small, double *L)
{
    const struct nc_vec3 cb = nc_v3(0, 0, 0), cs = nc_v3(0, 0, 1090), sd = nc_v3_unit(s->sun.direction);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            double sum = 0;
            for (int k = 0; k < 64; k++) {
                const double u = x - 0.4375 + 0.125 * (k % 8), v = y - 0.4375 + 0.125 * (k / 8);
                const struct nc_vec3 d =
                    nc_v3_unit(nc_quat_rotate(s->camera.attitude_q, nc_camera_dir(&s->camera, u, v)));
                const double tb = sphere_hit(s->camera.position_m, d, cb, 1000);
                const double ts = small ? sphere_hit(s->camera.position_m, d, cs, 30) : INFINITY;
                if (!(fmin(tb, ts) < INFINITY))
                    continue;
                const struct nc_vec3 p = nc_v3_add(s->camera.position_m, nc_v3_scale(d, fmin(tb, ts)));
                const struct nc_vec3 n = nc_v3_unit(nc_v3_sub(p, ts < tb ? cs : cb));
                const double mu0 = nc_v3_dot(n, sd);
                if (mu0 > 0 && !(ts >= tb && small && sphere_hit(p, sd, cs, 30) < INFINITY))
                    sum += 0.5 / M_PI * mu0;
            }
            L[y * 64 + x] = sum / 64;
        }
}

/* The shadowed fraction's sum (px) and centroid of "with" against "without". */
static void shadow_of(const double *with, const double *without, double *area, double *cx, double *cy)
{
    double sum = 0, sx = 0, sy = 0;
    for (int i = 0; i < 64 * 64; i++) {
        const double f = without[i] > 0 && with[i] < without[i] ? (without[i] - with[i]) / without[i] : 0;
        sum += f, sx += f * (i % 64), sy += f * (i / 64);
    }
    *area = sum, *cx = sx / sum, *cy = sy / sum;
}

/* The small sphere's shadow at range D in the render (area: px, the
 * shadowed fraction summed over the frames with and without the small
 * sphere; its centroid) and in the double-precision reference (ref: area,
 * x, y). */
static void shadow_at(double D, double *area, double *cx, double *cy, double *ref)
{
    char fx[64], fy[64], pos[96];
    snprintf(fx, sizeof fx, "camera.fx_px=%.17g", D / 10);
    snprintf(fy, sizeof fy, "camera.fy_px=%.17g", D / 10);
    snprintf(pos, sizeof pos, "camera.position_m=[-160, 0, %.17g]", D);
    const char *with[] = {fx, fy, pos}, *without[] = {fx, fy, pos, "bodies.1.position_m=[0, 1e6, 0]"};
    struct nc_scene s;
    struct nc_frame a, b;
    nc_test_scene(spheres, without, 4, &s);
    nc_test_render(&s, 2, &b);
    nc_scene_free(&s);
    nc_test_scene(spheres, with, 3, &s);
    nc_test_render(&s, 2, &a);
    static double la[64 * 64], lb[64 * 64];
    for (int i = 0; i < 64 * 64; i++)
        la[i] = a.radiance[i], lb[i] = b.radiance[i];
    shadow_of(la, lb, area, cx, cy);
    reference(&s, 1, la);
    reference(&s, 0, lb);
    shadow_of(la, lb, &ref[0], &ref[1], &ref[2]);
    nc_frame_free(&a);
    nc_frame_free(&b);
    nc_scene_free(&s);
}

int main(void)
{
    /* A */
    for (int k = 0; k < 3; k++) {
        const double D = k == 0 ? 2e5 : k == 1 ? 2e6 : 2e7;
        double a, x, y, ref[3];
        shadow_at(D, &a, &x, &y, ref);
        printf("%.0e m: shadow %.3f px, centroid (%.3f, %.3f); double-precision reference %.3f px at (%.3f, %.3f)\n",
               D, a, x, y, ref[0], ref[1], ref[2]);
        CHECK(fabs(a / ref[0] - 1) < 0.02 && hypot(x - ref[1], y - ref[2]) < 0.1,
              "%.0e m: %.4f of the area, %.3f px off", D, a / ref[0], hypot(x - ref[1], y - ref[2]));
    }

    /* B: the plate z = 0, 40 m square, the ridge along y: x = -0.5, 0, 0.5
     * at heights 0, 0.5, 0 (two rows of vertices, y = -20 and 20) */
    const char *obj = nc_test_path("ridge.obj");
    FILE *fo = fopen(obj, "w");
    const double xs[5] = {-20, -0.5, 0, 0.5, 20}, zs[5] = {0, 0, 0.5, 0, 0};
    for (int r = 0; r < 2; r++)
        for (int i = 0; i < 5; i++)
            fprintf(fo, "v %.17g %.17g %.17g\n", xs[i], r ? 20.0 : -20.0, zs[i]);
    for (int i = 1; i <= 4; i++) /* up: +z */
        fprintf(fo, "f %d %d %d\nf %d %d %d\n", i, i + 1, i + 6, i, i + 6, i + 5);
    fclose(fo);
    char shape[1200];
    snprintf(shape, sizeof shape, "bodies.0.shape={type: mesh, file: '%s', unit: m}", obj);
    const double e = 20 * M_PI / 180;
    char sun[128];
    snprintf(sun, sizeof sun, "sun.direction=[%.17g, 0, %.17g]", -cos(e), sin(e));
    const char *sets[] = {shape, sun, "bodies.1.position_m=[0, 1e7, 0]", "camera.width_px=128",
                          "camera.height_px=128", "camera.fx_px=8e5", "camera.fy_px=8e5",
                          "camera.position_m=[0, 0, 2e5]", "camera.look_at_m=[0, 0, 0]", "camera.up=[0, 1, 0]"};
    struct nc_scene s;
    struct nc_frame f;
    nc_test_scene(spheres, sets, 10, &s);
    nc_test_render(&s, 2, &f);
    /* pixel columns 0.25 m wide, edges on multiples of 0.25 m at z = 0 (a
     * pixel's ground x from the camera's own projection of two points on the
     * ridge's foot line); the shadowed fraction of the plate's light, rows
     * |y| < 12 m, in whole columns from the ridge's foot to 3 m */
    const double lit = 0.5 / M_PI * s.sun.irradiance_w_m2 * sin(e), want = 0.5 / tan(e) - 0.5;
    double at[2];
    for (int k = 0; k < 2; k++) {
        const struct nc_vec3 d =
            nc_quat_rotate(nc_quat_conj(s.camera.attitude_q), nc_v3_sub(nc_v3(k, 0, 0), s.camera.position_m));
        double yd;
        nc_camera_project(&s.camera, d, &at[k], &yd);
    }
    double cols = 0, beyond = 0;
    int nb = 0;
    for (int y = 16; y < 112; y++)
        for (int x = 0; x < 128; x++) {
            const double gx = (x - at[0]) / (at[1] - at[0]), l = f.radiance[y * 128 + x];
            if (gx > 0.6 && gx < 2.9)
                cols += 1 - l / lit;
            if (gx > 1.5 && gx < 3)
                beyond += l / lit, nb++;
        }
    const double rows = 96;
    printf("the ridge's shadow on the plate: %.4f m wide (%.4f expected); the plate beyond it at %.6f of full light\n",
           0.25 * cols / rows, want, beyond / nb);
    CHECK(fabs(0.25 * cols / rows - want) < 0.02, "the ridge's shadow %.4f m wide, %.4f expected",
          0.25 * cols / rows, want);
    CHECK(nb > 0 && fabs(beyond / nb - 1) < 1e-4, "the plate beyond the shadow at %.6f of full light", beyond / nb);
    nc_frame_free(&f);
    nc_scene_free(&s);

    /* C: bounce light in a valley (faces 30 deg up, 1 m facets), 0.25 m
     * pixels from 2 km and 230000.7 m (where the float points of bounces
     * fell under the surface; at 2e5 m above it): a bounce's point comes from a ray traced
     * from a float origin relative to the camera, known to 6e-8 of its
     * distance from the camera, so its shadow ray keeps the camera's frame
     * (in the far frame it started 1e-4 m off a point mm under the surface:
     * every bounce lit point shadowed itself, the bounce light gone) */
    const char *valley = nc_test_path("valley.obj");
    fo = fopen(valley, "w");
    for (int r = 0; r <= 40; r++)
        for (int i = 0; i <= 40; i++)
            fprintf(fo, "v %d %d %.17g\n", i - 20, r - 20, fabs(i - 20.0) * tan(M_PI / 6));
    for (int r = 0; r < 40; r++)
        for (int i = 1; i <= 40; i++) {
            const int a = r * 41 + i;
            fprintf(fo, "f %d %d %d\nf %d %d %d\n", a, a + 1, a + 42, a, a + 42, a + 41);
        }
    fclose(fo);
    snprintf(shape, sizeof shape, "bodies.0.shape={type: mesh, file: '%s', unit: m}", valley);
    double bounce[2];
    for (int k = 0; k < 2; k++) {
        char pos[96], fx[64], fy[64];
        const double D = k ? 230000.7 : 2e3;
        snprintf(pos, sizeof pos, "camera.position_m=[0, 0, %.17g]", D);
        snprintf(fx, sizeof fx, "camera.fx_px=%.17g", D / 0.25);
        snprintf(fy, sizeof fy, "camera.fy_px=%.17g", D / 0.25);
        double sum[2] = {0, 0};
        for (int b = 0; b < 2; b++) {
            const char *vs[] = {shape,  "sun.direction=[0.3, 0.1, 1]", "bodies.1.position_m=[0, 1e7, 0]",
                                pos,    "camera.look_at_m=[0, 0, 0]",  "camera.up=[0, 1, 0]",
                                fx,     fy,
                                "render.samples_per_pixel=4", b ? "render.bounces=1" : "render.bounces=0"};
            nc_test_scene(spheres, vs, 10, &s);
            nc_test_render(&s, 2, &f);
            for (int i = 0; i < 64 * 64; i++)
                sum[b] += f.radiance[i];
            nc_frame_free(&f);
            nc_scene_free(&s);
        }
        bounce[k] = (sum[1] - sum[0]) / sum[0];
    }
    printf("bounce light in the valley: %.4f of the direct from 2e3 m, %.4f from 230000.7 m\n", bounce[0], bounce[1]);
    CHECK(bounce[0] > 0.03 && bounce[1] > 0.9 * bounce[0], "bounce light %.4f from 2e3 m, %.4f from 230000.7 m",
          bounce[0], bounce[1]);

    /* D: V grooves (faces 15 deg off the plate, 10 m facets; the body alone,
     * its camera rays through the bins: with the analytic sphere of A beside
     * it they go through Embree, whose hits did not show this) under the
     * Sun overhead: every face lit alike, no shadow possible. Seen 30 deg off
     * the vertical with 2.5 m pixels from 2e6 and 2e7 m, a float hit on one
     * face of a groove whose exact ray meets the next, refined onto the
     * first face's plane, lay under the second past the groove's concave
     * edge and shadowed itself (an outside check: 4 and 371 dark pixels);
     * refined points are taken only inside their triangle. */
    const char *grooves = nc_test_path("grooves.obj");
    fo = fopen(grooves, "w");
    for (int i = 0; i <= 60; i++) /* vertex 61 i + r + 1 at x = 10 i - 300, y = 10 r - 300 */
        for (int r = 0; r <= 60; r++)
            fprintf(fo, "v %d %d %.17g\n", 10 * i - 300, 10 * r - 300, (i % 2) * 10 * tan(M_PI / 12));
    for (int i = 0; i < 60; i++)
        for (int r = 0; r < 60; r++) {
            const int a = 61 * i + r + 1, b = a + 61;
            fprintf(fo, "f %d %d %d\nf %d %d %d\n", a, b, b + 1, a, b + 1, a + 1);
        }
    fclose(fo);
    snprintf(shape, sizeof shape, "bodies.0.shape={type: mesh, file: '%s', unit: m}", grooves);
    for (int k = 0; k < 2; k++) {
        const double D = k ? 2e7 : 2e6;
        char pos[128], fx[64], fy[64];
        snprintf(pos, sizeof pos, "camera.position_m=[0, %.17g, %.17g]", -D / 2, D * sqrt(0.75));
        snprintf(fx, sizeof fx, "camera.fx_px=%.17g", D / 2.5);
        snprintf(fy, sizeof fy, "camera.fy_px=%.17g", D / 2.5);
        const char *gs[] = {shape, pos, fx, fy};
        nc_test_scene(plate, gs, 4, &s);
        nc_test_render(&s, 2, &f);
        const double L = 0.5 / M_PI * s.sun.irradiance_w_m2 * cos(M_PI / 12);
        int dark = 0; /* the middle 128 x 128 pixels, on the plate */
        for (int y = 64; y < 192; y++)
            for (int x = 64; x < 192; x++)
                dark += f.radiance[256 * y + x] < 0.99 * L;
        printf("grooves under the Sun overhead, from %.0e m: %d of 16384 pixels darker than their faces' light\n", D,
               dark);
        CHECK(dark == 0, "grooves from %.0e m: %d dark pixels", D, dark);
        nc_frame_free(&f);
        nc_scene_free(&s);
    }

    /* E: rocks at zero phase, 5 m pixels from 2e7 m: the camera's frame
     * places the body and each rock tile by float translations of their own,
     * so it sees the rocks some 2.4e-7 of the range (0.96 px here) off the
     * ground they stand on; in the far frame a ground point seen beside a
     * rock lay behind it, and every shadow ray along the line of sight met
     * it (a black rim around every rock, 12 % of the body in an outside
     * check). Such a body keeps the camera's frame. */
    const char *rocks[] = {"bodies.0.boulders={preset: bennu}", "render.boulder_min_px=0",
                           "sun.direction=[0, -1, 0]", "camera.position_m=[0, -2e7, 0]", "camera.focal_length_m=4.0",
                           "camera.pixel_pitch_m=1e-6", "camera.width_px=128", "camera.height_px=128",
                           "render.samples_per_pixel=1"};
    nc_test_scene(nc_test_asteroid_yaml, rocks, 9, &s);
    nc_test_render(&s, 2, &f);
    int body = 0, black = 0;
    for (int i = 0; i < 128 * 128; i++) {
        body += f.range_m[i] > 0;
        black += f.range_m[i] > 0 && !(f.radiance[i] > 0);
    }
    printf("rocks at zero phase from 2e7 m: %d of %d body pixels black\n", black, body);
    CHECK(body > 1000 && black < body / 100, "rocks at zero phase: %d of %d body pixels black", black, body);
    nc_frame_free(&f);
    nc_scene_free(&s);

    /* F: a 30 m ball of 5 120 facets at zero phase from 2e7 m (fx 1.6e7 px):
     * a float camera ray now and then slips through its near side and meets
     * the far wall's inner side; traced in the far frame from there, its
     * shadow ray was shut in by the body (a black pixel on a convex body at
     * zero phase: 11 in a review's 512 x 512 frame). Such points keep the
     * camera's frame: no shadow ray in a far frame starts on the far side. */
    const char *ballobj = nc_test_path("ball.obj");
    icosphere(ballobj, 30, 4);
    snprintf(shape, sizeof shape, "bodies.0.shape={type: mesh, file: '%s', unit: m}", ballobj);
    const char *ball[] = {shape,
                          "bodies.1={shape: {type: sphere, radius_m: 1000}, position_m: [0, 1e7, 0], "
                          "material: {model: lambert, A: 0.5}}",
                          "bodies.0.position_m=[770.7463914933, 0, 770.7463914933]",
                          "sun.direction=[0.7071067811865476, 0, 0.7071067811865476]",
                          "camera.position_m=[14142136.5, 0, 14142135.5]",
                          "camera.look_at_m=[770.7463914933, 0, 770.7463914933]", "camera.up=[0, 1, 0]",
                          "camera.fx_px=1.6e7", "camera.fy_px=1.6e7", "camera.width_px=512", "camera.height_px=512",
                          "render.samples_per_pixel=1"};
    nc_test_scene(plate, ball, 12, &s);
    struct nc_renderer rr;
    double inside[5] = {30, 0, M_SQRT1_2, 0, M_SQRT1_2};
    CHECK(nc_renderer_init(&rr, &s, 1) == 0, "renderer: %s", nc_errmsg());
    rr.ray_hook = count_inside;
    rr.ray_hook_user = inside;
    nc_frame_alloc(&f, 512, 512);
    CHECK(nc_render_frame(&rr, &s, &f) == 0, "render: %s", nc_errmsg());
    printf("a ball at zero phase from 2e7 m: %.0f shadow rays in its far frame from its far side\n", inside[1]);
    CHECK(inside[1] == 0, "%.0f shadow rays in the far frame start on the ball's far side", inside[1]);
    nc_frame_free(&f);
    nc_renderer_free(&rr);
    nc_scene_free(&s);
    return nc_test_end();
}
