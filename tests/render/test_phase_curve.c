/* test_phase_curve.c - rendered spheres against analytic disk-integrated
 * phase curves (shared/notes/reflectance.md): a Lambert sphere (geometric
 * albedo 2A/3, Phi = [sin a + (pi - a) cos a]/pi) and a Lommel-Seeliger sphere
 * (p = w/8, Phi = 1 - sin(a/2) tan(a/2) ln cot(a/4)), from 0 to 150 deg phase,
 * within 0.2%; and the Lommel-Seeliger disk at zero phase is uniform.
 * The camera is 1e6 radii away, so the analytic far-observer curves apply to
 * 1e-6; each pixel subtends 1/(fx fy) sr. */
#include <math.h>
#include <stdio.h>

#include "testutil.h"

static const char yaml[] =
    "bodies:\n"
    "  - shape: {type: sphere, radius_m: 1000}\n"
    "    material: {model: lambert, A: 0.3}\n"
    "sun: {direction: [0, 0, -1]}\n"
    "camera: {width_px: 320, height_px: 320, fx_px: 1.5e8, fy_px: 1.5e8,\n"
    "         position_m: [0, 0, -1.0e9], attitude_q: [1, 0, 0, 0]}\n"
    "render: {samples_per_pixel: 16, seed: 5}\n";

static double flux(const struct nc_scene *s, struct nc_frame *f)
{
    nc_test_render(s, 2, f);
    double sum = 0;
    for (int k = 0; k < f->width_px * f->height_px; k++)
        sum += f->radiance[k];
    return sum / (s->camera.fx_px * s->camera.fy_px); /* W m^-2 at the camera */
}

int main(void)
{
    const double phases[] = {0, 15, 30, 60, 90, 120, 150};
    for (int model = 0; model < 2; model++) {
        double worst = 0;
        for (size_t k = 0; k < sizeof phases / sizeof phases[0]; k++) {
            double a = phases[k] * M_PI / 180;
            char sun[128];
            snprintf(sun, sizeof sun, "sun.direction=[%.17g, 0, %.17g]", sin(a), -cos(a));
            const char *sets[] = {sun, model ? "bodies.0.material={model: lommel_seeliger, w: 0.6}" : "render.seed=5"};
            struct nc_scene s;
            nc_test_scene(yaml, sets, 2, &s);
            struct nc_frame f;
            double F = flux(&s, &f), R = 1000, D = 1e9, J = s.sun.irradiance_w_m2;
            double p, Phi;
            if (model == 0) {
                p = 2.0 * 0.3 / 3.0;
                Phi = (sin(a) + (M_PI - a) * cos(a)) / M_PI;
            } else {
                p = 0.6 / 8.0;
                Phi = a > 0 ? 1 - sin(a / 2) * tan(a / 2) * log(1 / tan(a / 4)) : 1.0;
            }
            double want = p * Phi * J * (R / D) * (R / D), rel = fabs(F - want) / want;
            worst = fmax(worst, rel);
            CHECK(rel < 2e-3, "%s phase %g deg: disk flux %.6g vs analytic %.6g (%.3g)", model ? "Lommel-Seeliger" : "Lambert",
                  phases[k], F, want, rel);
            printf("%-16s phase %5.1f deg: flux/analytic - 1 = %+.2e\n", model ? "Lommel-Seeliger" : "Lambert", phases[k],
                   F / want - 1);
            nc_frame_free(&f);
            nc_scene_free(&s);
        }
        printf("%s: worst relative flux error %.2e over 0..150 deg\n", model ? "Lommel-Seeliger" : "Lambert", worst);
    }
    /* Zero phase everywhere: the Sun at the camera. Then mu0 = mu at every
     * point and Lommel-Seeliger gives r = w/(8 pi): a uniform disk (up to the
     * 1/d^2 of the irradiance across the body, 2e-6 here). With the Sun at
     * infinity instead, a finite-distance camera sees a limb band where
     * mu0 >> mu and r doubles; that is geometry, not the model. */
    const char *sets[] = {"bodies.0.material={model: lommel_seeliger, w: 0.6}",
                          "sun={position_m: [0, 0, -1.0e9], irradiance_w_m2: 1361}"};
    struct nc_scene s;
    nc_test_scene(yaml, sets, 2, &s);
    struct nc_frame f;
    nc_test_render(&s, 2, &f);
    double L0 = 0.6 / (8 * M_PI) * 1361, dev = 0;
    int n = 0;
    for (int i = 0; i < f.width_px * f.height_px; i++)
        if (f.coverage[i] == 1.0f) {
            dev = fmax(dev, fabs(f.radiance[i] - L0) / L0);
            n++;
        }
    CHECK(n > 60000 && dev < 1e-5, "Lommel-Seeliger disk at zero phase not uniform: %d px, worst %.3g", n, dev);
    printf("Lommel-Seeliger at zero phase: %d fully covered pixels, worst deviation from w J/(8 pi) %.2e\n", n, dev);
    nc_frame_free(&f);
    nc_scene_free(&s);
    return nc_test_end();
}
