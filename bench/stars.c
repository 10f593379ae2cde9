/* bench/stars.c - what stars add to a frame: the default scene (its body,
 * 4 samples per pixel, the full camera model) at 1024x1024 with a 20 deg
 * field of view and the whole catalogue to V 8.99, the camera turned to 16
 * pointings across the sky.
 *   load_ms    reading the star index (nc_sky_load)
 *   first_ms   the first frame's stars (every star's direction at the epoch)
 *   stars_ms   the stars of a frame afterwards (median of 16): selection,
 *              aberration, occultation rays, drawing; target < 5 ms
 *   body_ms    the body's render of the same frames (median), for scale
 * Usage: bench_stars [STARS.DAT]   (default /usr/local/share/navcam/stars.dat,
 *                                   scripts/install-deps.sh --stars)
 * Last line: load_ms=... first_ms=... stars_ms=... stars_per_frame=... body_ms=...
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "camera/load.h"
#include "camera/sky.h"
#include "core/error.h"

static struct nc_quat unit_q(struct nc_quat q)
{
    double n = nc_quat_norm(q);
    return (struct nc_quat){q.w / n, q.x / n, q.y / n, q.z / n};
}

int main(int argc, char **argv)
{
    const char *dat = argc > 1 ? argv[1] : "/usr/local/share/navcam/stars.dat";
    struct nc_star_cat cat;
    char idx[64], set_idx[128];
    snprintf(idx, sizeof idx, "/tmp/navcam_bench_stars_%d.ncs", (int)getpid());
    if (nc_star_cat_read_kstars(dat, &cat) < 0 || nc_star_cat_write(&cat, idx) < 0) {
        fprintf(stderr, "bench_stars: %s (scripts/install-deps.sh --stars)\n", nc_errmsg());
        return 1;
    }
    nc_star_cat_free(&cat);
    snprintf(set_idx, sizeof set_idx, "stars={catalogue: '%s', observer_velocity_m_s: [0, 29780, 0]}", idx);
    /* 20 deg across 1024 px of 5.5 um: f = 5.632 mm / tan(10 deg) */
    const char *sets[] = {set_idx, "camera.focal_length_m=0.015970", "exposure.time_s=0.5"};
    struct nc_scene s;
    struct nc_camsys cs;
    struct nc_sky sky;
    double t0 = now_ms();
    if (nc_setup_load(NULL, sets, 3, &s, &cs) < 0 || (t0 = now_ms(), nc_sky_load(NULL, sets, 3, &sky)) < 0 ||
        nc_sky_prepare(&sky, &cs, &s.camera) < 0) {
        fprintf(stderr, "bench_stars: %s\n", nc_errmsg());
        return 1;
    }
    double load_ms = now_ms() - t0;
    unlink(idx);
    struct nc_renderer r;
    struct nc_frame f;
    struct nc_scene drawn = s;
    nc_camsys_render_camera(&cs, &s.camera, &drawn.camera);
    if (nc_renderer_init(&r, &drawn, 0) < 0 || nc_frame_alloc(&f, drawn.camera.width_px, drawn.camera.height_px) < 0)
        return fprintf(stderr, "bench_stars: %s\n", nc_errmsg()), 1;
    enum { N = 16 };
    double body[N], star[N], first = 0;
    long drawn_n = 0;
    for (int i = 0; i <= N; i++) {
        /* the camera turned about the scene's z axis and tilted: new stars each time */
        struct nc_quat turn = unit_q((struct nc_quat){cos(0.2 * i), 0.3 * sin(0.1 * i), 0, sin(0.2 * i)});
        drawn.camera.attitude_q = unit_q(nc_quat_mul(turn, s.camera.attitude_q));
        struct nc_sky_stats st;
        double a = now_ms();
        nc_render_frame(&r, &drawn, &f);
        double b = now_ms();
        if (nc_sky_draw(&sky, &r, &cs, &drawn, 0, 0.5, &f, &st) < 0)
            return fprintf(stderr, "bench_stars: %s\n", nc_errmsg()), 1;
        double c = now_ms();
        if (i == 0) {
            first = c - b;
            continue;
        }
        body[i - 1] = b - a;
        star[i - 1] = c - b;
        drawn_n += st.drawn;
    }
    double sm = median(star, N), bm = median(body, N);
    printf("star index: %zu stars to V %.2f, loaded in %.1f ms\n", sky.cat.n, sky.cat.star[sky.cat.n - 1].v_mag, load_ms);
    printf("1024x1024, 20 deg field, default scene: stars %.2f ms a frame (median of %d; %.0f stars drawn a frame; "
           "first frame %.1f ms with every direction at the epoch), the body's render %.1f ms\n",
           sm, N, (double)drawn_n / N, first, bm);
    printf("load_ms=%.2f first_ms=%.2f stars_ms=%.3f stars_per_frame=%.0f body_ms=%.1f\n", load_ms, first, sm,
           (double)drawn_n / N, bm);
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_sky_free(&sky);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
    return 0;
}
