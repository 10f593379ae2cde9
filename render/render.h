/* render.h - the integrator: camera rays, shadows toward the Sun (hard, or
 * over its disk), the material's reflectance, indirect light along paths of
 * render.bounces vertices (bounce.h), and the per-pixel image in physical
 * units.
 *
 * Work is split into fixed tiles handed out to threads; every pixel's value
 * depends only on the scene and its own coordinates, so frames are
 * bit-identical for any thread count.
 */
#ifndef NC_RENDER_H
#define NC_RENDER_H

#include "render/rt.h"
#include "render/scene.h"

/* Tiles of NC_TILE x NC_TILE pixels are the unit of work (and of
 * nc_render_rows); a tile is (NC_TILE/4)^2 ray packets of 4x4 pixels. */
#define NC_TILE 16

struct nc_frame {
    int width_px, height_px;
    float *radiance;  /* W m^-2 sr^-1, mean over the pixel's samples */
    float *iof;       /* I/F = pi r, dimensionless */
    float *range_m;   /* mean distance camera -> surface over samples that hit; 0 where none hit */
    float *coverage;  /* fraction of the pixel's samples that hit a body */
    /* Optional (the caller allocates it; nc_frame_free frees it): the
     * boulder the pixel's first sample hit, as its index in its body's
     * list (boulders.h), -1 for ground, sky or no rock (an exposure with
     * time samples: at the middle one). */
    int32_t *rock_id;
    /* Optional (the caller allocates NC_GEOM_PLANES x w x h floats;
     * nc_frame_free frees it): the geometry the pixel's first sample saw,
     * plane after plane (enum nc_geom_plane). At one sample a pixel
     * (render.samples_per_pixel 1, no time samples) that is the ray through
     * the pixel's centre. Where the sample hit nothing, body is -1 and
     * every other plane 0. */
    float *geom;
    /* Optional (the caller allocates w x h floats each; nc_frame_free frees
     * them), W m^-2 sr^-1, means over the pixel's samples like radiance:
     * direct, the part of radiance that is sunlight at the camera rays'
     * surface points (radiance - direct: the indirect light); direct_hard,
     * the same sunlight with each shadow ray aimed at the Sun's centre
     * (hard shadows: what render.soft_shadows 0 would give with these
     * samples; equal to direct when shadows are hard). */
    float *direct, *direct_hard;
    /* Optional (w x h floats, the same): the radiance of one of the
     * pixel's samples, uniformly random over its strata (keyed by the
     * seed; in a pass, its first): a one-sample render within this one. */
    float *one;
};

/* The planes of nc_frame.geom: range (m) along the ray; the point hit in
 * the body-fixed frame of the body hit (m); the surface's unit normal there
 * (body-fixed, turned toward the camera: the facet's, or the interpolated
 * one of smooth shading); the angles of incidence, emission and phase (deg)
 * at that point; the body's index in the scene. */
enum nc_geom_plane { NC_GEOM_RANGE, NC_GEOM_X, NC_GEOM_Y, NC_GEOM_Z, NC_GEOM_NX, NC_GEOM_NY, NC_GEOM_NZ,
                     NC_GEOM_INCIDENCE, NC_GEOM_EMISSION, NC_GEOM_PHASE, NC_GEOM_BODY, NC_GEOM_PLANES };
extern const char *const nc_geom_plane_names[NC_GEOM_PLANES];

#define NC_SCRATCH_FRAMES 4

struct nc_renderer {
    struct nc_rt *rt;
    int threads;
    struct nc_pool *pool; /* pool_threads - 1 workers, started by the first frame */
    int pool_threads;
    /* Optional observer of every traced packet (benchmarks record the exact
     * rays with it): kind 0 camera rays, 1 shadow rays, 2 bounce rays, in
     * frame (nc_rt_occluded16's: -1 the camera's, b body b's far frame);
     * called from render threads, so use with threads = 1. */
    void (*ray_hook)(void *user, int kind, const struct nc_ray16 *ray, int frame);
    void *ray_hook_user;
    /* 1: trace every block, even those whose rays cannot reach a body's
     * bounding sphere (tests compare the two; the frames are identical). */
    int no_cull;
    /* 1: trace every shadow ray, even those proven to meet nothing
     * (nc_rt_occluded16); the frames differ only where float tracing of
     * such a ray reports a spurious hit. */
    int no_shadow_cull;
    /* 1: trace camera rays in packets of one sample of 4x4 pixels, as the
     * shading takes them, instead of 2x2 pixels x 4 samples (trace_camera in
     * render.c), and where the bins serve, hand them to the bins one at a
     * time instead of up to 4 together; tests compare the two (the frames
     * are the same). */
    int one_sample_packets;
    /* 1: trace camera rays through Embree even where a pass's camera is a
     * pinhole at rest over meshes (nc_rt_bin_camera's binned triangles serve
     * them otherwise); tests compare the two. */
    int no_bins;
    /* 1: set up the camera rays' surface points and hard-shadow rays lane by
     * lane, in the general loops, instead of the branch-free loops that
     * serve where they apply (render.c: plain_lanes, hard_lanes); tests
     * compare the two (the frames are the same). */
    int lane_by_lane;
    /* Per body, at the last frame: the roughness theta_bar (deg) its
     * material was rendered with after folding in the rocks not traced, or
     * -1 where nothing was folded (scene.h, render.boulder_fold). */
    double fold_theta_bar_deg[NC_MAX_BODIES];
    /* Bodies nc_render_exposure draws as point sources (smaller than a
     * pixel): their ray hits hide what is behind them but give no light;
     * their light is added as a point (render/stars.h). 0 outside it. */
    unsigned char as_point[NC_MAX_BODIES];
    struct nc_frame scratch[NC_SCRATCH_FRAMES]; /* nc_renderer_scratch */
    /* nc_render_exposure's time samples: one sample's frame and the sums
     * over samples (exp_sum: 4 planes of exp_sub's size), kept between
     * exposures so that each does not allocate and fault in ~50 MB anew at
     * 1024x1024. */
    struct nc_frame exp_sub;
    double *exp_sum;
};

int nc_frame_alloc(struct nc_frame *f, int width_px, int height_px);
void nc_frame_free(struct nc_frame *f);
/* Frames kept with the renderer for renders of a sample of a frame
 * (nc_render_tile_list: quality.h's pilots), so that each call does not
 * allocate and fault in its memory anew: scratch frame i (0 <= i <
 * NC_SCRATCH_FRAMES) at w x h, carrying the optional planes the bits of
 * `planes` ask for (NC_PLANE_*) and no others; its pixels hold what the
 * last render into it left. NULL: out of memory or no such frame
 * (nc_errmsg). nc_renderer_free frees them. */
enum { NC_PLANE_DIRECT = 1, NC_PLANE_DIRECT_HARD = 2, NC_PLANE_ONE = 4 };
struct nc_frame *nc_renderer_scratch(struct nc_renderer *r, int i, int w, int h, unsigned planes);

/* threads <= 0: use scene render.threads, then all online cores. */
int nc_renderer_init(struct nc_renderer *r, const struct nc_scene *s, int threads);
/* The largest of fold_theta_bar_deg over the first nbodies bodies (-1: none folded). */
double nc_render_fold_theta_bar_deg(const struct nc_renderer *r, int nbodies);
/* Render the scene's current poses into f (allocated to the camera size). */
int nc_render_frame(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f);
/* Only image rows [16 begin, 16 end): rows of 16-pixel tiles; other rows of f
 * are left as they are. nc_render_tile_rows() is the number of tile rows. */
int nc_render_rows(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, int tile_row_begin,
                   int tile_row_end);
int nc_render_tile_rows(const struct nc_scene *s);
/* Time and anti-aliasing samples in one budget (render/exposure.c): each
 * pixel takes N = max(S, K) samples over an exposure of K time samples (S =
 * the render.samples_per_pixel strata; one of S, K divides the other).
 * Sample g (0 <= g < N) lies in stratum g mod S; a random permutation per
 * pixel deals the N samples to the K time samples, N / K each, so every
 * time sample sees every part of the pixel on average (unbiased), and the
 * exposure costs N samples a pixel, not K * S. Pass k of K renders its
 * share; each frame it makes is the mean of that share. */
struct nc_sample_pass {
    int k, K, N;
};
/* The same with each image row's camera row_dt[y] seconds after the scene's
 * pose (camera rates; bodies stay at the scene's time). row_dt may be NULL;
 * pass NULL renders every stratum (S samples). */
int nc_render_rows_timed(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, int tile_row_begin,
                         int tile_row_end, const double *row_dt, const struct nc_sample_pass *pass);
/* The n tiles tiles[] of the frame (a sample of it: pilots), tile (tx, ty)
 * numbered ty (width + 15) / 16 + tx; other pixels of f are left as they
 * are. blocks 0: every pixel of those tiles; 1 or 2: only the 4 x 4 pixel
 * blocks (bx, by) of each tile (0 to 3 each) with bx + by even or odd, a
 * checkerboard (half the pixels, spread over the tile), the others left
 * as they are: rendering 1 and then 2 into the same frame gives what 0
 * does. */
int nc_render_tile_list(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, const int *tiles, int n,
                        int blocks, const struct nc_sample_pass *pass);

/* An exposure: pose motion integrated over the exposure window. The scene's
 * poses are those at mid-exposure (of the middle row, for a rolling shutter);
 * camera and body rates (scene config) move them linearly in position and at
 * constant angular rate in attitude. */
struct nc_exposure {
    double exposure_s;
    int rolling;          /* rolling shutter: row y starts line_time_s after row y-1 */
    double line_time_s;
    int max_time_samples; /* 0: 256 */
};
/* Render f over the exposure, with as many time samples as the image motion
 * needs (one per 0.5 px of motion, at least 1); *time_samples reports it. */
int nc_render_exposure(struct nc_renderer *r, const struct nc_scene *s, const struct nc_exposure *ex,
                       struct nc_frame *f, int *time_samples);
/* Image motion over the exposure, pixels: an upper bound from the rates
 * and the nearest possible range (the bodies' bounding spheres), 0 for an
 * exposure of 0. With the camera inside a bounding sphere that range is
 * half the least range r renders over the field at 64 x 64 rays (less the
 * camera's travel in the exposure): an estimate, not a bound (NULL r: no
 * range, as much motion as there can be). */
double nc_render_motion_px(struct nc_renderer *r, const struct nc_scene *s, double exposure_s);
void nc_renderer_free(struct nc_renderer *r);

#endif
