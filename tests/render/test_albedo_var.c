/* test_albedo_var.c - procedural albedo variation (albedo_var.h): the
 * ground's factor has mean 1 over the surface and the configured relative
 * RMS, at any mesh resolution, and is smooth between neighbouring
 * vertices; each rock's factor has mean 1 and the configured RMS, all
 * a function of the seed; rendered, the body's total light moves by little,
 * the pixels vary by about the RMS, and frames are the same on any thread
 * count. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/albedo_var.h"
#include "testutil.h"

/* Area-weighted mean and RMS about it of the per-vertex factors. */
static void stats(const struct nc_mesh *m, const float *f, double *mean, double *rms)
{
    double s = 0, s2 = 0, a = 0;
    for (size_t t = 0; t < m->nt; t++) {
        double w = nc_mesh_face(m, t, NULL) / 3;
        for (int e = 0; e < 3; e++) {
            double v = f[m->tri[3 * t + e]];
            s += w * v, s2 += w * v * v;
        }
        a += 3 * w;
    }
    *mean = s / a;
    *rms = sqrt(fmax(s2 / a - *mean * *mean, 0));
}

static void check_ground(void)
{
    struct nc_asteroid_params ap = {.radii_m = {300, 300, 300}, .subdivisions = 7, .seed = 1};
    struct nc_mesh m;
    CHECK(nc_mesh_asteroid(&ap, &m) == 0, "%s", nc_errmsg());
    struct nc_albedo_var_params p = {.rms = 0.2, .largest_m = 20, .hurst = 0.5, .rocks_rms = 0.3, .seed = 4};
    float *a, *b, *c, *coarse;
    double wl_min, mean, rms, wl2;
    CHECK(nc_albedo_var_vertices(&m, &p, &a, &wl_min) == 0 && nc_albedo_var_vertices(&m, &p, &b, &wl_min) == 0,
          "%s", nc_errmsg());
    stats(&m, a, &mean, &rms);
    int finite = 1;
    for (size_t i = 0; i < m.nv; i++)
        finite &= isfinite(a[i]) && a[i] > 0;
    printf("ground: %zu vertices, wavelengths 20 to %.3g m: mean %.6f, RMS %.4f (configured 0.2)\n", m.nv, wl_min,
           mean, rms);
    CHECK(finite, "a factor is not finite and positive");
    CHECK(fabs(mean - 1) < 1e-5, "mean %.7f", mean);
    CHECK(fabs(rms / 0.2 - 1) < 0.1, "RMS %.4f for 0.2", rms);
    CHECK(!memcmp(a, b, m.nv * sizeof *a), "the same seed gave other factors");
    p.seed = 5;
    CHECK(nc_albedo_var_vertices(&m, &p, &c, &wl_min) == 0, "%s", nc_errmsg());
    size_t differ = 0;
    for (size_t i = 0; i < m.nv; i++)
        differ += a[i] != c[i];
    CHECK(differ > m.nv * 9 / 10, "another seed changed only %zu of %zu factors", differ, m.nv);
    /* The octaves add: on a mesh of half the resolution (the finest octave
     * dropped), neighbouring vertices differ less in proportion to their
     * spacing than an uncorrelated field would (the variation is smooth),
     * and the same largest wavelength gives the same RMS. */
    struct nc_mesh half;
    ap.subdivisions = 6;
    CHECK(nc_mesh_asteroid(&ap, &half) == 0, "%s", nc_errmsg());
    p.seed = 4;
    CHECK(nc_albedo_var_vertices(&half, &p, &coarse, &wl2) == 0, "%s", nc_errmsg());
    double mean2, rms2, d2 = 0;
    stats(&half, coarse, &mean2, &rms2);
    for (size_t t = 0; t < half.nt; t++)
        d2 += pow(coarse[half.tri[3 * t]] - coarse[half.tri[3 * t + 1]], 2);
    double neighbour = sqrt(d2 / half.nt) / rms2;
    printf("ground at half the resolution: wavelengths down to %.3g m, RMS %.4f; neighbours differ by %.2f RMS "
           "(sqrt 2 if independent)\n", wl2, rms2, neighbour);
    CHECK(fabs(wl2 / wl_min - 2) < 0.05 && fabs(rms2 / 0.2 - 1) < 0.1, "half resolution: %g m, RMS %g", wl2, rms2);
    CHECK(neighbour < 0.8, "neighbouring factors differ by %.2f RMS", neighbour);
    free(a), free(b), free(c), free(coarse);
    nc_mesh_free(&m);
    nc_mesh_free(&half);

    /* rocks: one factor each */
    p.rms = 0.2;
    double s = 0, s2 = 0;
    const size_t n = 400000;
    for (size_t i = 0; i < n; i++) {
        double v = nc_albedo_var_rock(&p, i);
        s += v, s2 += v * v;
    }
    double rm = s / n, rr = sqrt(s2 / n - rm * rm);
    printf("rocks: mean %.4f, RMS %.4f (configured 0.3)\n", rm, rr);
    CHECK(fabs(rm - 1) < 0.003 && fabs(rr / 0.3 - 1) < 0.03, "rocks: mean %g, RMS %g", rm, rr);
    CHECK(nc_albedo_var_rock(&p, 17) == nc_albedo_var_rock(&p, 17) && nc_albedo_var_rock(&p, 17) != nc_albedo_var_rock(&p, 18),
          "a rock's factor is not a function of its index");
    p.rocks_rms = 0;
    CHECK(nc_albedo_var_rock(&p, 17) == 1.0f, "no rock variation gave %g", nc_albedo_var_rock(&p, 17));
}


static void check_render(void)
{
    /* the finer asteroid: 4.5 m vertex spacing under 2.6 m pixels */
    const char *bare_sets[] = {"bodies[0].shape.subdivisions=6"};
    const char *var[] = {"bodies[0].shape.subdivisions=6", "bodies[0].albedo_variation={rms: 0.2, largest_m: 40, seed: 2}",
                         "bodies[0].boulders={preset: bennu, min_diameter_m: 4, seed: 3}"};
    const char *rock_sets[] = {var[0], var[2]};
    struct nc_scene bare, varied, rocks, rocks_var;
    nc_test_scene(nc_test_asteroid_yaml, bare_sets, 1, &bare);
    nc_test_scene(nc_test_asteroid_yaml, var, 2, &varied);
    nc_test_scene(nc_test_asteroid_yaml, rock_sets, 2, &rocks);
    nc_test_scene(nc_test_asteroid_yaml, var, 3, &rocks_var);
    struct nc_frame f0, f1, f2, r0, r1;
    nc_test_render(&bare, 2, &f0);
    nc_test_render(&varied, 2, &f1);
    nc_test_render(&varied, 1, &f2);
    nc_test_render(&rocks, 2, &r0);
    nc_test_render(&rocks_var, 2, &r1);
    size_t n = (size_t)f0.width_px * f0.height_px, lit = 0;
    double s0 = 0, s1 = 0, d2 = 0;
    for (size_t i = 0; i < n; i++) {
        s0 += f0.radiance[i], s1 += f1.radiance[i];
        if (f0.radiance[i] > 0 && f0.coverage[i] == 1) {
            d2 += pow(f1.radiance[i] / f0.radiance[i] - 1, 2);
            lit++;
        }
    }
    double rel = sqrt(d2 / lit);
    printf("render: total light %+.3f %% with the variation; over %zu lit pixels the ratio varies by %.3f RMS "
           "(configured 0.2)\n", 100 * (s1 / s0 - 1), lit,
           rel);
    CHECK(fabs(s1 / s0 - 1) < 0.02, "total light moved by %.2f %%", 100 * (s1 / s0 - 1));
    CHECK(rel > 0.14 && rel < 0.22, "pixels vary by %.3f", rel);
    CHECK(!memcmp(f1.radiance, f2.radiance, n * sizeof *f1.radiance), "1 and 2 threads differ");
    /* rocks take their own factors: pixels where rocks are differ */
    size_t rock_px = 0, changed = 0;
    for (size_t i = 0; i < n; i++)
        if (r0.radiance[i] != f0.radiance[i] && r0.radiance[i] > 0) {
            rock_px++;
            changed += r1.radiance[i] != r0.radiance[i];
        }
    printf("render: %zu pixels show rocks, %zu of them change with the variation\n", rock_px, changed);
    CHECK(rock_px > 500 && changed > rock_px * 9 / 10, "%zu of %zu rock pixels changed", changed, rock_px);
    nc_frame_free(&f0), nc_frame_free(&f1), nc_frame_free(&f2), nc_frame_free(&r0), nc_frame_free(&r1);
    nc_scene_free(&bare), nc_scene_free(&varied), nc_scene_free(&rocks), nc_scene_free(&rocks_var);

    /* configuration errors name the key */
    const char *sphere[] = {"bodies[0].shape={type: sphere, radius_m: 100}", "bodies[0].albedo_variation={rms: 0.1}"};
    struct nc_scene s;
    CHECK(nc_test_scene_rc(nc_test_asteroid_yaml, sphere, 2, &s) < 0 && nc_test_contains(nc_errmsg(), "albedo_variation needs a mesh"),
          "on a sphere: %s", nc_errmsg());
    const char *bad[] = {"bodies[0].albedo_variation={rms: -1}"};
    CHECK(nc_test_scene_rc(nc_test_asteroid_yaml, bad, 1, &s) < 0 && nc_test_contains(nc_errmsg(), "albedo_variation.rms"),
          "a negative RMS: %s", nc_errmsg());
}

int main(void)
{
    check_ground();
    check_render();
    return nc_test_end();
}
