/* test_indirect.c - indirect light (render.bounces) against exact results.
 *  1. The bounce mixture (render/bounce.c): samples and density agree: the
 *     importance-sampled integrals of known functions over the hemisphere
 *     and over a cone (one of 3 deg, one of 1e-4 rad) come out right.
 *  2. A convex body has no indirect light: a Lambert sphere's frame with
 *     bounces is the frame without.
 *  3. A Lambert spherical bowl (a hemisphere open at the top) lit at 40 deg
 *     elevation. Two points inside a sphere see each other with the same
 *     view factor dA / (4 pi R^2) wherever they are, so the scattered
 *     irradiance is the same everywhere in the bowl and, with every order
 *     of scattering, E_s = A P / (4 pi R^2 (1 - A f)), P the sunlight
 *     entering the opening and f the bowl's fraction of the sphere
 *     (Buhl, Welch and Rea 1968; Ingersoll, Svitek and Murray 1992). The
 *     shadowed floor's radiance is A E_s / pi, the lit wall's A (J mu0 +
 *     E_s) / pi.
 *  4. Light between bodies: the night side of a sphere lit by a Lambert
 *     moon at 45 deg phase. The irradiance is the integral over the moon's
 *     lit surface seen from the point, L cos(theta_point) cos(theta_moon)
 *     dA / s^2 (a 400 x 800 midpoint sum at the centre of view); across the
 *     view it varies as the far-field E = J A (2/3) (R/d)^2 (sin a +
 *     (pi - a) cos a) / pi times the cosine at the point, which alone is 2 %
 *     low at R/d = 0.04 (the moon's near side is closer than its centre).
 *  5. Determinism: bit-identical on 1 and 2 threads. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "render/bounce.h"
#include "testutil.h"

/* ---- 1. the mixture ---------------------------------------------------- */

static void check_mixture(double sin_cone, const char *what)
{
    struct nc_vec3 n = nc_v3_unit(nc_v3(0.2, -0.3, 1.0));
    /* the other body 60 deg from the normal */
    struct nc_vec3 axis = nc_v3_unit(nc_v3_add(nc_v3_scale(n, 0.5), nc_v3_scale(nc_v3_unit(nc_v3(1, 0, 0.2)), 0.866)));
    struct nc_vec3 centre[2] = {nc_v3(0, 0, 0), nc_v3_scale(axis, 1000.0)};
    double radius[2] = {1, 1000.0 * sin_cone};
    struct nc_bounce_mix m;
    nc_bounce_init(&m, n, centre, radius, 2, 0);
    CHECK(m.ncone == 1, "%s: %d cones", what, m.ncone);
    /* E[g / pdf] over the mixture's samples = the integral of g */
    const int N = 400000;
    double hemi = 0, cosw = 0, cone = 0, cone2 = 0;
    uint64_t st = 12345;
    double omc = 1 - sqrt(1 - sin_cone * sin_cone);
    if (sin_cone < 1e-3)
        omc = sin_cone * sin_cone / 2;
    for (int k = 0; k < N; k++) {
        struct nc_vec3 w = nc_bounce_sample(&m, nc_rng_uniform(&st), nc_rng_uniform(&st), nc_rng_uniform(&st));
        double p = nc_bounce_pdf(&m, w), mu = nc_v3_dot(n, w);
        if (!(p > 0 && fabs(nc_v3_norm(w) - 1) < 1e-12)) {
            CHECK(0, "%s: sample %d: pdf %g, |w| - 1 = %g", what, k, p, nc_v3_norm(w) - 1);
            return;
        }
        if (mu > 0) {
            hemi += 1 / p;
            cosw += mu / p;
        }
        struct nc_vec3 x = nc_v3_cross(axis, w);
        if (nc_v3_dot(axis, w) > 0 && nc_v3_dot(x, x) <= sin_cone * sin_cone * (1 - 1e-9)) {
            cone += 1 / p;
            cone2 += 1 / (p * p);
        }
    }
    hemi /= N;
    cosw /= N;
    cone /= N;
    double cone_sd = sqrt(cone2 / N - cone * cone) / sqrt(N);
    printf("%s: hemisphere %.5f (2 pi = %.5f), cosine %.5f (pi), cone %.6g +- %.2g (%.6g)\n", what, hemi, 2 * M_PI,
           cosw, cone, cone_sd, 2 * M_PI * omc);
    CHECK(fabs(hemi / (2 * M_PI) - 1) < 0.01, "%s: hemisphere %g", what, hemi);
    CHECK(fabs(cosw / M_PI - 1) < 0.01, "%s: cosine %g", what, cosw);
    CHECK(fabs(cone / (2 * M_PI * omc) - 1) < 0.01 && fabs(cone - 2 * M_PI * omc) < 4 * cone_sd + 1e-12 * omc,
          "%s: cone %g for %g", what, cone, 2 * M_PI * omc);
}

/* ---- 2. a convex body ----------------------------------------------------- */

static const char sphere_yaml[] =
    "bodies:\n"
    "  - shape: {type: sphere, radius_m: 1000}\n"
    "    material: {model: lambert, A: 0.9}\n"
    "sun: {direction: [1, 0.3, -0.5]}\n"
    "camera: {width_px: 96, height_px: 96, fx_px: 120, fy_px: 120, position_m: [0, 0, -4000], look_at_m: [0, 0, 0], up: [0, 1, 0]}\n"
    "render: {samples_per_pixel: 4}\n";

static void check_convex(void)
{
    const char *with[] = {"render.bounces=4"};
    struct nc_scene a, b;
    nc_test_scene(sphere_yaml, NULL, 0, &a);
    nc_test_scene(sphere_yaml, with, 1, &b);
    struct nc_frame fa, fb;
    nc_test_render(&a, 2, &fa);
    nc_test_render(&b, 2, &fb);
    size_t n = (size_t)fa.width_px * (size_t)fa.height_px, diff = 0;
    for (size_t o = 0; o < n; o++)
        diff += fa.radiance[o] != fb.radiance[o] || fa.iof[o] != fb.iof[o];
    CHECK(diff == 0, "convex sphere: %zu pixels changed by indirect light", diff);
    nc_frame_free(&fa);
    nc_frame_free(&fb);
    nc_scene_free(&a);
    nc_scene_free(&b);
}

/* ---- 3. the spherical bowl --------------------------------------------- */

#define BOWL_R 100.0
#define BOWL_ELEV_DEG 40.0

/* The lower hemisphere of a sphere of radius BOWL_R about the origin, open
 * at z = 0, as an OBJ of nt x np quads (two triangles each), wound outward. */
static void write_bowl(const char *path, int nt, int np)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(2);
    }
    fprintf(f, "v 0 0 %.17g\n", -BOWL_R);
    for (int i = 1; i <= nt; i++) {
        double th = 0.5 * M_PI * i / nt; /* from the bottom */
        for (int k = 0; k < np; k++) {
            double ph = 2 * M_PI * k / np;
            fprintf(f, "v %.17g %.17g %.17g\n", BOWL_R * sin(th) * cos(ph), BOWL_R * sin(th) * sin(ph), -BOWL_R * cos(th));
        }
    }
    for (int k = 0; k < np; k++) /* the bottom fan */
        fprintf(f, "f 1 %d %d\n", 2 + (k + 1) % np, 2 + k);
    for (int i = 1; i < nt; i++)
        for (int k = 0; k < np; k++) {
            int a = 2 + (i - 1) * np + k, b = 2 + (i - 1) * np + (k + 1) % np, c = a + np, d = b + np;
            fprintf(f, "f %d %d %d\nf %d %d %d\n", a, b, d, a, d, c);
        }
    fclose(f);
}

static void check_bowl(void)
{
    const char *obj = nc_test_path("bowl.obj");
    write_bowl(obj, 96, 384);
    const double el = BOWL_ELEV_DEG * M_PI / 180, A = 0.5;
    char yaml[1024];
    snprintf(yaml, sizeof yaml,
             "bodies:\n"
             "  - shape: {type: mesh, file: %s, unit: m, normals: smooth}\n"
             "    material: {model: lambert, A: %g}\n"
             "sun: {direction: [%.17g, 0, %.17g]}\n"
             "camera: {width_px: 160, height_px: 160, fx_px: 1300, fy_px: 1300, position_m: [0, 0, 1500],"
             " look_at_m: [0, 0, 0], up: [0, 1, 0]}\n"
             "render: {samples_per_pixel: 16, bounces: 8}\n",
             obj, A, cos(el), sin(el));
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    struct nc_frame f;
    nc_test_render(&s, 2, &f);
    const double J = s.sun.irradiance_w_m2, f_sphere = 0.5;
    const double P = J * sin(el) * M_PI * BOWL_R * BOWL_R;
    const double Es = A * P / (4 * M_PI * BOWL_R * BOWL_R * (1 - A * f_sphere));
    const struct nc_camera *c = &s.camera;
    const struct nc_vec3 sun = nc_v3(cos(el), 0, sin(el));
    double shade_sum = 0, lit_sum = 0, iof_err = 0;
    int nshade = 0, nlit = 0;
    for (int y = 0; y < c->height_px; y++)
        for (int x = 0; x < c->width_px; x++) {
            size_t o = (size_t)y * (size_t)c->width_px + (size_t)x;
            /* the pixel centre's point on the sphere (the far side from the camera) */
            struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
            struct nc_vec3 o0 = c->position_m;
            double b = nc_v3_dot(o0, d), cc = nc_v3_dot(o0, o0) - BOWL_R * BOWL_R, disc = b * b - cc;
            if (disc <= 0)
                continue;
            double t = -b + sqrt(disc);
            struct nc_vec3 p = nc_v3_add(o0, nc_v3_scale(d, t));
            if (p.z > -0.3 * BOWL_R || f.coverage[o] < 1) /* near the rim: walls seen at grazing */
                continue;
            struct nc_vec3 nin = nc_v3_scale(p, -1.0 / BOWL_R);
            double mu0 = nc_v3_dot(nin, sun);
            /* in the shadow when the segment toward the Sun meets the sphere again below z = 0 */
            double bs = nc_v3_dot(p, sun), t2 = -2 * bs; /* the other root of |p + t s| = R */
            double zexit = p.z + t2 * sun.z;
            int shadow = zexit < 0;
            /* stay 3 degrees away from the shadow's edge */
            double zmargin = 2 * BOWL_R * sin(3 * M_PI / 180);
            iof_err = fmax(iof_err, fabs(f.iof[o] - M_PI * f.radiance[o] / J) / (M_PI * f.radiance[o] / J + 1e-30));
            if (shadow && zexit < -zmargin) {
                shade_sum += f.radiance[o];
                nshade++;
            } else if (!shadow && zexit > zmargin && mu0 > 0.2) {
                lit_sum += f.radiance[o] / (A * (J * mu0 + Es) / M_PI);
                nlit++;
            }
        }
    double shade = shade_sum / nshade, lit = lit_sum / nlit, expect = A * Es / M_PI;
    printf("bowl: shadowed floor %.5g W/m^2/sr for %.5g (%d px, ratio %.4f); lit wall ratio %.4f (%d px)\n", shade,
           expect, nshade, shade / expect, lit, nlit);
    CHECK(nshade > 2000 && nlit > 4000, "bowl: %d shadowed and %d lit pixels", nshade, nlit);
    CHECK(fabs(shade / expect - 1) < 0.01, "bowl: shadowed floor %g for %g", shade, expect);
    CHECK(fabs(lit - 1) < 0.005, "bowl: lit wall ratio %g", lit);
    CHECK(iof_err < 1e-5, "bowl: I/F differs from pi L / J by %g", iof_err);
    /* without indirect light the shadow is black */
    const char *none[] = {"render.bounces=0"};
    struct nc_scene s0;
    nc_test_scene(yaml, none, 1, &s0);
    struct nc_frame f0;
    nc_test_render(&s0, 2, &f0);
    double dark = 0;
    size_t npx = (size_t)c->width_px * (size_t)c->height_px;
    for (size_t o = 0; o < npx; o++)
        dark += f0.radiance[o] < f.radiance[o] * (1 - 1e-6) ? 1 : 0;
    CHECK(dark > nshade, "bowl: only %g pixels brighter with indirect light", dark);
    nc_frame_free(&f);
    nc_frame_free(&f0);
    nc_scene_free(&s);
    nc_scene_free(&s0);
}

/* ---- 4. a moon lights the night side ------------------------------------ */

/* Irradiance at q (unit normal nq) from a Lambert sphere of albedo A and
 * radius R at m, lit by the Sun along +x with J: the integral over its
 * surface, midpoint rule in (theta, phi), per unit J. */
static double moon_irradiance(struct nc_vec3 q, struct nc_vec3 nq, struct nc_vec3 m, double R, double A, int N)
{
    double E = 0;
    for (int i = 0; i < N; i++) {
        double th = (i + 0.5) * M_PI / N;
        for (int k = 0; k < 2 * N; k++) {
            double ph = (k + 0.5) * M_PI / N;
            struct nc_vec3 n = nc_v3(sin(th) * cos(ph), sin(th) * sin(ph), cos(th));
            struct nc_vec3 v = nc_v3_sub(q, nc_v3_add(m, nc_v3_scale(n, R)));
            double s = nc_v3_norm(v), cx = nc_v3_dot(n, v) / s, cq = -nc_v3_dot(nq, v) / s;
            if (n.x > 0 && cx > 0 && cq > 0)
                E += A * n.x / M_PI * cx * cq / (s * s) * R * R * sin(th) * (M_PI / N) * (M_PI / N);
        }
    }
    return E;
}

/* The far-field approximation of the same, per unit J. */
static double moon_far(struct nc_vec3 q, struct nc_vec3 nq, struct nc_vec3 m, double R, double A)
{
    struct nc_vec3 to = nc_v3_sub(m, q);
    double dist = nc_v3_norm(to), cos_t = nc_v3_dot(nq, to) / dist;
    double a = acos(-to.x / dist); /* phase at the moon: Sun (+x) and the way back to q */
    return A * (2.0 / 3) * (R / dist) * (R / dist) * (sin(a) + (M_PI - a) * cos(a)) / M_PI * cos_t;
}

static void check_moonlight(void)
{
    const double Rp = 1000, Rm = 300, D = 8000, Am = 0.9, Ap = 0.3;
    const struct nc_vec3 mdir = nc_v3_unit(nc_v3(-1, 1, 0)), m = nc_v3_scale(mdir, D);
    const struct nc_vec3 P = nc_v3_scale(mdir, Rp), cam = nc_v3_add(P, nc_v3_scale(mdir, 400));
    char yaml[1024];
    snprintf(yaml, sizeof yaml,
             "bodies:\n"
             "  - shape: {type: sphere, radius_m: %g}\n"
             "    material: {model: lambert, A: %g}\n"
             "  - shape: {type: sphere, radius_m: %g}\n"
             "    material: {model: lambert, A: %g}\n"
             "    position_m: [%.17g, %.17g, 0]\n"
             "sun: {direction: [1, 0, 0]}\n"
             "camera: {width_px: 64, height_px: 64, fx_px: 200, fy_px: 200, position_m: [%.17g, %.17g, 0],"
             " look_at_m: [%.17g, %.17g, 0], up: [0, 0, 1]}\n"
             "render: {samples_per_pixel: 16, bounces: 1}\n",
             Rp, Ap, Rm, Am, m.x, m.y, cam.x, cam.y, P.x, P.y);
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    struct nc_frame f;
    nc_test_render(&s, 2, &f);
    const struct nc_camera *c = &s.camera;
    const double J = s.sun.irradiance_w_m2;
    const double near = moon_irradiance(P, mdir, m, Rm, Am, 400) / moon_far(P, mdir, m, Rm, Am);
    double sum = 0;
    int npx = 0;
    for (int y = 0; y < c->height_px; y++)
        for (int x = 0; x < c->width_px; x++) {
            struct nc_vec3 d = nc_v3_unit(nc_quat_rotate(c->attitude_q, nc_camera_dir(c, x, y)));
            struct nc_vec3 o0 = c->position_m;
            double b = nc_v3_dot(o0, d), cc = nc_v3_dot(o0, o0) - Rp * Rp, disc = b * b - cc;
            if (disc <= 0)
                continue;
            struct nc_vec3 q = nc_v3_add(o0, nc_v3_scale(d, -b - sqrt(disc)));
            double E = J * near * moon_far(q, nc_v3_scale(q, 1 / Rp), m, Rm, Am);
            sum += f.radiance[(size_t)y * (size_t)c->width_px + (size_t)x] / (Ap * E / M_PI);
            npx++;
        }
    printf("moonlight: night side / exact %.4f over %d px (exact / far-field %.4f)\n", sum / npx, npx, near);
    CHECK(npx == c->width_px * c->height_px, "moonlight: %d pixels on the planet", npx);
    CHECK(fabs(sum / npx - 1) < 0.01, "moonlight: ratio %g", sum / npx);
    nc_frame_free(&f);
    nc_scene_free(&s);
}

/* ---- 5. determinism ----------------------------------------------------- */

static void check_threads(void)
{
    const char *sets[] = {"render.bounces=3", "camera.position_m=[0, 300, -2600]", "sun.direction=[0.3, 1, -0.2]"};
    struct nc_scene s;
    nc_test_scene(nc_test_asteroid_yaml, sets, 3, &s);
    struct nc_frame a, b;
    nc_test_render(&s, 1, &a);
    nc_test_render(&s, 2, &b);
    size_t n = (size_t)a.width_px * (size_t)a.height_px;
    CHECK(!memcmp(a.radiance, b.radiance, n * sizeof(float)) && !memcmp(a.iof, b.iof, n * sizeof(float)),
          "indirect light differs between 1 and 2 threads");
    size_t bad = 0;
    for (size_t o = 0; o < n; o++)
        bad += !isfinite(a.radiance[o]) || a.radiance[o] < 0;
    CHECK(bad == 0, "%zu pixels not finite or negative", bad);
    nc_frame_free(&a);
    nc_frame_free(&b);
    nc_scene_free(&s);
}

int main(void)
{
    check_mixture(sin(3 * M_PI / 180), "3 deg cone");
    check_mixture(1e-4, "1e-4 rad cone");
    check_convex();
    check_bowl();
    check_moonlight();
    check_threads();
    return nc_test_end();
}
