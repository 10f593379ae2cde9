/* test_stability.c - the stability suite (docs/validation.md): the cases
 * where rendering methods classically fail, each with its expected
 * behaviour asserted. Cases covered elsewhere are named in the docs' table
 * (a camera 1 m above a Moon-sized body: test_precision, test_dem; eclipse
 * by a second body: test_shadow).
 *  1. Hapke at w up to 0.999, roughness up to 45 deg, grazing geometry
 *     (i, e up to 89.99 deg, every azimuth): the double evaluation against
 *     the same formulas in long double, to 1e-9 relative.
 *  2. Zero phase: the opposition surge finite and monotone toward g = 0.
 *  3. The Sun at 89.9 deg incidence: finite, positive, below 89 deg's.
 *  4. The terminator on a faceted convex mesh lit 80 deg from the view,
 *     flat and smooth normals: no shadow ray finds the body it leaves.
 *  5. The camera inside a body: every pixel finite, on the body, unlit.
 *  6. The Sun behind the body: the visible side dark, the frame finite.
 *  7. Ranges from 1 m to 1e9 m: a sphere's centre pixel within 1e-6 of the
 *     analytic Lambert radiance and the range within 1e-6 relative.
 *  8. Degenerate triangles (zero area, repeated vertices): loaded, rendered
 *     finite, never hit. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/material.h"
#include "testutil.h"

/* ---- 1. Hapke in long double ------------------------------------------- */

typedef long double ld;

struct hapke_p {
    ld w, b, c, bs0, hs, bc0, hc, theta_deg, phi;
};

static ld H(ld x, ld w, ld r0)
{
    if (!(x > 0))
        return 1;
    return 1 / (1 - w * x * (r0 + 0.5L * (1 - 2 * r0 * x) * logl((1 + x) / x)));
}

/* The formulas of render/brdf.c (Hapke 2012 with IMSA; notes/reflectance.md),
 * evaluated in long double. */
static ld hapke_ld(const struct hapke_p *p, ld mu0, ld mu, ld cg)
{
    const ld PI = 3.141592653589793238462643383279502884L;
    ld K = 1;
    if (p->phi > 0) {
        ld x = 1.209L * powl(p->phi, 2.0L / 3);
        K = -log1pl(-x) / x;
    }
    const ld tb = p->theta_deg * PI / 180, tanb = tanl(tb), chi = 1 / sqrtl(1 + PI * tanb * tanb);
    const ld s = sqrtl(1 - p->w), r0 = (1 - s) / (1 + s);
    ld muA = mu0 > mu ? mu0 : mu, muB = mu0 > mu ? mu : mu0, muAe = muA, muBe = muB, S = 1, Sden = 1;
    if (p->theta_deg > 0) {
        const ld sA = sqrtl(fmaxl(0, 1 - muA * muA)), sB = sqrtl(fmaxl(0, 1 - muB * muB)), cotb = 1 / tanb;
        ld cp = 1, aA = INFINITY, aB = INFINITY;
        if (sA * sB > 1e-300L) {
            cp = (cg - muA * muB) / (sA * sB);
            aA = cotb * muA / sA;
            aB = cotb * muB / sB;
        } else if (sB > 0) {
            aB = cotb * muB / sB;
        }
        cp = cp < -1 ? -1 : cp > 1 ? 1 : cp;
        const ld f = expl(-2 * sqrtl((1 - cp) / (1 + cp))), E1A = expl(-2 / PI * aA), E1B = expl(-2 / PI * aB),
                 E2A = expl(-aA * aA / PI), E2B = expl(-aB * aB / PI), psi = acosl(cp), s2 = 0.5L * (1 - cp);
        const ld etaA = chi * (muA + sA * tanb * E2A / (2 - E1A)), etaB = chi * (muB + sB * tanb * E2B / (2 - E1B));
        const ld dd = 2 - E1B - psi / PI * E1A, inv = dd > 1e-12L ? 1 / dd : 0;
        muAe = chi * (muA + sA * tanb * (cp * E2B + s2 * E2A) * inv);
        muBe = chi * (muB + sB * tanb * (E2B - s2 * E2A) * inv);
        muAe = muAe > 0 ? muAe : 0;
        muBe = muBe > 0 ? muBe : 0;
        S = muAe * muBe * chi;
        Sden = etaB * (etaA * (1 - f) + f * chi * muA);
    }
    S /= muAe + muBe;
    if (!(S > 0) || !(Sden > 0))
        return 0;
    cg = cg < -1 ? -1 : cg > 1 ? 1 : cg;
    const ld tg2 = sqrtl((1 - cg) / (1 + cg));
    const ld Bs = p->bs0 > 0 ? p->bs0 * p->hs / (p->hs + tg2) : 0;
    ld Bc = 0;
    if (p->bc0 > 0) {
        ld x = tg2 / p->hc, q = x > 1e-8L ? -expm1l(-x) / x : 1 - 0.5L * x;
        Bc = p->bc0 * (1 + q) / (2 * (1 + x) * (1 + x));
    }
    ld P = 1;
    if (p->b != 0) {
        ld k = 1 - p->b * p->b, back = 1 - 2 * p->b * cg + p->b * p->b, fwd = 1 + 2 * p->b * cg + p->b * p->b;
        ld lb = back > 0 ? k / (back * sqrtl(back)) : 0, lf = fwd > 0 ? k / (fwd * sqrtl(fwd)) : 0;
        P = 0.5L * (1 + p->c) * lb + 0.5L * (1 - p->c) * lf;
    }
    const ld M = H(muAe / K, p->w, r0) * H(muBe / K, p->w, r0) - 1;
    return K * p->w / (4 * PI) * mu0 * ((P * (1 + Bs) + M) * (1 + Bc)) * S / Sden;
}

static void check_hapke_precision(void)
{
    static const double ws[] = {0.05, 0.5, 0.9, 0.99, 0.999}, thetas[] = {0, 20, 45},
                        angles[] = {0, 30, 60, 85, 89, 89.9, 89.99}, psis[] = {0, 1, 45, 90, 135, 179, 180};
    double worst = 0;
    char where[160] = "";
    long n = 0;
    for (int a = 0; a < 5; a++)
        for (int t = 0; t < 3; t++) {
            struct hapke_p hp = {ws[a], 0.3, 0.4, 1.0, 0.06, 0.5, 0.04, thetas[t], 0.3};
            struct nc_material m;
            CHECK(nc_material_init(&m, "hapke") == 0 && nc_material_set(&m, "w", ws[a]) == 0 &&
                      nc_material_set(&m, "b", 0.3) == 0 && nc_material_set(&m, "c", 0.4) == 0 &&
                      nc_material_set(&m, "B_S0", 1) == 0 && nc_material_set(&m, "h_S", 0.06) == 0 &&
                      nc_material_set(&m, "B_C0", 0.5) == 0 && nc_material_set(&m, "h_C", 0.04) == 0 &&
                      nc_material_set(&m, "theta_bar", thetas[t]) == 0 && nc_material_set(&m, "phi", 0.3) == 0 &&
                      nc_material_finish(&m) == 0,
                  "%s", nc_errmsg());
            for (int i = 0; i < 7; i++)
                for (int e = 0; e < 7; e++)
                    for (int k = 0; k < 7; k++) {
                        const double d = M_PI / 180, I = angles[i] * d, E = angles[e] * d, P = psis[k] * d;
                        struct nc_photometry g = {cos(I), cos(E), cos(I) * cos(E) + sin(I) * sin(E) * cos(P), 1.0};
                        if (!(g.mu0 > 0 && g.mu > 0))
                            continue;
                        double r;
                        nc_material_eval(&m, 1, &g, &r);
                        ld ref = hapke_ld(&hp, g.mu0, g.mu, g.cos_g);
                        double rel = ref != 0 ? (double)fabsl((r - ref) / ref) : fabs(r);
                        n++;
                        if (!(rel <= worst)) {
                            worst = rel;
                            snprintf(where, sizeof where, "w %g theta_bar %g i %g e %g psi %g: %.17g vs %.17Lg",
                                     ws[a], thetas[t], angles[i], angles[e], psis[k], r, ref);
                        }
                    }
            nc_material_free(&m);
        }
    printf("1. Hapke against long double: %ld geometries, worst relative difference %.3g (%s)\n", n, worst, where);
    CHECK(worst < 1e-9, "Hapke differs by %.3g from long double at %s", worst, where);
}

/* ---- 2, 3. Zero phase and grazing incidence, every model ------------- */

static void check_angles(void)
{
    static const char *const presets[] = {"comet_67p", "moon"};
    for (int k = 0; k < 2; k++) {
        struct nc_material m;
        CHECK(nc_material_preset(&m, presets[k]) == 0 && nc_material_finish(&m) == 0, "%s", nc_errmsg());
        /* i = e = 30 deg, g from 1 deg down to exactly 0 (psi -> 0) */
        double prev = 0, r0 = 0;
        int ok = 1;
        for (int j = 0; j <= 6; j++) {
            double g = j < 6 ? pow(10, -j) : 0, d = M_PI / 180, cg = cos(g * d);
            struct nc_photometry geo = {cos(30 * d), cos(30 * d), cg, 1.0};
            double r;
            nc_material_eval(&m, 1, &geo, &r);
            ok &= isfinite(r) && r >= prev; /* the surge rises toward g = 0 */
            prev = r;
            r0 = r;
        }
        printf("2. zero phase, %s: r(0) = %.6g 1/sr, rising monotonically from g = 1 deg\n", presets[k], r0);
        CHECK(ok && r0 > 0, "%s: not finite or not monotone toward zero phase", presets[k]);
        nc_material_free(&m);
    }
    static const char *const models[][2] = {
        {"lambert", "A"}, {"lommel_seeliger", "w"}, {"mcewen", "A"}, {"hapke", "w"}};
    /* (0.2: McEwen's A is at most 0.25) */
    for (int k = 0; k < 4; k++) {
        struct nc_material m;
        CHECK(nc_material_init(&m, models[k][0]) == 0 && nc_material_set(&m, models[k][1], 0.2) == 0 &&
                  nc_material_finish(&m) == 0,
              "%s: %s", models[k][0], nc_errmsg());
        double out89[4], out899[4], out8999[4];
        CHECK(nc_material_eval_deg(&m, 89, 0, 89, out89) == 0 && nc_material_eval_deg(&m, 89.9, 0, 89.9, out899) == 0 &&
                  nc_material_eval_deg(&m, 89.99, 0, 89.99, out8999) == 0,
              "%s", nc_errmsg());
        printf("3. grazing Sun, %s: r = %.4g, %.4g, %.4g 1/sr at i = 89, 89.9, 89.99 deg\n", models[k][0], out89[0],
               out899[0], out8999[0]);
        CHECK(isfinite(out8999[0]) && out8999[0] > 0 && out8999[0] < out899[0] && out899[0] < out89[0],
              "%s at grazing incidence: %g %g %g", models[k][0], out89[0], out899[0], out8999[0]);
        nc_material_free(&m);
    }
}

/* ---- 4-8: frames ------------------------------------------------------- */

static int finite_frame(const struct nc_frame *f)
{
    for (size_t i = 0; i < (size_t)f->width_px * f->height_px; i++)
        if (!isfinite(f->radiance[i]) || !(f->radiance[i] >= 0) || !isfinite(f->range_m[i]))
            return 0;
    return 1;
}

static const char sphere_yaml[] = "bodies:\n"
                                  "  - shape: {type: sphere, radius_m: 1000}\n"
                                  "    material: {model: lambert, A: 0.2}\n"
                                  "sun: {direction: [0, -1, 0]}\n"
                                  "camera: {width_px: 64, height_px: 64, fx_px: 40, fy_px: 40, position_m: [0, -5000, 0],\n"
                                  "         look_at_m: [0, 0, 0], up: [0, 0, 1]}\n"
                                  "render: {samples_per_pixel: 4}\n";

/* The frame of s with every shadow ray traced (no_cull = 1) or with those
 * the shadow grid proves unoccluded skipped. */
static void render_shadows(const struct nc_scene *s, int no_cull, struct nc_frame *f)
{
    struct nc_renderer r;
    CHECK(nc_renderer_init(&r, s, 2) == 0 && nc_frame_alloc(f, s->camera.width_px, s->camera.height_px) == 0, "%s",
          nc_errmsg());
    r.no_shadow_cull = no_cull;
    CHECK(nc_render_frame(&r, s, f) == 0, "%s", nc_errmsg());
    nc_renderer_free(&r);
}

static void check_frames(void)
{
    struct nc_scene s;
    struct nc_frame f;
    /* 4. Terminator acne: a convex icosphere (1280 faces) casts no shadow on
     * itself, so every shadow ray from a point lit by the shading normal
     * must reach the Sun. Traced one by one, any that stops on the body is
     * acne: the frame with every shadow ray traced must equal the frame
     * whose rays the shadow grid proved unoccluded without tracing. */
    for (int smooth = 0; smooth < 2; smooth++) {
        const char *sets[] = {"bodies[0].shape={type: asteroid, radii_m: [1000, 1000, 1000], subdivisions: 3, "
                              "lump_amplitude: 0, craters: 0}",
                              smooth ? "bodies[0].shape.normals=smooth" : "bodies[0].shape.normals=flat",
                              "sun.direction=[0.985, -0.174, 0]", "camera.width_px=256", "camera.height_px=256",
                              "camera.fx_px=600", "camera.fy_px=600"};
        nc_test_scene(sphere_yaml, sets, 7, &s);
        struct nc_frame traced;
        render_shadows(&s, 0, &f);
        render_shadows(&s, 1, &traced);
        int lit = 0, acne = 0;
        for (int i = 0; i < 256 * 256; i++) {
            lit += f.radiance[i] > 0;
            acne += traced.radiance[i] != f.radiance[i];
        }
        printf("4. terminator, %s normals, Sun 80 deg from the view: %d of %d lit pixels change when every shadow "
               "ray is traced\n", smooth ? "smooth" : "flat", acne, lit);
        CHECK(finite_frame(&traced) && lit > 5000 && acne == 0, "%s normals: %d pixels of acne",
              smooth ? "smooth" : "flat", acne);
        nc_frame_free(&traced);
        nc_frame_free(&f);
        nc_scene_free(&s);
    }
    /* 5. the camera inside the body: the inside wall, unlit */
    const char *inside[] = {"camera.position_m=[0, 0, 0]", "camera.look_at_m=[0, 1, 0]"};
    nc_test_scene(sphere_yaml, inside, 2, &s);
    nc_test_render(&s, 2, &f);
    double lit = 0, cover = 0;
    for (int i = 0; i < 64 * 64; i++)
        lit += f.radiance[i], cover += f.coverage[i];
    printf("5. camera inside: coverage %.3f, radiance sum %g, range at the centre %.3f m\n", cover / 4096, lit,
           f.range_m[32 * 64 + 32]);
    CHECK(finite_frame(&f) && cover == 4096 && lit == 0 && fabs(f.range_m[32 * 64 + 32] - 1000) < 1e-3,
          "inside: coverage %g, light %g", cover, lit);
    nc_frame_free(&f);
    nc_scene_free(&s);
    /* 6. the Sun behind the body: the night side faces the camera */
    const char *behind[] = {"sun.direction=[0, 1, 0]"};
    nc_test_scene(sphere_yaml, behind, 1, &s);
    nc_test_render(&s, 2, &f);
    lit = cover = 0;
    for (int i = 0; i < 64 * 64; i++)
        lit += f.radiance[i], cover += f.coverage[i];
    printf("6. Sun behind: %.0f pixels of body, radiance sum %g\n", cover, lit);
    CHECK(finite_frame(&f) && cover > 100 && lit == 0, "Sun behind: light %g on %g pixels", lit, cover);
    nc_frame_free(&f);
    nc_scene_free(&s);
    /* 7. ranges from 1 m to 1e9 m: the sub-camera point, Sun 30 deg off */
    static const double alt[] = {1, 1e3, 1e6, 1e9};
    for (int k = 0; k < 4; k++) {
        char cam[256], fx[64], fy[64];
        double d = 1000 + alt[k], focal = 8 * alt[k] / 1000 + 8; /* the sphere about 16 px wide, or more */
        snprintf(cam, sizeof cam, "camera.position_m=[0, %.17g, 0]", -d);
        snprintf(fx, sizeof fx, "camera.fx_px=%.17g", focal);
        snprintf(fy, sizeof fy, "camera.fy_px=%.17g", focal);
        const char *sets[] = {cam, fx, fy, "sun.direction=[0.5, -0.8660254037844386, 0]", "camera.cx_px=32",
                              "camera.cy_px=32", "render.samples_per_pixel=1"};
        nc_test_scene(sphere_yaml, sets, 7, &s);
        nc_test_render(&s, 2, &f);
        const double L = 0.2 / M_PI * s.sun.irradiance_w_m2 * 0.8660254037844386;
        double got = f.radiance[32 * 64 + 32], range = f.range_m[32 * 64 + 32];
        printf("7. altitude %g m: centre radiance %.9g (exact %.9g), range %.9g m\n", alt[k], got, L, range);
        CHECK(finite_frame(&f) && fabs(got / L - 1) < 1e-6 && fabs(range / alt[k] - 1) < 1e-6,
              "altitude %g m: radiance %g (exact %g), range %g", alt[k], got, L, range);
        nc_frame_free(&f);
        nc_scene_free(&s);
    }
}

/* 8. Degenerate triangles: a closed octahedron, and the same with
 * zero-area triangles added (a repeated vertex, three collinear vertices):
 * the same frame, bit for bit. */
static void check_degenerate(void)
{
    const char *octa = "v 1000 0 0\nv -1000 0 0\nv 0 1000 0\nv 0 -1000 0\nv 0 0 1000\nv 0 0 -1000\n"
                       "v 0 -500 500\n"
                       "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
    char clean[1024], dirty[1024];
    snprintf(clean, sizeof clean, "%s", octa);
    snprintf(dirty, sizeof dirty, "%sf 1 1 5\nf 4 7 5\nf 2 2 2\n", octa);
    nc_test_write(nc_test_path("clean.obj"), clean);
    nc_test_write(nc_test_path("dirty.obj"), dirty);
    struct nc_frame f[2];
    for (int k = 0; k < 2; k++) {
        char shape[512];
        snprintf(shape, sizeof shape, "bodies[0].shape={type: mesh, unit: m, file: '%s'}",
                 nc_test_path(k ? "dirty.obj" : "clean.obj"));
        const char *sets[] = {shape, "sun.direction=[0.6, -0.8, 0]"};
        struct nc_scene s;
        nc_test_scene(sphere_yaml, sets, 2, &s);
        nc_test_render(&s, 2, &f[k]);
        nc_scene_free(&s);
    }
    size_t n = 64 * 64 * sizeof(float);
    int same = !memcmp(f[0].radiance, f[1].radiance, n) && !memcmp(f[0].range_m, f[1].range_m, n);
    printf("8. degenerate triangles: frame finite %d, the same as without them %d\n", finite_frame(&f[1]), same);
    CHECK(finite_frame(&f[1]) && same, "degenerate triangles changed the frame");
    nc_frame_free(&f[0]);
    nc_frame_free(&f[1]);
}

int main(void)
{
    printf("long double: %d mantissa bits\n", LDBL_MANT_DIG);
    check_hapke_precision();
    check_angles();
    check_frames();
    check_degenerate();
    return nc_test_end();
}
