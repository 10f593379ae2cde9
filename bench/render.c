/* bench/render.c - frame time of the full renderer against Embree alone
 * tracing exactly the same camera and shadow rays (coherent 16-wide packets,
 * no shading, no output), on a procedural asteroid of >= 1 million triangles
 * at 1024x1024 with shadows.
 *
 * Usage: bench_render [--frames N] [--threads N] [--subdivisions S] [--spp N]
 * Last line: frame_ms=... raw_rays_ms=... overhead_ratio=... embree_camera_frame_ms=...
 * (the frame with its camera rays through Embree instead of the bins of
 * render/rt_bins.h; the rays Embree alone traces are those the frame traced:
 * one-sample packets of 4x4 pixels where the bins serve). At the defaults
 * (1.3 million triangles, 1 sample a pixel) the bins do not serve (more
 * triangles than samples reach the body), so the frame's camera rays go
 * through Embree either way, as the output says; `make bench` runs it also
 * with the default scene's mesh and samples (--subdivisions 7 --spp 4),
 * where they do, as in the default scene.
 * Both figures are medians over N runs of one process on this machine.
 */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench_util.h"
#include "core/error.h"
#include "render/render.h"
#include "render/rt.h"
#include "camera/camsys.h"
#include "camera/load.h"
#include "render/scene.h"

struct recorder {
    struct nc_ray16 *cam, *shadow;
    int *frame; /* each shadow packet's */
    size_t ncam, nshadow, capcam, capshadow;
};

static void record(void *user, int shadow, const struct nc_ray16 *ray, int frame)
{
    struct recorder *r = user;
    struct nc_ray16 **a = shadow ? &r->shadow : &r->cam;
    size_t *n = shadow ? &r->nshadow : &r->ncam, *cap = shadow ? &r->capshadow : &r->capcam;
    if (*n == *cap) {
        *cap = *cap ? 2 * *cap : 4096;
        *a = realloc(*a, *cap * sizeof **a);
        if (shadow)
            r->frame = realloc(r->frame, *cap * sizeof *r->frame);
        if (!*a || (shadow && !r->frame)) {
            fprintf(stderr, "out of memory\n");
            exit(1);
        }
    }
    if (shadow)
        r->frame[*n] = frame;
    (*a)[(*n)++] = *ray;
}

int main(int argc, char **argv)
{
    int frames = 7, threads = (int)sysconf(_SC_NPROCESSORS_ONLN), subdiv = 8, spp = 1, c;
    static const struct option opts[] = {{"frames", required_argument, NULL, 'n'},
                                         {"threads", required_argument, NULL, 'j'},
                                         {"subdivisions", required_argument, NULL, 's'},
                                         {"spp", required_argument, NULL, 'p'},
                                         {"help", no_argument, NULL, 'h'},
                                         {NULL, 0, NULL, 0}};
    while ((c = getopt_long(argc, argv, "n:j:s:p:h", opts, NULL)) != -1) {
        switch (c) {
        case 'n': frames = atoi(optarg); break;
        case 'j': threads = atoi(optarg); break;
        case 's': subdiv = atoi(optarg); break;
        case 'p': spp = atoi(optarg); break;
        default:
            puts("Usage: bench_render [--frames N] [--threads N] [--subdivisions S] [--spp N]");
            return c == 'h' ? 0 : 2;
        }
    }
    if (frames < 1 || frames > 1000)
        frames = 7;
    char s_sub[64], s_spp[64];
    snprintf(s_sub, sizeof s_sub, "bodies.0.shape.subdivisions=%d", subdiv);
    snprintf(s_spp, sizeof s_spp, "render.samples_per_pixel=%d", spp);
    /* The default scene, closer in so the body fills much of the frame, with a
     * Lambert surface: this measures the renderer's own overhead over Embree
     * (ray generation, shading loop, image); the cost of the reflectance
     * models is bench_brdf's (Hapke frame = 1.2x the Lambert frame). */
    const char *sets[] = {s_sub, s_spp, "camera.position_m=[0, -2600, 0]",
                          "bodies.0.material={model: lambert, A: 0.05}"};
    struct nc_scene s;
    struct nc_camsys cs;
    double t0 = now_ms();
    if (nc_setup_load(NULL, sets, 4, &s, &cs) < 0) {
        fprintf(stderr, "bench: %s\n", nc_errmsg());
        return 1;
    }
    double t1 = now_ms();
    struct nc_renderer r;
    if (nc_renderer_init(&r, &s, threads) < 0) {
        fprintf(stderr, "bench: %s\n", nc_errmsg());
        return 1;
    }
    double t2 = now_ms();
    struct nc_frame f;
    nc_frame_alloc(&f, s.camera.width_px, s.camera.height_px);
    printf("scene: procedural asteroid, Lambert, %zu triangles, %zu vertices; %dx%d, %d sample(s)/pixel, %d threads\n",
           s.body[0].mesh.nt, s.body[0].mesh.nv, s.camera.width_px, s.camera.height_px, s.render.samples_per_pixel,
           r.threads);
    printf("setup: mesh generation %.0f ms, Embree BVH build %.0f ms\n", t1 - t0, t2 - t1);

    /* Record the exact packets of one frame (single-threaded pass, untimed). */
    struct recorder rec = {0};
    int keep = r.threads;
    r.threads = 1;
    r.ray_hook = record;
    r.ray_hook_user = &rec;
    nc_render_frame(&r, &s, &f);
    r.ray_hook = NULL;
    r.threads = keep;
    size_t cam_rays = 0, sh_rays = 0, covered = 0;
    for (size_t i = 0; i < rec.ncam; i++)
        for (int k = 0; k < NC_PACKET; k++)
            cam_rays += rec.cam[i].valid[k] != 0;
    for (size_t i = 0; i < rec.nshadow; i++)
        for (int k = 0; k < NC_PACKET; k++)
            sh_rays += rec.shadow[i].valid[k] != 0;
    for (int i = 0; i < f.width_px * f.height_px; i++)
        covered += f.coverage[i] > 0;
    printf("rays per frame: %zu camera (%zu packets), %zu shadow (%zu packets); body covers %.1f%% of pixels\n",
           cam_rays, rec.ncam, sh_rays, rec.nshadow, 100.0 * covered / ((double)f.width_px * f.height_px));

    struct nc_rt_batch *bc, *bs;
    if (nc_rt_batch_create(rec.cam, NULL, rec.ncam, 0, &bc) < 0 ||
        nc_rt_batch_create(rec.shadow, rec.frame, rec.nshadow, 1, &bs) < 0) {
        fprintf(stderr, "bench: %s\n", nc_errmsg());
        return 1;
    }
    double *ft = calloc((size_t)frames, sizeof *ft), *rt = calloc((size_t)frames, sizeof *rt);
    double *rc_ms = calloc((size_t)frames, sizeof *rc_ms), *rs_ms = calloc((size_t)frames, sizeof *rs_ms);
    double *sc_ms = calloc((size_t)frames, sizeof *sc_ms), *ss_ms = calloc((size_t)frames, sizeof *ss_ms);
    double *nc_ms = calloc((size_t)frames, sizeof *nc_ms); /* every shadow ray traced */
    double *nb_ms = calloc((size_t)frames, sizeof *nb_ms); /* camera rays through Embree, not the bins */
    /* Warm up both paths once, then interleave them so that machine noise
     * hits both alike. */
    nc_render_frame(&r, &s, &f);
    nc_rt_batch_trace(r.rt, bc, r.threads, 0);
    nc_rt_batch_trace(r.rt, bs, r.threads, 0);
    for (int i = 0; i < frames; i++) {
        double a = now_ms();
        nc_render_frame(&r, &s, &f);
        ft[i] = now_ms() - a;
        rc_ms[i] = nc_rt_batch_trace(r.rt, bc, r.threads, 0);
        rs_ms[i] = nc_rt_batch_trace(r.rt, bs, r.threads, 0);
        sc_ms[i] = nc_rt_batch_trace(r.rt, bc, r.threads, 1);
        ss_ms[i] = nc_rt_batch_trace(r.rt, bs, r.threads, 1);
        rt[i] = rc_ms[i] + rs_ms[i];
        r.no_shadow_cull = 1;
        a = now_ms();
        nc_render_frame(&r, &s, &f);
        nc_ms[i] = now_ms() - a;
        r.no_shadow_cull = 0;
        r.no_bins = 1;
        a = now_ms();
        nc_render_frame(&r, &s, &f);
        nb_ms[i] = now_ms() - a;
        r.no_bins = 0;
    }
    struct nc_rt_stats sa, sb;
    nc_rt_get_stats(r.rt, &sa);
    nc_render_frame(&r, &s, &f);
    nc_rt_get_stats(r.rt, &sb);
    unsigned long culled = sb.shadow_rays_culled - sa.shadow_rays_culled;
    double frame_ms = median(ft, frames), raw_ms = median(rt, frames);
    double cam_ms = median(rc_ms, frames), shadow_ms = median(rs_ms, frames);
    double single_cam_ms = median(sc_ms, frames), single_shadow_ms = median(ss_ms, frames);

    /* Pose updates that move the camera 600 m sideways and back: far out
     * (more than one bounding radius from the body's bounding sphere, the
     * mesh stays anchored at the body's origin), then at half a radius from
     * the sphere, where every step leaves the camera's geometry cell and the
     * mesh is re-anchored (vertex rewrite + BVH refit). */
    struct nc_rt_stats st0, st1, st2;
    double *upd = calloc((size_t)frames, sizeof *upd), *near = calloc((size_t)frames, sizeof *near);
    const struct nc_vec3 cam0 = s.camera.position_m;
    nc_rt_get_stats(r.rt, &st0);
    for (int i = 0; i < frames; i++) {
        s.camera.position_m.x += 600.0 * (i % 2 ? -1 : 1);
        double a = now_ms();
        nc_rt_update(r.rt, &s);
        upd[i] = now_ms() - a;
    }
    nc_rt_get_stats(r.rt, &st1);
    const unsigned long far_reanchors = st1.reanchors - st0.reanchors;
    const double R = s.body[0].bounding_radius_m;
    s.camera.position_m = nc_v3_scale(nc_v3_unit(nc_v3_sub(cam0, s.body[0].position_m)), 1.5 * R);
    s.camera.position_m = nc_v3_add(s.camera.position_m, s.body[0].position_m);
    nc_rt_update(r.rt, &s);
    nc_rt_get_stats(r.rt, &st1);
    for (int i = 0; i < frames; i++) {
        s.camera.position_m.x += 0.25 * R * (i % 2 ? -1 : 1);
        double a = now_ms();
        nc_rt_update(r.rt, &s);
        near[i] = now_ms() - a;
    }
    nc_rt_get_stats(r.rt, &st2);
    printf("pose update, camera %.0f m from the body, moved 600 m: %.2f ms median (%lu re-anchors in %d)\n",
           nc_v3_norm(nc_v3_sub(cam0, s.body[0].position_m)), median(upd, frames), far_reanchors, frames);
    printf("pose update at half a radius from the bounding sphere, moved %.0f m into a new geometry cell: %.2f ms "
           "median (%lu re-anchors in %d)\n",
           0.25 * R, median(near, frames), st2.reanchors - st1.reanchors, frames);
    free(near);
    s.camera.position_m = cam0;
    printf("Embree alone, 16-wide packets: camera rays %.2f ms, shadow rays %.2f ms (medians of %d)\n", cam_ms,
           shadow_ms, frames);
    printf("Embree alone, single rays:     camera rays %.2f ms, shadow rays %.2f ms (packets %.2fx faster)\n",
           single_cam_ms, single_shadow_ms, (single_cam_ms + single_shadow_ms) / (cam_ms + shadow_ms));
    printf("full frame: %.2f ms median of %d (%.1f Mrays/s incl. shading)\n", frame_ms, frames,
           (cam_rays + sh_rays) / frame_ms / 1e3);
    printf("shadow rays proven unoccluded, not traced: %.1f%%; every shadow ray traced: %.2f ms (the proof "
           "saves %.1f%%)\n",
           100.0 * culled / (culled + sb.shadow_rays_traced - sa.shadow_rays_traced), median(nc_ms, frames),
           100.0 * (1 - frame_ms / median(nc_ms, frames)));
    if (sb.camera_bins)
        printf("camera rays through Embree instead of the bins (no_bins): %.2f ms a frame (the bins save %.1f%%)\n",
               median(nb_ms, frames), 100.0 * (1 - frame_ms / median(nb_ms, frames)));
    else /* nc_rt_bin_camera: listing triangles costs more than Embree's tree where they outnumber the samples */
        printf("camera rays through Embree: the bins do not serve this frame (more triangles than samples that "
               "reach the body; --spp 4 or --subdivisions 7 for them); embree_camera_frame_ms is the same path\n");
    printf("frame_ms=%.3f raw_rays_ms=%.3f overhead_ratio=%.3f embree_camera_frame_ms=%.3f\n", frame_ms, raw_ms,
           frame_ms / raw_ms, median(nb_ms, frames));
    free(nb_ms);
    free(ft);
    free(rt);
    free(rc_ms);
    free(rs_ms);
    free(sc_ms);
    free(ss_ms);
    free(nc_ms);
    free(upd);
    free(rec.cam);
    free(rec.shadow);
    free(rec.frame);
    nc_rt_batch_destroy(bc);
    nc_rt_batch_destroy(bs);
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_scene_free(&s);
    nc_camsys_free(&cs);
    return 0;
}
