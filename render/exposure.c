/* exposure.c - rendering over an exposure window: time samples for motion
 * smear, and rows at their own times for a rolling shutter. Every sample is
 * a full render at propagated poses; nothing here approximates the image.
 * Time and anti-aliasing samples share one budget (struct nc_sample_pass):
 * K time samples over S strata cost max(S, K) samples a pixel. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/render.h"
#include "render/stars.h"

/* Inside a body's bounding sphere the nearest range is what the camera
 * sees: the least range of a render of 64 x 64 rays over the same field
 * (one through each probe pixel's centre), at the frame's middle pose.
 * INFINITY when nothing is hit. */
static double probe_range_m(struct nc_renderer *r, const struct nc_scene *s)
{
    enum { P = 64 };
    const struct nc_camera *c = &s->camera;
    const double k = (double)P / (c->width_px > c->height_px ? c->width_px : c->height_px);
    struct nc_scene z = *s; /* shallow: shares meshes and materials */
    z.camera.width_px = (int)ceil(c->width_px * k), z.camera.height_px = (int)ceil(c->height_px * k);
    z.camera.fx_px = c->fx_px * k, z.camera.fy_px = c->fy_px * k;
    z.camera.cx_px = (c->cx_px + 0.5) * k - 0.5, z.camera.cy_px = (c->cy_px + 0.5) * k - 0.5;
    z.render.samples_per_pixel = 1;
    z.render.bounces = 0;
    z.render.quality_auto = 0;
    struct nc_frame f;
    double least = INFINITY;
    if (nc_frame_alloc(&f, z.camera.width_px, z.camera.height_px) < 0 || nc_render_frame(r, &z, &f) < 0) {
        nc_frame_free(&f);
        return -1; /* unknown: as near as can be */
    }
    for (size_t i = 0; i < (size_t)f.width_px * f.height_px; i++)
        if (f.coverage[i] > 0)
            least = fmin(least, f.range_m[i]);
    nc_frame_free(&f);
    return least;
}

double nc_render_motion_px(struct nc_renderer *r, const struct nc_scene *s, double T)
{
    const struct nc_camera *c = &s->camera;
    if (!(T > 0))
        return 0;
    double f = fmax(c->fx_px, c->fy_px);
    /* Nearest possible range: to any body's bounding sphere. */
    double dmin = INFINITY;
    for (int i = 0; i < s->nbodies; i++)
        dmin = fmin(dmin, nc_v3_norm(nc_v3_sub(s->body[i].position_m, c->position_m)) - s->body[i].bounding_radius_m);
    double motion = nc_v3_norm(c->angular_velocity_rad_s) * T * f;
    double lin = nc_v3_norm(c->velocity_m_s);
    for (int i = 0; i < s->nbodies; i++)
        lin = fmax(lin, nc_v3_norm(s->body[i].velocity_m_s) + nc_v3_norm(c->velocity_m_s) +
                            nc_v3_norm(s->body[i].angular_velocity_rad_s) * s->body[i].bounding_radius_m);
    if (lin > 0 && !(dmin > 0) && r) /* half the least range seen, less the way travelled in the exposure */
        dmin = 0.5 * probe_range_m(r, s) - lin * T;
    if (lin > 0)
        motion += dmin > 0 ? lin * T / dmin * f : INFINITY;
    return motion;
}

struct acc {
    double *L, *iof, *range, *cov;
};

/* Rows [o0, o1) of sample f into the sums a: the first sample sets them. */
static void accumulate(struct acc *a, const struct nc_frame *f, size_t o0, size_t o1, int first)
{
    for (size_t o = o0; o < o1; o++) {
        double L = f->radiance[o], iof = f->iof[o], range = (double)f->range_m[o] * f->coverage[o],
               cov = f->coverage[o];
        if (first) {
            a->L[o] = L, a->iof[o] = iof, a->range[o] = range, a->cov[o] = cov;
        } else {
            a->L[o] += L, a->iof[o] += iof, a->range[o] += range, a->cov[o] += cov;
        }
    }
}

/* Time samples for at least k0 of them over S strata: a divisor of S, or
 * a multiple of S, so that the N = max(S, K) samples of a pixel fall evenly
 * on strata and time samples. */
static int fold_time_samples(int k0, int S)
{
    if (k0 <= 1)
        return 1;
    if (k0 <= S) {
        int K = k0;
        while (S % K)
            K++;
        return K;
    }
    return S * ((k0 + S - 1) / S);
}

/* Global shutter: one band of all rows. Rolling: bands of 16 rows; the
 * camera of each row is at that row's own time, the bodies at the band's
 * mid-time (within 8 line times of every row in it): band b's mid-time tc
 * and each row's offset from it, row_dt. The rows are read out in the
 * stored image's order: for a view whose stored image is mirrored top to
 * bottom (flip_rows, a SUM camera's K22 < 0), from the view's last row up. */
static double band_times(const struct nc_exposure *ex, int b, int H, int flip_rows, double *row_dt)
{
    const double line_s = flip_rows ? -ex->line_time_s : ex->line_time_s;
    int y0 = NC_TILE * b, y1 = NC_TILE * (b + 1) < H ? NC_TILE * (b + 1) : H;
    double tc = ex->rolling ? (0.5 * (y0 + y1 - 1) - 0.5 * (H - 1)) * line_s : 0.0;
    for (int y = 0; y < H; y++)
        row_dt[y] = ex->rolling ? (y - 0.5 * (H - 1)) * line_s - tc : 0.0;
    return tc;
}

/* A rolling shutter with one time sample: each band rendered straight into
 * f (its rows are its own; nothing to add up). */
static int rolling_into(struct nc_renderer *r, const struct nc_scene *s, const struct nc_exposure *ex,
                        struct nc_frame *f)
{
    const int H = f->height_px, bands = nc_render_tile_rows(s);
    double *row_dt = malloc((size_t)H * sizeof *row_dt);
    if (!row_dt)
        return nc_error(-ENOMEM, "out of memory");
    int rc = 0;
    for (int b = 0; b < bands && rc >= 0; b++) {
        struct nc_scene at;
        nc_scene_propagate(s, band_times(ex, b, H, s->camera.flip_rows, row_dt), &at);
        rc = nc_render_rows_timed(r, &at, f, b, b + 1, row_dt, NULL);
    }
    free(row_dt);
    return rc;
}

/* The exposure's K > 1 time samples, S strata. */
static int time_samples_into(struct nc_renderer *r, const struct nc_scene *s, const struct nc_exposure *ex, int K,
                             int S, struct nc_frame *f)
{
    const double T = ex->exposure_s;
    const int W = f->width_px, H = f->height_px, bands = nc_render_tile_rows(s);
    const size_t n = (size_t)W * (size_t)H;
    struct nc_frame *sub = &r->exp_sub;
    int rc = 0;
    if (sub->width_px != W || sub->height_px != H) {
        nc_frame_free(sub);
        free(r->exp_sum);
        r->exp_sum = NULL;
        if ((rc = nc_frame_alloc(sub, W, H)) < 0)
            return rc;
    }
    if (!r->exp_sum && !(r->exp_sum = malloc(4 * n * sizeof *r->exp_sum)))
        return nc_error(-ENOMEM, "out of memory");
    if (!f->rock_id) { /* render no rock plane the caller did not ask for */
        free(sub->rock_id);
        sub->rock_id = NULL;
    } else if (!sub->rock_id && !(sub->rock_id = malloc(n * sizeof *sub->rock_id))) {
        return nc_error(-ENOMEM, "out of memory");
    }
    struct acc a = {r->exp_sum, r->exp_sum + n, r->exp_sum + 2 * n, r->exp_sum + 3 * n};
    double *row_dt = malloc((size_t)H * sizeof *row_dt);
    if (!row_dt)
        return nc_error(-ENOMEM, "out of memory");
    int nb = ex->rolling ? bands : 1;
    for (int b = 0; b < nb && rc >= 0; b++) {
        int r0 = ex->rolling ? b : 0, r1 = ex->rolling ? b + 1 : bands;
        int y0 = NC_TILE * r0, y1 = NC_TILE * r1 < H ? NC_TILE * r1 : H;
        double tc = band_times(ex, b, H, s->camera.flip_rows, row_dt);
        /* the rocks seen at the middle of the exposure: its time sample for an odd K; an even K has none
         * there (K / 2 is T / 2K after it), so a pass of its own (k = -1, first: the renderer's state after
         * the band is the last sample's, as without it), with that sample's strata, renders them */
        for (int k = f->rock_id && K % 2 == 0 ? -1 : 0; k < K && rc >= 0; k++) {
            struct nc_scene at;
            nc_scene_propagate(s, tc + (k >= 0 ? T * ((k + 0.5) / K - 0.5) : 0), &at);
            const struct nc_sample_pass pass = {k >= 0 ? k : K / 2, K, K > S ? K : S};
            if ((rc = nc_render_rows_timed(r, &at, sub, r0, r1, row_dt, &pass)) >= 0 && k >= 0)
                accumulate(&a, sub, (size_t)y0 * W, (size_t)y1 * W, k == 0);
            if (rc >= 0 && f->rock_id && k == (K % 2 ? K / 2 : -1))
                memcpy(f->rock_id + (size_t)y0 * W, sub->rock_id + (size_t)y0 * W,
                       (size_t)(y1 - y0) * (size_t)W * sizeof *f->rock_id);
        }
    }
    free(row_dt);
    for (size_t o = 0; rc >= 0 && o < n; o++) {
        f->radiance[o] = (float)(a.L[o] / K);
        f->iof[o] = (float)(a.iof[o] / K);
        f->range_m[o] = a.cov[o] > 0 ? (float)(a.range[o] / a.cov[o]) : 0.0f;
        f->coverage[o] = (float)(a.cov[o] / K);
    }
    return rc;
}

int nc_render_exposure(struct nc_renderer *r, const struct nc_scene *s, const struct nc_exposure *ex,
                       struct nc_frame *f, int *time_samples)
{
    const double T = ex->exposure_s;
    const int maxk = ex->max_time_samples > 0 ? ex->max_time_samples : 256;
    double motion = nc_render_motion_px(r, s, T);
    int strata = (int)lround(sqrt((double)s->render.samples_per_pixel)), S = strata > 1 ? strata * strata : 1;
    /* at most 0.5 px of motion between time samples */
    int K = fold_time_samples(motion > 0 ? (int)fmin(maxk, ceil(motion / 0.5)) : 1, S);
    if (K > maxk && K > S) /* rounded up past the cap: the largest multiple of S within it */
        K = S * (maxk / S > 1 ? maxk / S : 1);
    if (time_samples)
        *time_samples = K;
    /* Bodies smaller than a pixel: their light as points (render/stars.h),
     * measured at mid-exposure; their ray hits give none meanwhile. */
    struct nc_point_source pts[NC_MAX_BODIES];
    int np = nc_render_point_bodies(r, s, pts), rc = np;
    if (rc >= 0)
        rc = K > 1 ? time_samples_into(r, s, ex, K, S, f) : ex->rolling ? rolling_into(r, s, ex, f)
                                                                          : nc_render_frame(r, s, f);
    if (rc >= 0 && np > 0) { /* what is in front of them: in their own renders and occlusion rays */
        const double line_s = ex->rolling ? ex->line_time_s : 0;
        long hidden, drawn = nc_render_points(r, s, T, line_s, pts, (size_t)np, 0, f, &hidden);
        rc = drawn < 0 ? (int)drawn : 0;
    }
    memset(r->as_point, 0, sizeof r->as_point);
    return rc;
}

