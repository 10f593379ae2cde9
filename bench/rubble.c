/* bench/rubble.c - what boulders cost (docs/terrain.md).
 *
 * The default scene (its asteroid, Hapke, shadows, 4 samples per pixel,
 * 1024x1024) bare and covered with the Bennu boulder preset down to 0.45 m
 * (over a million rocks, faces 20 deg rough; those of 64 pixels or more at
 * their distance traced as detailed surfaces of 1280 triangles: the
 * effective triangles are the rocks times that), seen along -y from far
 * (6 km: the whole body),
 * medium (1.5 km: the body fills the frame) and close (300 m above the
 * surface, 7 cm pixels). Per range: the frame time of each (median of N
 * frames; bare, every rock and cut interleaved frame by frame after one
 * untimed round), their ratio; the same with the rocks under
 * one pixel at the nearest range left out (render.boulder_min_px: 1, the
 * default for this Hapke material), the rocks that leaves and how the
 * frame's brightness moves with them folded into the roughness (cut_flux:
 * total radiance / that with every rock - 1; theta_bar the roughness used)
 * and without the fold (unfolded_flux); and the time of a pose update that moves the
 * anchor (the mesh re-anchored; the rock tiles only move). Memory: resident memory the rubble
 * scene and its renderer take beyond the bare ones, and that per million rocks
 * (the budget: 200 MB a million).
 * Usage: bench_rubble [--frames N] [--threads N]
 * One line per range:
 *   range=far ... bare_ms=... rubble_ms=... ratio=... memory_mb=... memory_mb_per_million_rocks=... rocks=...
 *   effective_triangles=...
 *   cut_ms=... cut_ratio=... traced=...
 *   theta_bar=... cut_flux=... unfolded_flux=... reanchor_ms=...
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "camera/load.h"
#include "core/error.h"
#include "core/proc.h"
#include "render/render.h"
#include "render/rt.h"

static void die(void)
{
    fprintf(stderr, "bench_rubble: %s\n", nc_errmsg());
    exit(1);
}

/* A scene and its renderer, and the resident memory they took. */
struct setup {
    struct nc_scene s;
    struct nc_renderer r;
    struct nc_frame f;
    double mem_mb;
};

static void setup(const char *const *sets, int nsets, int threads, struct setup *u)
{
    long before = nc_resident_kb();
    struct nc_camsys cs;
    if (nc_setup_load(NULL, sets, nsets, &u->s, &cs) < 0)
        die();
    nc_camsys_render_camera(&cs, &u->s.camera, &u->s.camera);
    nc_camsys_free(&cs);
    if (nc_renderer_init(&u->r, &u->s, threads) < 0 || nc_frame_alloc(&u->f, u->s.camera.width_px,
                                                                       u->s.camera.height_px) < 0)
        die();
    if (nc_render_frame(&u->r, &u->s, &u->f) < 0) /* every tree built */
        die();
    u->mem_mb = (double)(nc_resident_kb() - before) / 1024;
}

static void place(struct nc_scene *s, double y_m)
{
    s->camera.position_m = nc_v3(0, y_m, 0);
    /* looking at the origin along +y, image up +z: the default scene's attitude */
}

static double sum(const struct nc_frame *f)
{
    double s = 0;
    for (size_t i = 0; i < (size_t)f->width_px * f->height_px; i++)
        s += f->radiance[i];
    return s;
}

/* Frame times, median ms: [0] the bare scene, [1] the rubble one with every
 * rock traced, [2] with the default cut, interleaved frame by frame so that
 * the machine's noise hits all three alike; and the total radiance of the
 * last frames [1] and [2] in flux[0], flux[1]. A first round is not timed
 * (levels and cuts picked, their trees built); a switch of the cut after it
 * only enables or disables tiles' instances and folds the material's
 * roughness again. */
static void frames_ms(struct setup *bare, struct setup *rubble, int frames, double ms[3], double flux[2])
{
    double *t = calloc(3 * (size_t)frames, sizeof *t);
    if (!t) {
        fprintf(stderr, "bench_rubble: out of memory\n");
        exit(1);
    }
    for (int i = -1; i < frames; i++)
        for (int k = 0; k < 3; k++) {
            struct setup *u = k ? rubble : bare;
            rubble->s.render.boulder_min_px = k == 2;
            double a = now_ms();
            if (nc_render_frame(&u->r, &u->s, &u->f) < 0)
                die();
            if (i >= 0)
                t[k * frames + i] = now_ms() - a;
            if (k && i == frames - 1)
                flux[k - 1] = sum(&u->f);
        }
    for (int k = 0; k < 3; k++)
        ms[k] = median(t + k * frames, frames);
    free(t);
}

/* A pose update that moves the anchor: the camera steps a quarter of its
 * range sideways and back (each step leaves the anchor's cell, unless the
 * camera is more than one bounding radius from the body's bounding sphere:
 * there the mesh stays anchored at the body's origin). */
static double reanchor_ms(struct setup *u, double range_m)
{
    struct nc_vec3 p = u->s.camera.position_m;
    double t[4];
    for (int i = 0; i < 4; i++) {
        u->s.camera.position_m = nc_v3(p.x + (i % 2 ? 0 : 0.25 * range_m), p.y, p.z);
        double a = now_ms();
        if (nc_rt_update(u->r.rt, &u->s) < 0)
            die();
        t[i] = now_ms() - a;
    }
    u->s.camera.position_m = p;
    if (nc_rt_update(u->r.rt, &u->s) < 0)
        die();
    return median(t, 4);
}

int main(int argc, char **argv)
{
    int frames = 3, threads;
    int status = bench_frames_threads(argc, argv, "bench_rubble", &frames, &threads);
    if (status >= 0)
        return status;
    struct setup bare, rubble;
    setup(NULL, 0, threads, &bare);
    const char *sets[] = {"bodies.0.boulders={preset: bennu, min_diameter_m: 0.45, roughness_deg: 20}"};
    double t0 = now_ms();
    setup(sets, 1, threads, &rubble);
    const struct nc_boulder_field *f = &rubble.s.body[0].boulders;
    const double tri = (double)nc_rt_rock_mesh_triangles(rubble.r.rt, 0);
    printf("bench_rubble: %zu triangles; %zu rocks of 0.45 to 64 m (Bennu preset, faces 20 deg rough), %d shapes, "
           "each a detailed surface of %.0f triangles from %g px: %.3g effective triangles; set up in %.0f ms; "
           "%dx%d, %d samples/pixel, %d threads, median of %d frames\n",
           rubble.s.body[0].mesh.nt, f->n, f->nshapes, tri, rubble.s.render.boulder_mesh_px, tri * (double)f->n,
           now_ms() - t0, rubble.s.camera.width_px, rubble.s.camera.height_px, rubble.s.render.samples_per_pixel,
           rubble.r.threads, frames);
    /* the surface along -y: the body's extent there */
    double surface = 0;
    for (size_t i = 0; i < rubble.s.body[0].mesh.nv; i++) {
        const double *v = &rubble.s.body[0].mesh.v[3 * i];
        if (fabs(v[0]) < 5 && fabs(v[2]) < 5)
            surface = fmin(surface, v[1]);
    }
    const struct {
        const char *name;
        double y_m;
    } ranges[] = {{"far", -6000}, {"medium", -1500}, {"close", surface - 300}};
    for (int k = 0; k < 3; k++) {
        place(&bare.s, ranges[k].y_m);
        place(&rubble.s, ranges[k].y_m);
        double ms[3], fl[2];
        frames_ms(&bare, &rubble, frames, ms, fl); /* ends on the cut's frame */
        const double b = ms[0], r = ms[1], c = ms[2], all = fl[0], flux = fl[1] / all - 1;
        const double theta = rubble.r.fold_theta_bar_deg[0];
        struct nc_rt_stats st;
        nc_rt_get_stats(rubble.r.rt, &st);
        rubble.s.render.boulder_min_px = 0; /* the pose updates with every rock */
        double re = reanchor_ms(&rubble, fabs(ranges[k].y_m)), re_bare = reanchor_ms(&bare, fabs(ranges[k].y_m));
        rubble.s.render.boulder_min_px = 1;
        rubble.s.render.boulder_fold = 0;
        if (nc_render_frame(&rubble.r, &rubble.s, &rubble.f) < 0)
            die();
        double unfolded = sum(&rubble.f) / all - 1;
        rubble.s.render.boulder_fold = 1;
        const double mem_mb = rubble.mem_mb - bare.mem_mb;
        printf("range=%s distance_m=%.0f bare_ms=%.1f rubble_ms=%.1f ratio=%.2f memory_mb=%.1f "
               "memory_mb_per_million_rocks=%.1f rocks=%zu effective_triangles=%.3g cut_ms=%.1f "
               "cut_ratio=%.2f traced=%zu min_d_m=%.3f theta_bar=%.2f cut_flux=%+.4f unfolded_flux=%+.4f reanchor_ms=%.1f reanchor_bare_ms=%.1f\n",
               ranges[k].name, fabs(ranges[k].y_m), b, r, r / b, mem_mb, mem_mb * 1e6 / (double)f->n, f->n,
               tri * (double)f->n, c, c / b,
               st.boulders_traced[0], st.boulder_min_m[0], theta, flux, unfolded, re, re_bare);
        fflush(stdout);
    }
    nc_frame_free(&rubble.f);
    nc_frame_free(&bare.f);
    nc_renderer_free(&rubble.r);
    nc_renderer_free(&bare.r);
    nc_scene_free(&rubble.s);
    nc_scene_free(&bare.s);
    return 0;
}
