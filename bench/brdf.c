/* bench/brdf.c - reflectance model cost: evaluations per second per core
 * for each model, batched 16 at a time as the renderer calls them, and the
 * frame time of a 1024x1024 Hapke render against the same frame with Lambert.
 *
 * Usage: bench_brdf [--frames N] [--threads N]
 * Last line: lambert_ms=... hapke_ms=... ratio=...
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_util.h"
#include "core/error.h"
#include "render/material.h"
#include "render/render.h"
#include "camera/camsys.h"
#include "camera/load.h"
#include "render/scene.h"

struct setup {
    struct nc_scene s;
    struct nc_renderer r;
    struct nc_frame f;
};

static void setup(struct setup *x, const char *material, int threads)
{
    const char *sets[] = {"bodies.0.shape.subdivisions=8", "render.samples_per_pixel=1",
                          "camera.position_m=[0, -2600, 0]", material};
    struct nc_camsys cs;
    if (nc_setup_load(NULL, sets, 4, &x->s, &cs) < 0 || nc_renderer_init(&x->r, &x->s, threads) < 0 ||
        nc_frame_alloc(&x->f, x->s.camera.width_px, x->s.camera.height_px) < 0) {
        fprintf(stderr, "bench: %s\n", nc_errmsg());
        exit(1);
    }
    nc_camsys_free(&cs); /* the scene's camera model is not needed here */
    nc_render_frame(&x->r, &x->s, &x->f); /* warm-up */
}

static double one_frame(struct setup *x)
{
    double a = now_ms();
    nc_render_frame(&x->r, &x->s, &x->f);
    return now_ms() - a;
}

static void teardown(struct setup *x)
{
    nc_frame_free(&x->f);
    nc_renderer_free(&x->r);
    nc_scene_free(&x->s);
}

int main(int argc, char **argv)
{
    int frames = 7, threads;
    int status = bench_frames_threads(argc, argv, "bench_brdf", &frames, &threads);
    if (status >= 0)
        return status;

    /* 1. Model evaluations, one core, batches of 16 over 2^20 random
     * geometries with mu0, mu in (0, 1] and a consistent phase angle. */
    enum { NG = 1 << 20, BATCH = 16 };
    struct nc_photometry *geo = malloc(NG * sizeof *geo);
    double *r = malloc(NG * sizeof *r);
    uint64_t z = 12345;
    for (int k = 0; k < NG; k++) {
        double u[3];
        for (int q = 0; q < 3; q++) {
            z = z * 6364136223846793005ull + 1442695040888963407ull;
            u[q] = (double)(z >> 11) * 0x1.0p-53;
        }
        double mu0 = 1e-3 + (1 - 1e-3) * u[0], mu = 1e-3 + (1 - 1e-3) * u[1], psi = M_PI * u[2];
        double cg = mu0 * mu + sqrt(1 - mu0 * mu0) * sqrt(1 - mu * mu) * cos(psi);
        geo[k] = (struct nc_photometry){mu0, mu, cg, 1.0};
    }
    const char *models[][2] = {{"lambert", "A=0.1"},
                               {"lommel_seeliger", "w=0.3"},
                               {"mcewen", "A=0.1"},
                               {"hapke (comet_67p)", NULL},
                               {"hapke (moon)", NULL}};
    double sink = 0;
    printf("model evaluations, 1 core, batches of %d, 2^20 geometries, median of 5 passes:\n", BATCH);
    for (int m = 0; m < 5; m++) {
        struct nc_material mat;
        if (m < 3) {
            nc_material_init(&mat, models[m][0]);
            nc_material_set(&mat, models[m][0][0] == 'l' && models[m][0][1] == 'o' ? "w" : "A",
                            atof(models[m][1] + 2));
        } else {
            nc_material_preset(&mat, m == 3 ? "comet_67p" : "moon");
        }
        nc_material_finish(&mat);
        double t[5];
        for (int pass = 0; pass < 5; pass++) {
            double a = now_ms();
            for (int k = 0; k < NG; k += BATCH)
                nc_material_eval(&mat, BATCH, geo + k, r + k);
            t[pass] = now_ms() - a;
            sink += r[pass];
        }
        double ms = median(t, 5);
        printf("  %-18s %7.1f M evaluations/s per core (%.1f ns each)\n", models[m][0], NG / ms / 1e3, ms * 1e6 / NG);
        nc_material_free(&mat);
    }
    free(geo);
    free(r);

    /* 2. A whole frame: the same scene and rays, Lambert vs Hapke, frames
     * interleaved so that machine noise hits both alike. */
    struct setup L, Hk;
    setup(&L, "bodies.0.material={model: lambert, A: 0.05}", threads);
    setup(&Hk, "bodies.0.material={preset: comet_67p}", threads);
    double *tl = calloc((size_t)frames, sizeof *tl), *th = calloc((size_t)frames, sizeof *th);
    for (int i = 0; i < frames; i++) {
        tl[i] = one_frame(&L);
        th[i] = one_frame(&Hk);
    }
    double lam = median(tl, frames), hap = median(th, frames);
    free(tl);
    free(th);
    teardown(&L);
    teardown(&Hk);
    printf("1024x1024 frame, 1.31 M-triangle asteroid, shadows, 1 sample/pixel, %d threads, median of %d:\n", threads,
           frames);
    printf("  lambert %.2f ms, hapke (comet_67p) %.2f ms (checksum %g)\n", lam, hap, sink);
    printf("lambert_ms=%.3f hapke_ms=%.3f ratio=%.3f\n", lam, hap, hap / lam);
    return 0;
}
