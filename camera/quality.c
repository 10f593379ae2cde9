/* quality.c - render.quality: auto (quality.h). */
#include "camera/quality.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/error.h"

/* A pilot: the chosen rows of tiles into f at spp 1 or 4. One sample
 * lies anywhere in the pixel (one pass of four over 2 x 2 strata: a random
 * stratum per pixel, jittered in it), so that two pilots differ by what
 * the pixel's area holds too (a limb, a shadow's edge, facets), not only by
 * the soft-shadow and bounce streams; 4 are the 2 x 2 strata. */
static int pilot(struct nc_renderer *r, const struct nc_scene *s, uint64_t seed, int bounces, int spp, int step,
                 struct nc_frame *f)
{
    struct nc_scene p = *s;
    p.render.samples_per_pixel = 4;
    p.render.seed = seed;
    p.render.bounces = bounces;
    const struct nc_sample_pass one = {0, 4, 4}; /* NULL: all four strata */
    return nc_render_rows_every(r, &p, f, step, spp == 1 ? &one : NULL);
}

/* The variants of the pilot c (the same rays, one setting changed) whose
 * difference from it is what that setting costs: hard shadows, the rocks
 * below the boulder cut folded, a level of detail. */
enum { V_HARD, V_CUT, V_LOD, NV };

/* What the pilots say, over the pixels either of the first two saw a body
 * in: means of squared differences in camera noise variances (shot plus
 * read, electrons clipped at the full well), and of the bounce light. */
struct pilot_stats {
    double var_ab;            /* (a - b)^2 / 2: a pixel's Monte Carlo variance, through the PSF */
    double diff[NV];          /* (c - v)^2 for each variant v rendered */
    double ind_sigma, ind_sum, dir_sum; /* a - c over sigma, a - c, c */
    size_t n;
};

static void pilot_stats(const struct nc_scene *s, const struct nc_camsys *cs, double exposure_s, int step,
                        const struct nc_frame *fa, const struct nc_frame *fb, const struct nc_frame *fc,
                        const struct nc_frame *const *fv, struct pilot_stats *st)
{
    const int W = s->camera.width_px, H = s->camera.height_px, rows = nc_render_tile_rows(s);
    const int same = W == cs->render_width_px && H == cs->render_height_px;
    const double fw = cs->sensor.full_well_e, rn2 = cs->sensor.read_noise_e * cs->sensor.read_noise_e;
    memset(st, 0, sizeof *st);
    for (int t = 0; t < rows; t += step)
        for (int y = t * NC_TILE; y < (t + 1) * NC_TILE && y < H; y++)
            for (int x = 0; x < W; x++) {
                size_t o = (size_t)y * (size_t)W + (size_t)x;
                if (fa->coverage[o] <= 0 && fb->coverage[o] <= 0)
                    continue;
                /* electrons per unit radiance at this pixel (the middle one's where sizes differ) */
                double g = (same ? cs->response[o] : cs->response[(size_t)(cs->render_height_px / 2) * cs->render_width_px +
                                                                  (size_t)(cs->render_width_px / 2)]) * exposure_s;
                double ea = fmin(fa->radiance[o] * g, fw), eb = fmin(fb->radiance[o] * g, fw);
                double var_cam = 0.5 * (ea + eb) + rn2;
                if (!(var_cam > 0))
                    continue;
                st->var_ab += 0.5 * (ea - eb) * (ea - eb) / var_cam;
                if (fc) {
                    double ec = fmin(fc->radiance[o] * g, fw);
                    st->ind_sigma += (ea - ec) / sqrt(var_cam);
                    st->ind_sum += ea - ec;
                    st->dir_sum += ec;
                    for (int v = 0; v < NV; v++)
                        if (fv[v]) {
                            double ev = fmin(fv[v]->radiance[o] * g, fw);
                            st->diff[v] += (ec - ev) * (ec - ev) / var_cam;
                        }
                }
                st->n++;
            }
    /* A pixel's rendering errors are independent of its neighbours', and the
     * optics spread each over the PSF before the noise is added: their
     * variance at the detector is sum(w^2) of the kernel's. */
    double w2 = cs->optics.psf.size > 0 ? 0 : 1;
    for (int i = 0; i < cs->optics.psf.size * cs->optics.psf.size; i++)
        w2 += cs->optics.psf.kernel[i] * cs->optics.psf.kernel[i];
    if (st->n) {
        st->var_ab *= w2 / (double)st->n;
        for (int v = 0; v < NV; v++)
            st->diff[v] /= (double)st->n;
        st->ind_sigma /= (double)st->n;
    }
}

int nc_quality_auto(struct nc_renderer *r, struct nc_scene *s, const struct nc_camsys *cs, double exposure_s,
                    struct nc_quality_choice *out)
{
    const int64_t t0 = nc_mono_ns();
    const struct nc_camera *c = &s->camera;
    const double k = s->render.auto_noise_fraction, fx = fmax(c->fx_px, c->fy_px);
    memset(out, 0, sizeof *out);
    /* Soft shadows: the widest penumbra in pixels, a bound; where it spans
     * half a pixel, the pilots tell whether hard shadows would show. */
    double tan_a = tan(nc_scene_sun_radius_rad(s));
    for (int b = 0; b < s->nbodies; b++) {
        double R = s->body[b].bounding_radius_m, range = nc_v3_norm(nc_v3_sub(s->body[b].position_m, c->position_m)) - R;
        out->penumbra_px = fmax(out->penumbra_px, range > 0 ? 2 * tan_a * 2 * R * fx / range : INFINITY);
    }
    const int may_soft = out->penumbra_px >= 0.5;
    s->render.soft_shadows = may_soft;
    /* Biases the noise rule cannot see, as variants of pilot c: rocks below
     * the boulder cut folded into the reflectance, a level of detail. */
    int cut = 0;
    for (int b = 0; b < s->nbodies; b++)
        cut |= s->body[b].boulders.n > 0 && nc_scene_boulder_min_px(s, b) > 0;
    const int want[NV] = {may_soft, cut, s->render.lod_error_px > 0};
    /* The pilots. */
    const int W = c->width_px, H = c->height_px, rows = nc_render_tile_rows(s), step = rows >= 8 ? 4 : 1;
    struct nc_frame f[3 + NV] = {{0}};
    const struct nc_frame *fv[NV] = {NULL};
    int rc = 0;
    for (int i = 0; i < 3 + NV && rc >= 0; i++)
        if (i < 3 || want[i - 3])
            rc = nc_frame_alloc(&f[i], W, H);
    const uint64_t sa = s->render.seed * 0x9e3779b97f4a7c15ull + 0x51, sb = sa + 0x2545f4914f6cdd1dull;
    if (rc >= 0)
        rc = pilot(r, s, sa, 1, 1, step, &f[0]);
    if (rc >= 0)
        rc = pilot(r, s, sb, 1, 1, step, &f[1]);
    if (rc >= 0)
        rc = pilot(r, s, sa, 0, 1, step, &f[2]); /* the same rays without the bounce: their difference is the bounce */
    for (int v = 0; v < NV && rc >= 0; v++)
        if (want[v]) {
            struct nc_scene p = *s;
            if (v == V_HARD)
                p.render.soft_shadows = 0;
            else if (v == V_CUT)
                p.render.boulder_min_px = 0;
            else
                p.render.lod_error_px = 0;
            rc = pilot(r, &p, sa, 0, 1, step, &f[3 + v]);
            fv[v] = &f[3 + v];
        }
    struct pilot_stats st = {0}, st4 = {0};
    if (rc >= 0)
        pilot_stats(s, cs, exposure_s, step, &f[0], &f[1], &f[2], fv, &st);
    out->mc_to_noise_var = st.var_ab;
    out->indirect_sigma = st.ind_sigma;
    out->indirect_ratio = st.dir_sum > 0 ? st.ind_sum / st.dir_sum : 0;
    out->hard_shadow_rms = sqrt(st.diff[V_HARD]);
    out->cut_rms = sqrt(st.diff[V_CUT]);
    out->lod_rms = sqrt(st.diff[V_LOD]);
    out->soft_shadows = may_soft && out->hard_shadow_rms > 0.5 * k;
    out->all_rocks = cut && out->cut_rms > 0.5 * k;
    out->full_mesh = want[V_LOD] && out->lod_rms > 0.5 * k;
    s->render.soft_shadows = out->soft_shadows;
    if (out->all_rocks)
        s->render.boulder_min_px = 0;
    if (out->full_mesh)
        s->render.lod_error_px = 0;
    /* Indirect light, and how deep. */
    if (out->indirect_sigma >= k) {
        double rho = fmin(fmax(out->indirect_ratio, 0), 0.95);
        out->bounces = 1;
        while (out->bounces < 8 && out->indirect_sigma * pow(rho, out->bounces) / (1 - rho) >= k)
            out->bounces++;
    }
    /* Samples: the fewest (a square) whose variance is k^2 of the camera's.
     * Stratified, the variance falls as S^-beta, beta from 1 (noise within
     * a pixel's strata) to 2 (smooth gradients); two more pilots at 4
     * samples a pixel measure it where one sample is not enough. */
    int m = 1;
    out->strata_beta = 1;
    if (rc >= 0 && out->mc_to_noise_var > k * k) {
        const int nb = out->bounces > 0; /* as the frame will be drawn (a bounce at most) */
        rc = pilot(r, s, sa, nb, 4, step, &f[0]);
        if (rc >= 0)
            rc = pilot(r, s, sb, nb, 4, step, &f[1]);
        if (rc >= 0) {
            pilot_stats(s, cs, exposure_s, step, &f[0], &f[1], NULL, NULL, &st4);
            double v1 = out->mc_to_noise_var, v4 = st4.var_ab;
            out->strata_beta = v4 > 0 ? fmin(fmax(log(v1 / v4) / log(4.0), 1.0), 2.0) : 2.0;
            m = 2;
            while (m < 16 && v4 * pow(4.0 / (m * m), out->strata_beta) > k * k)
                m++;
        }
    }
    for (int i = 0; i < 3 + NV; i++)
        nc_frame_free(&f[i]);
    if (rc < 0)
        return rc;
    out->samples_per_pixel = m * m;
    s->render.samples_per_pixel = out->samples_per_pixel;
    s->render.bounces = out->bounces;
    out->pilot_ms = (double)(nc_mono_ns() - t0) * 1e-6;
    return 0;
}

void nc_quality_describe(const struct nc_quality_choice *q, char *buf, size_t len)
{
    snprintf(buf, len,
             "spp=%d bounces=%d soft=%d%s%s (MC/noise variance at 1 spp %.3g falling as spp^-%.2f, bounce light %.3g sigma "
             "and %.3g of direct, penumbra bound %.3g px, hard shadows off by %.3g sigma RMS, boulder cut %.3g, "
             "level of detail %.3g, pilots %.1f ms)",
             q->samples_per_pixel, q->bounces, q->soft_shadows, q->all_rocks ? " rocks=all" : "",
             q->full_mesh ? " lod=off" : "", q->mc_to_noise_var, q->strata_beta, q->indirect_sigma,
             q->indirect_ratio, q->penumbra_px, q->hard_shadow_rms, q->cut_rms, q->lod_rms, q->pilot_ms);
}
