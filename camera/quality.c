/* quality.c - render.quality: auto (quality.h). */
#include "camera/quality.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/error.h"

/* The pilots' rows of tiles: over each body's image, every l-th row, l the
 * largest power of 2 up to 16 that puts 4 rows through it (every row of an
 * image under 4 rows tall), so that the pilots cost a small part of a
 * large body's frame and still see a small one; rows no body can reach
 * are not rendered. The image of a body's bounding sphere: 64 directions
 * on the cone it subtends, projected through the lens, and a row to spare
 * each side; a body around the camera, or partly behind it, spans every
 * row. weight[i]: the rows of the frame row[i] stands for (its l). */
struct pilot_rows {
    int n, *row;
    double *weight;
};

enum { PILOT_STEP_MAX = 16, PILOT_ROWS_MIN = 4 };

static int pilot_rows_pick(const struct nc_scene *s, struct pilot_rows *pr)
{
    const struct nc_camera *c = &s->camera;
    const int rows = nc_render_tile_rows(s);
    int *l = calloc((size_t)rows, sizeof *l); /* 0: no body */
    pr->row = malloc((size_t)rows * sizeof *pr->row);
    pr->weight = malloc((size_t)rows * sizeof *pr->weight);
    if (!l || !pr->row || !pr->weight) {
        free(l);
        return nc_error(-ENOMEM, "out of memory");
    }
    const struct nc_mat3 R = nc_quat_to_mat(c->attitude_q); /* camera -> scene */
    for (int b = 0; b < s->nbodies; b++) {
        struct nc_vec3 to = nc_mat_tmul_v(&R, nc_v3_sub(s->body[b].position_m, c->position_m));
        double d = nc_v3_norm(to), R_m = s->body[b].bounding_radius_m, y0 = 0, y1 = c->height_px;
        if (d > R_m) {
            struct nc_vec3 u = nc_v3_scale(to, 1 / d), e1, e2;
            const double ca = sqrt(d * d - R_m * R_m) / d, sa = R_m / d;
            if (u.z <= -sa)
                continue; /* wholly behind the camera */
            nc_v3_basis(u, &e1, &e2);
            int behind = 0;
            y0 = INFINITY;
            y1 = -INFINITY;
            for (int k = 0; k < 64 && !behind; k++) {
                double phi = 2 * M_PI * k / 64, x, y;
                struct nc_vec3 w = nc_v3_add(nc_v3_scale(e1, cos(phi)), nc_v3_scale(e2, sin(phi)));
                behind = nc_camera_project(c, nc_v3_add(nc_v3_scale(u, ca), nc_v3_scale(w, sa)), &x, &y) < 0;
                y0 = fmin(y0, y);
                y1 = fmax(y1, y);
            }
            if (behind) {
                y0 = 0;
                y1 = c->height_px;
            }
        }
        if (y1 < 0 || y0 >= c->height_px)
            continue;
        const int t0 = (int)fmax(floor(y0 / NC_TILE) - 1, 0), t1 = (int)fmin(floor(y1 / NC_TILE) + 1, rows - 1);
        int lb = PILOT_STEP_MAX;
        while (lb > 1 && t1 - t0 + 1 < PILOT_ROWS_MIN * lb)
            lb /= 2;
        for (int t = t0; t <= t1; t++)
            l[t] = l[t] && l[t] < lb ? l[t] : lb;
    }
    pr->n = 0;
    for (int t = 0; t < rows; t++)
        if (l[t] && t % l[t] == 0) {
            pr->row[pr->n] = t;
            pr->weight[pr->n++] = l[t];
        }
    free(l);
    return 0;
}

static void pilot_rows_free(struct pilot_rows *pr)
{
    free(pr->row);
    free(pr->weight);
}

/* A pilot: the chosen rows of tiles into f at spp 1 or 4. One sample
 * lies anywhere in the pixel (one pass of four over 2 x 2 strata: a random
 * stratum per pixel, jittered in it), so that two pilots differ by what
 * the pixel's area holds too (a limb, a shadow's edge, facets), not only by
 * the soft-shadow and bounce streams; 4 are the 2 x 2 strata. */
static int pilot(struct nc_renderer *r, const struct nc_scene *s, uint64_t seed, int bounces, int spp,
                 const struct pilot_rows *pr, struct nc_frame *f)
{
    struct nc_scene p = *s;
    p.render.samples_per_pixel = 4;
    p.render.seed = seed;
    p.render.bounces = bounces;
    const struct nc_sample_pass one = {0, 4, 4}; /* NULL: all four strata */
    return nc_render_row_list(r, &p, f, pr->row, pr->n, spp == 1 ? &one : NULL);
}

/* The variants of the pilot c (the same rays, one setting changed) whose
 * difference from it is what that setting costs: hard shadows, the rocks
 * below the boulder cut folded, a level of detail. Soft shadows' random
 * Sun-disk points make c - hard noisy in every penumbra at one sample, so
 * hard shadows' bias is taken from two independent pairs (c, hard) and
 * (c2, hard2) drawn with b's rays: the mean of (c - hard)(c2 - hard2) is
 * the squared bias alone. */
enum { V_HARD, V_CUT, V_LOD, NV };

/* What the pilots say, over the pixels either of the first two saw a body
 * in: means of squared differences in camera noise variances (shot plus
 * read, electrons clipped at the full well), and of the bounce light. */
struct pilot_stats {
    double var_ab;            /* (a - b)^2 / 2: a pixel's Monte Carlo variance, through the PSF */
    double diff[NV];          /* (c - v)^2 for each variant v rendered; (c - hard)(c2 - hard2) */
    double ind_sigma, ind_sum, dir_sum; /* a - c over sigma, a - c, c */
    double n;                           /* the pixels these stand for */
};

static void pilot_stats(const struct nc_scene *s, const struct nc_camsys *cs, double exposure_s,
                        const struct pilot_rows *pr,
                        const struct nc_frame *fa, const struct nc_frame *fb, const struct nc_frame *fc,
                        const struct nc_frame *const *fv, const struct nc_frame *const *f2, struct pilot_stats *st)
{
    const int W = s->camera.width_px, H = s->camera.height_px;
    const int same = W == cs->render_width_px && H == cs->render_height_px;
    const double fw = cs->sensor.full_well_e, rn2 = cs->sensor.read_noise_e * cs->sensor.read_noise_e;
    memset(st, 0, sizeof *st);
    for (int i = 0; i < pr->n; i++)
        for (int y = pr->row[i] * NC_TILE; y < (pr->row[i] + 1) * NC_TILE && y < H; y++)
            for (int x = 0; x < W; x++) {
                const double wt = pr->weight[i];
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
                st->var_ab += wt * 0.5 * (ea - eb) * (ea - eb) / var_cam;
                if (fc) {
                    double ec = fmin(fc->radiance[o] * g, fw);
                    st->ind_sigma += wt * (ea - ec) / sqrt(var_cam);
                    st->ind_sum += wt * (ea - ec);
                    st->dir_sum += wt * ec;
                    for (int v = 0; v < NV; v++)
                        if (fv[v]) {
                            double ev = fmin(fv[v]->radiance[o] * g, fw), other = ec - ev;
                            if (v == V_HARD) /* c2 - hard2 */
                                other = fmin(f2[0]->radiance[o] * g, fw) - fmin(f2[1]->radiance[o] * g, fw);
                            st->diff[v] += wt * (ec - ev) * other / var_cam;
                        }
                }
                st->n += wt;
            }
    /* A pixel's rendering errors are independent of its neighbours', and the
     * optics spread each over the PSF before the noise is added: their
     * variance at the detector is sum(w^2) of the kernel's. */
    double w2 = cs->optics.psf.size > 0 ? 0 : 1;
    for (int i = 0; i < cs->optics.psf.size * cs->optics.psf.size; i++)
        w2 += cs->optics.psf.kernel[i] * cs->optics.psf.kernel[i];
    if (st->n) {
        st->var_ab *= w2 / st->n;
        for (int v = 0; v < NV; v++)
            st->diff[v] /= st->n;
        st->ind_sigma /= st->n;
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
    const int W = c->width_px, H = c->height_px;
    struct nc_frame f[5 + NV] = {{0}}; /* a, b, c, the variants, c2, hard2 */
    const struct nc_frame *fv[NV] = {NULL};
    struct pilot_rows pr = {0};
    int rc = pilot_rows_pick(s, &pr);
    out->pilot_rows = pr.n;
    for (int i = 0; i < 5 + NV && rc >= 0; i++)
        if (i < 3 || (i < 3 + NV && want[i - 3]) || (i >= 3 + NV && want[V_HARD]))
            rc = nc_frame_alloc(&f[i], W, H);
    const uint64_t sa = s->render.seed * 0x9e3779b97f4a7c15ull + 0x51, sb = sa + 0x2545f4914f6cdd1dull;
    if (rc >= 0)
        rc = pilot(r, s, sa, 1, 1, &pr, &f[0]);
    if (rc >= 0)
        rc = pilot(r, s, sb, 1, 1, &pr, &f[1]);
    if (rc >= 0)
        rc = pilot(r, s, sa, 0, 1, &pr, &f[2]); /* the same rays without the bounce: their difference is the bounce */
    for (int v = 0; v < NV && rc >= 0; v++)
        if (want[v]) {
            struct nc_scene p = *s;
            if (v == V_HARD)
                p.render.soft_shadows = 0;
            else if (v == V_CUT)
                p.render.boulder_min_px = 0;
            else
                p.render.lod_error_px = 0;
            rc = pilot(r, &p, sa, 0, 1, &pr, &f[3 + v]);
            fv[v] = &f[3 + v];
            if (v == V_HARD && rc >= 0)
                rc = pilot(r, s, sb, 0, 1, &pr, &f[3 + NV]);
            if (v == V_HARD && rc >= 0)
                rc = pilot(r, &p, sb, 0, 1, &pr, &f[4 + NV]);
        }
    const struct nc_frame *f2[2] = {&f[3 + NV], &f[4 + NV]};
    struct pilot_stats st = {0}, st4 = {0};
    if (rc >= 0)
        pilot_stats(s, cs, exposure_s, &pr, &f[0], &f[1], &f[2], fv, f2, &st);
    out->mc_to_noise_var = st.var_ab;
    out->indirect_sigma = st.ind_sigma;
    out->indirect_ratio = st.dir_sum > 0 ? st.ind_sum / st.dir_sum : 0;
    out->hard_shadow_rms = sqrt(fmax(st.diff[V_HARD], 0));
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
        rc = pilot(r, s, sa, nb, 4, &pr, &f[0]);
        if (rc >= 0)
            rc = pilot(r, s, sb, nb, 4, &pr, &f[1]);
        if (rc >= 0) {
            pilot_stats(s, cs, exposure_s, &pr, &f[0], &f[1], NULL, NULL, NULL, &st4);
            /* Without a bounce, jittered strata cut an edge's variance as
             * S^-1.5 and a smooth gradient's as S^-2; from 1 to 4 samples
             * an edge falls less (some lie on a stratum's boundary), so
             * 1.5 is the least fall taken then (soft shadows' random
             * Sun-disk points fall as S^-1, but only in penumbrae: bennu
             * at 256 px, soft, fell as S^-1.17 from 1 to 4 samples and
             * S^-1.42 from 4 to 121). Paths are random: S^-1. */
            const double least = out->bounces > 0 ? 1.0 : 1.5;
            double v1 = out->mc_to_noise_var, v4 = st4.var_ab;
            out->strata_beta = v4 > 0 ? fmin(fmax(log(v1 / v4) / log(4.0), least), 2.0) : 2.0;
            m = 2;
            while (m < 16 && v4 * pow(4.0 / (m * m), out->strata_beta) > k * k)
                m++;
        }
    }
    for (int i = 0; i < 5 + NV; i++)
        nc_frame_free(&f[i]);
    pilot_rows_free(&pr);
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
             "level of detail %.3g, pilots %.1f ms over %d rows of tiles)",
             q->samples_per_pixel, q->bounces, q->soft_shadows, q->all_rocks ? " rocks=all" : "",
             q->full_mesh ? " lod=off" : "", q->mc_to_noise_var, q->strata_beta, q->indirect_sigma,
             q->indirect_ratio, q->penumbra_px, q->hard_shadow_rms, q->cut_rms, q->lod_rms, q->pilot_ms,
             q->pilot_rows);
}
