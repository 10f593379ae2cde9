/* render.h - the integrator: camera rays, hard shadows toward the Sun, the
 * material's reflectance, and the per-pixel image in physical units.
 *
 * Work is split into fixed tiles handed out to threads; every pixel's value
 * depends only on the scene and its own coordinates, so frames are
 * bit-identical for any thread count.
 */
#ifndef NC_RENDER_H
#define NC_RENDER_H

#include "rt.h"
#include "scene.h"

struct nc_frame {
    int width_px, height_px;
    float *radiance;  /* W m^-2 sr^-1, mean over the pixel's samples */
    float *iof;       /* I/F = pi r, dimensionless */
    float *range_m;   /* mean distance camera -> surface over samples that hit; 0 where none hit */
    float *coverage;  /* fraction of the pixel's samples that hit a body */
};

struct nc_renderer {
    struct nc_rt *rt;
    int threads;
    /* Optional observer of every traced packet (benchmarks record the exact
     * rays with it); called from render threads, so use with threads = 1. */
    void (*ray_hook)(void *user, int shadow, const struct nc_ray16 *ray);
    void *ray_hook_user;
};

int nc_frame_alloc(struct nc_frame *f, int width_px, int height_px);
void nc_frame_free(struct nc_frame *f);

/* threads <= 0: use scene render.threads, then all online cores. */
int nc_renderer_init(struct nc_renderer *r, const struct nc_scene *s, int threads);
/* Render the scene's current poses into f (allocated to the camera size). */
int nc_render_frame(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f);
void nc_renderer_free(struct nc_renderer *r);

#endif
