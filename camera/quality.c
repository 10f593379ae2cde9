/* quality.c - render.quality: auto (quality.h). */
#include "camera/quality.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/error.h"

/* The pilot: one sample a pixel in the chosen rows of tiles, into f. */
static int pilot(struct nc_renderer *r, const struct nc_scene *s, uint64_t seed, int bounces, int step,
                 struct nc_frame *f)
{
    struct nc_scene p = *s;
    p.render.samples_per_pixel = 1;
    p.render.seed = seed;
    p.render.bounces = bounces;
    int rows = nc_render_tile_rows(s), rc = 0;
    for (int t = 0; t < rows && rc >= 0; t += step)
        rc = nc_render_rows(r, &p, f, t, t + 1);
    return rc;
}

int nc_quality_auto(struct nc_renderer *r, struct nc_scene *s, const struct nc_camsys *cs, double exposure_s,
                    struct nc_quality_choice *out)
{
    const int64_t t0 = nc_mono_ns();
    const struct nc_camera *c = &s->camera;
    const double k = s->render.auto_noise_fraction, fx = fmax(c->fx_px, c->fy_px);
    memset(out, 0, sizeof *out);
    /* Soft shadows: the widest penumbra in pixels. */
    double tan_a = tan(nc_scene_sun_radius_rad(s));
    for (int b = 0; b < s->nbodies; b++) {
        double R = s->body[b].bounding_radius_m, range = nc_v3_norm(nc_v3_sub(s->body[b].position_m, c->position_m)) - R;
        out->penumbra_px = fmax(out->penumbra_px, range > 0 ? 2 * tan_a * 2 * R * fx / range : INFINITY);
    }
    out->soft_shadows = out->penumbra_px >= 0.5;
    s->render.soft_shadows = out->soft_shadows;
    /* The pilots. */
    const int W = c->width_px, H = c->height_px, rows = nc_render_tile_rows(s), step = rows >= 8 ? 4 : 1;
    struct nc_frame fa = {0}, fb = {0}, fc = {0};
    int rc = nc_frame_alloc(&fa, W, H);
    if (rc >= 0)
        rc = nc_frame_alloc(&fb, W, H);
    if (rc >= 0)
        rc = nc_frame_alloc(&fc, W, H);
    const uint64_t sa = s->render.seed * 0x9e3779b97f4a7c15ull + 0x51, sb = sa + 0x2545f4914f6cdd1dull;
    if (rc >= 0)
        rc = pilot(r, s, sa, 1, step, &fa);
    if (rc >= 0)
        rc = pilot(r, s, sb, 1, step, &fb);
    if (rc >= 0)
        rc = pilot(r, s, sa, 0, step, &fc); /* the same rays without the bounce: their difference is the bounce */
    double var_ratio = 0, ind_sigma = 0, ind_sum = 0, dir_sum = 0;
    size_t n = 0;
    const int same = W == cs->render_width_px && H == cs->render_height_px;
    const double fw = cs->sensor.full_well_e, rn2 = cs->sensor.read_noise_e * cs->sensor.read_noise_e;
    for (int t = 0; rc >= 0 && t < rows; t += step)
        for (int y = t * NC_TILE; y < (t + 1) * NC_TILE && y < H; y++)
            for (int x = 0; x < W; x++) {
                size_t o = (size_t)y * (size_t)W + (size_t)x;
                if (fa.coverage[o] <= 0 && fb.coverage[o] <= 0)
                    continue;
                /* electrons per unit radiance at this pixel (the middle one's where sizes differ) */
                double g = (same ? cs->response[o] : cs->response[(size_t)(cs->render_height_px / 2) * cs->render_width_px +
                                                                  (size_t)(cs->render_width_px / 2)]) * exposure_s;
                double ea = fmin(fa.radiance[o] * g, fw), eb = fmin(fb.radiance[o] * g, fw), ec = fmin(fc.radiance[o] * g, fw);
                double var_cam = 0.5 * (ea + eb) + rn2;
                if (!(var_cam > 0))
                    continue;
                var_ratio += 0.5 * (ea - eb) * (ea - eb) / var_cam;
                ind_sigma += (ea - ec) / sqrt(var_cam);
                ind_sum += ea - ec;
                dir_sum += ec;
                n++;
            }
    nc_frame_free(&fa);
    nc_frame_free(&fb);
    nc_frame_free(&fc);
    if (rc < 0)
        return rc;
    if (n) {
        out->mc_to_noise_var = var_ratio / (double)n;
        out->indirect_sigma = ind_sigma / (double)n;
        out->indirect_ratio = dir_sum > 0 ? ind_sum / dir_sum : 0;
    }
    /* Indirect light, and how deep. */
    out->bounces = 0;
    if (out->indirect_sigma >= k) {
        double rho = fmin(fmax(out->indirect_ratio, 0), 0.95);
        out->bounces = 1;
        while (out->bounces < 8 && out->indirect_sigma * pow(rho, out->bounces) / (1 - rho) >= k)
            out->bounces++;
    }
    /* Samples: mean MC variance / k^2 of the camera's, to the next square. */
    int m = (int)ceil(sqrt(out->mc_to_noise_var) / k - 1e-9);
    m = m < 1 ? 1 : m > 16 ? 16 : m;
    out->samples_per_pixel = m * m;
    s->render.samples_per_pixel = out->samples_per_pixel;
    s->render.bounces = out->bounces;
    out->pilot_ms = (double)(nc_mono_ns() - t0) * 1e-6;
    return 0;
}

void nc_quality_describe(const struct nc_quality_choice *q, char *buf, size_t len)
{
    snprintf(buf, len,
             "spp=%d bounces=%d soft=%d (MC/noise variance at 1 spp %.3g, bounce light %.3g sigma and %.3g of direct, "
             "penumbra %.3g px, pilots %.1f ms)",
             q->samples_per_pixel, q->bounces, q->soft_shadows, q->mc_to_noise_var, q->indirect_sigma,
             q->indirect_ratio, q->penumbra_px, q->pilot_ms);
}
