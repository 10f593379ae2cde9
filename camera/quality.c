/* quality.c - render.quality: auto (quality.h). */
#include "camera/quality.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/error.h"

/* The pilots' tiles: over each body's image, a staggered lattice, every
 * ly-th row of tiles and in it every lx-th tile (shifted by one each
 * row taken): lx, ly 2 where that puts 4 columns, 4 rows through the
 * image, else 1, halved, the larger first, while the lattice has under 32
 * tiles. A quarter of a large body's tiles: sparser lattices missed what
 * holds the variance (on the default scene at 1024 x 1024, one tile in 16
 * read hard shadows' bias as 0 and v1 as 1.5, one in 4 read 0.26 and 4.6,
 * every tile 0.20 and 4.1; on the sphere at 256 x 256, 23 tiles of 81
 * read v1 4.2, 45 of them 15.7). Tiles no body can reach are not
 * rendered. The image of a body's bounding sphere: 64
 * directions on the cone it subtends, projected through the lens, and a
 * tile to spare each side; a body around the camera, or partly behind it,
 * spans the frame. weight[i]: the tiles tile[i] stands for (lx ly). */
struct pilot_tiles {
    int n, *tile;
    double *weight;
};

enum { PILOT_SPAN_MIN = 4, PILOT_TILES_MIN = 32 };

/* Every second tile of a span where that leaves PILOT_SPAN_MIN of them, else every one. */
static int lattice_step(int span) { return span >= 2 * PILOT_SPAN_MIN ? 2 : 1; }

static int pilot_tiles_pick(const struct nc_scene *s, struct pilot_tiles *pt)
{
    const struct nc_camera *c = &s->camera;
    const int rows = nc_render_tile_rows(s), cols = (c->width_px + NC_TILE - 1) / NC_TILE, n = rows * cols;
    int *lx = calloc((size_t)n, sizeof *lx), *ly = calloc((size_t)n, sizeof *ly); /* 0: no body */
    pt->tile = malloc((size_t)n * sizeof *pt->tile);
    pt->weight = malloc((size_t)n * sizeof *pt->weight);
    if (!lx || !ly || !pt->tile || !pt->weight) {
        free(lx);
        free(ly);
        return nc_error(-ENOMEM, "out of memory");
    }
    const struct nc_mat3 R = nc_quat_to_mat(c->attitude_q); /* camera -> scene */
    for (int b = 0; b < s->nbodies; b++) {
        struct nc_vec3 to = nc_mat_tmul_v(&R, nc_v3_sub(s->body[b].position_m, c->position_m));
        double d = nc_v3_norm(to), R_m = s->body[b].bounding_radius_m;
        double x0 = 0, x1 = c->width_px, y0 = 0, y1 = c->height_px;
        if (d > R_m) {
            struct nc_vec3 u = nc_v3_scale(to, 1 / d), e1, e2;
            const double ca = sqrt(d * d - R_m * R_m) / d, sa = R_m / d;
            if (u.z <= -sa)
                continue; /* wholly behind the camera */
            nc_v3_basis(u, &e1, &e2);
            int behind = 0;
            x0 = y0 = INFINITY;
            x1 = y1 = -INFINITY;
            for (int k = 0; k < 64 && !behind; k++) {
                double phi = 2 * M_PI * k / 64, x, y;
                struct nc_vec3 w = nc_v3_add(nc_v3_scale(e1, cos(phi)), nc_v3_scale(e2, sin(phi)));
                behind = nc_camera_project(c, nc_v3_add(nc_v3_scale(u, ca), nc_v3_scale(w, sa)), &x, &y) < 0;
                x0 = fmin(x0, x);
                x1 = fmax(x1, x);
                y0 = fmin(y0, y);
                y1 = fmax(y1, y);
            }
            if (behind) {
                x0 = y0 = 0;
                x1 = c->width_px;
                y1 = c->height_px;
            }
        }
        if (x1 < 0 || x0 >= c->width_px || y1 < 0 || y0 >= c->height_px)
            continue;
        const int t0 = (int)fmax(floor(y0 / NC_TILE) - 1, 0), t1 = (int)fmin(floor(y1 / NC_TILE) + 1, rows - 1);
        const int u0 = (int)fmax(floor(x0 / NC_TILE) - 1, 0), u1 = (int)fmin(floor(x1 / NC_TILE) + 1, cols - 1);
        int bx = lattice_step(u1 - u0 + 1), by = lattice_step(t1 - t0 + 1);
        while ((bx > 1 || by > 1) && (double)(u1 - u0 + 1) * (t1 - t0 + 1) < PILOT_TILES_MIN * (double)bx * by) {
            if (bx >= by)
                bx /= 2;
            else
                by /= 2;
        }
        for (int t = t0; t <= t1; t++)
            for (int u = u0; u <= u1; u++) {
                const int i = t * cols + u;
                if (!lx[i] || bx * by < lx[i] * ly[i]) { /* the densest lattice where bodies overlap */
                    lx[i] = bx;
                    ly[i] = by;
                }
            }
    }
    pt->n = 0;
    for (int t = 0; t < rows; t++)
        for (int u = 0; u < cols; u++) {
            const int i = t * cols + u;
            if (lx[i] && t % ly[i] == 0 && u % lx[i] == t / ly[i] % lx[i]) {
                pt->tile[pt->n] = i;
                pt->weight[pt->n++] = lx[i] * ly[i];
            }
        }
    free(lx);
    free(ly);
    return 0;
}

static void pilot_tiles_free(struct pilot_tiles *pt)
{
    free(pt->tile);
    free(pt->weight);
}

/* A pilot: the chosen tiles (their blocks as nc_render_tile_list's) into
 * f at 4 samples a pixel, 2 x 2 strata, with its seed and bounces. */
static int pilot(struct nc_renderer *r, const struct nc_scene *s, uint64_t seed, int bounces, int blocks,
                 const struct pilot_tiles *pt, struct nc_frame *f)
{
    struct nc_scene p = *s;
    p.render.samples_per_pixel = 4;
    p.render.seed = seed;
    p.render.bounces = bounces;
    return nc_render_tile_list(r, &p, f, pt->tile, pt->n, blocks, NULL);
}

/* Two pilots a and b of 4 samples a pixel (2 x 2 strata) with their own
 * seeds, each carrying the planes of render.h: its direct sunlight, so
 * that radiance - direct is the bounce light; the same sunlight with hard
 * shadows; one of its samples. The Monte Carlo variance of one sample is
 * v1 = (one_a - one_b)^2 / 2, of four v4 = (a - b)^2 / 2. Variants of b,
 * its rays with hard shadows, no bounce and one setting changed, against
 * b's direct light with hard shadows (the same rays: no noise between
 * them), show what other settings cost: the rocks below the boulder cut
 * folded, a level of detail. Soft
 * shadows' random Sun-disk points make direct - hard noisy in every
 * penumbra, so hard shadows' squared bias is the mean of (a - hard_a)(b -
 * hard_b): independent pairs, the noise cancels. */
enum { V_HARD, V_CUT, V_LOD, NV };

/* What the pilots say, over the pixels a or b saw a body in: means of
 * squared differences in camera noise variances (shot plus read,
 * electrons clipped at the full well), and of the bounce light. */
struct pilot_stats {
    double v1, v4;            /* Monte Carlo variances at 1 and 4 samples, through the PSF */
    double diff[NV];          /* (a - hard_a)(b - hard_b); (hard_b - v)^2 for each variant v rendered */
    double ind_sigma, ind_sum, dir_sum; /* the bounce light over sigma, the bounce light, direct light */
    double n;                           /* the pixels these stand for */
};

/* Electrons from radiance v at g electrons per unit radiance, clipped at the full well fw. */
static inline double el(double g, double fw, float v) { return fmin(v * g, fw); }

static void pilot_stats(const struct nc_scene *s, const struct nc_camsys *cs, double exposure_s,
                        const struct pilot_tiles *pt, int blocks, const struct nc_frame *fa,
                        const struct nc_frame *fb, const struct nc_frame *const *fv, struct pilot_stats *st)
{
    const int W = s->camera.width_px, H = s->camera.height_px, cols = (W + NC_TILE - 1) / NC_TILE;
    const int same = W == cs->render_width_px && H == cs->render_height_px;
    const double fw = cs->sensor.full_well_e, rn2 = cs->sensor.read_noise_e * cs->sensor.read_noise_e;
    memset(st, 0, sizeof *st);
    for (int i = 0; i < pt->n; i++) {
        const int tx = pt->tile[i] % cols * NC_TILE, ty = pt->tile[i] / cols * NC_TILE;
        const double wt = pt->weight[i];
        for (int y = ty; y < ty + NC_TILE && y < H; y++)
            for (int x = tx; x < tx + NC_TILE && x < W; x++) {
                size_t o = (size_t)y * (size_t)W + (size_t)x;
                if ((blocks && ((x - tx) / 4 + (y - ty) / 4) % 2 != blocks - 1) ||
                    (fa->coverage[o] <= 0 && fb->coverage[o] <= 0))
                    continue; /* not rendered (nc_render_tile_list's blocks), or no body */
                /* electrons per unit radiance at this pixel (the middle one's where sizes differ) */
                double g = (same ? cs->response[o] : cs->response[(size_t)(cs->render_height_px / 2) * cs->render_width_px +
                                                                  (size_t)(cs->render_width_px / 2)]) * exposure_s;
                double ea = el(g, fw, fa->radiance[o]), eb = el(g, fw, fb->radiance[o]);
                double da = el(g, fw, fa->direct[o]), db = el(g, fw, fb->direct[o]);
                double oa = el(g, fw, fa->one[o]), ob = el(g, fw, fb->one[o]);
                double var_cam = 0.5 * (ea + eb) + rn2;
                if (!(var_cam > 0))
                    continue;
                st->v1 += wt * 0.5 * (oa - ob) * (oa - ob) / var_cam;
                st->v4 += wt * 0.5 * (ea - eb) * (ea - eb) / var_cam;
                st->ind_sigma += wt * 0.5 * (ea - da + eb - db) / sqrt(var_cam);
                st->ind_sum += wt * 0.5 * (ea - da + eb - db);
                st->dir_sum += wt * 0.5 * (da + db);
                if (fv && fa->direct_hard)
                    st->diff[V_HARD] +=
                        wt * (da - el(g, fw, fa->direct_hard[o])) * (db - el(g, fw, fb->direct_hard[o])) / var_cam;
                for (int v = 0; v < NV && fv; v++)
                    if (fv[v]) {
                        double e = el(g, fw, (fb->direct_hard ? fb->direct_hard : fb->direct)[o]) -
                                   el(g, fw, fv[v]->radiance[o]);
                        st->diff[v] += wt * e * e / var_cam;
                    }
                st->n += wt;
            }
    }
    /* A pixel's rendering errors are independent of its neighbours', and the
     * optics spread each over the PSF before the noise is added: their
     * variance at the detector is sum(w^2) of the kernel's. */
    double w2 = cs->optics.psf.size > 0 ? 0 : 1;
    for (int i = 0; i < cs->optics.psf.size * cs->optics.psf.size; i++)
        w2 += cs->optics.psf.kernel[i] * cs->optics.psf.kernel[i];
    if (st->n) {
        st->v1 *= w2 / st->n;
        st->v4 *= w2 / st->n;
        for (int v = 0; v < NV; v++)
            st->diff[v] /= st->n;
        st->ind_sigma /= st->n;
    }
}

/* A lone sphere or ellipsoid neither shadows nor lights itself: soft
 * shadows and bounces leave its frame as it is. */
static int lone_convex(const struct nc_scene *s)
{
    return s->nbodies == 1 && (s->body[0].shape == NC_SHAPE_SPHERE || s->body[0].shape == NC_SHAPE_ELLIPSOID);
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
    const int may_soft = out->penumbra_px >= 0.5 && !lone_convex(s);
    s->render.soft_shadows = may_soft;
    /* Biases the noise rule cannot see, as variants of pilot b's direct
     * light with hard shadows: rocks below the boulder cut folded into the reflectance, a
     * level of detail. */
    int cut = 0;
    for (int b = 0; b < s->nbodies; b++)
        cut |= s->body[b].boulders.n > 0 && nc_scene_boulder_min_px(s, b) > 0;
    const int want[NV] = {0, cut, s->render.lod_error_px > 0};
    /* The pilots: a and b with their planes, the variants. */
    const int W = c->width_px, H = c->height_px, pb = !lone_convex(s);
    struct nc_frame *f[2 + NV] = {NULL}; /* the renderer's scratch frames */
    const struct nc_frame *fv[NV] = {NULL};
    struct pilot_tiles pt = {0};
    int rc = pilot_tiles_pick(s, &pt);
    out->pilot_tiles = pt.n;
    for (int i = 0; i < 2 + NV && rc >= 0; i++) /* scratch frames a, b, V_CUT's, V_LOD's (V_HARD: planes) */
        if ((i < 2 || want[i - 2]) &&
            !(f[i] = nc_renderer_scratch(r, i < 2 ? i : i - 1, W, H,
                                          i >= 2 ? 0 : NC_PLANE_DIRECT | NC_PLANE_ONE | (may_soft ? NC_PLANE_DIRECT_HARD : 0))))
            rc = -ENOMEM;
    /* Half of each tile's pixels first (a checkerboard of 4 x 4 blocks);
     * the other half where a bounce is taken, whose path noise makes the
     * fall of the variance with samples matter most. */
    const uint64_t sa = s->render.seed * 0x9e3779b97f4a7c15ull + 0x51, sb = sa + 0x2545f4914f6cdd1dull;
    const struct nc_scene ps = *s; /* as the pilots are drawn */
    if (rc >= 0)
        rc = pilot(r, &ps, sa, pb, 1, &pt, f[0]);
    if (rc >= 0)
        rc = pilot(r, &ps, sb, pb, 1, &pt, f[1]);
    for (int v = 0; v < NV && rc >= 0; v++)
        if (want[v]) {
            struct nc_scene p = ps;
            p.render.soft_shadows = 0;
            if (v == V_CUT)
                p.render.boulder_min_px = 0;
            else
                p.render.lod_error_px = 0;
            rc = pilot(r, &p, sb, 0, 1, &pt, f[2 + v]); /* b's rays */
            fv[v] = f[2 + v];
        }
    struct pilot_stats st = {0};
    if (rc >= 0)
        pilot_stats(s, cs, exposure_s, &pt, 1, f[0], f[1], fv, &st);
    out->mc_to_noise_var = st.v1;
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
        if (rc >= 0)
            rc = pilot(r, &ps, sa, pb, 2, &pt, f[0]);
        if (rc >= 0)
            rc = pilot(r, &ps, sb, pb, 2, &pt, f[1]);
        if (rc >= 0)
            pilot_stats(s, cs, exposure_s, &pt, 0, f[0], f[1], NULL, &st);
        out->mc_to_noise_var = st.v1;
    }
    pilot_tiles_free(&pt);
    if (rc < 0)
        return rc;
    /* Samples: the fewest (a square) whose variance is k^2 of the camera's.
     * Stratified, the variance falls as S^-beta, beta from 1 (noise within
     * a pixel's strata, paths) to 2 (smooth gradients): from 1 to 4
     * samples it is log4(v1 / v4), taken to hold on. Without a bounce
     * beta is at least 1.5: jittered strata cut an edge's variance as
     * S^-1.5, and from 1 to 4 samples an edge falls less (some lie on a
     * stratum's boundary); soft shadows' random Sun-disk points fall as
     * S^-1, but only in penumbrae (bennu at 256 px, soft, fell as S^-1.17
     * from 1 to 4 samples and S^-1.42 from 4 to 121). With a bounce, at
     * most 1.5: the paths' noise falls as S^-1 and takes over from the
     * edges' as samples grow (icy measured 1.58 and 1.61 from 1 to 4,
     * and with it got 64 and 49 samples for 0.34 and 0.40 sigma). */
    int m = 1;
    out->strata_beta = 1;
    if (out->mc_to_noise_var > k * k) {
        const double v1 = out->mc_to_noise_var, v4 = st.v4;
        const double least = out->bounces > 0 ? 1.0 : 1.5, most = out->bounces > 0 ? 1.5 : 2.0;
        out->strata_beta = v4 > 0 ? fmin(fmax(log(v1 / v4) / log(4.0), least), most) : most;
        /* Aimed at 0.7 k: the pilots' estimate is itself a sample (at k
         * the bench's sphere, comet and icy came out at 1.10, 1.17 and
         * 1.36 k). At most 256 samples. */
        const double aim = 0.7 * k;
        m = 2;
        while (m < 16 && v4 * pow(4.0 / (m * m), out->strata_beta) > aim * aim)
            m++;
    }
    out->samples_per_pixel = m * m;
    s->render.samples_per_pixel = out->samples_per_pixel;
    s->render.bounces = out->bounces;
    out->pilot_ms = (double)(nc_mono_ns() - t0) * 1e-6;
    return 0;
}

void nc_quality_describe(const struct nc_quality_choice *q, int timing, char *buf, size_t len)
{
    char ms[32] = "", pen[64] = "unbounded (the camera within a body's bounding sphere)";
    if (timing)
        snprintf(ms, sizeof ms, " %.1f ms", q->pilot_ms);
    if (isfinite(q->penumbra_px))
        snprintf(pen, sizeof pen, "%.3g px", q->penumbra_px);
    snprintf(buf, len,
             "spp=%d bounces=%d soft=%d%s%s (MC/noise variance at 1 spp %.3g falling as spp^-%.2f, bounce light %.3g sigma "
             "and %.3g of direct, penumbra bound %s, hard shadows off by %.3g sigma RMS, boulder cut %.3g, "
             "level of detail %.3g, pilots%s over %d tiles)",
             q->samples_per_pixel, q->bounces, q->soft_shadows, q->all_rocks ? " rocks=all" : "",
             q->full_mesh ? " lod=off" : "", q->mc_to_noise_var, q->strata_beta, q->indirect_sigma,
             q->indirect_ratio, pen, q->hard_shadow_rms, q->cut_rms, q->lod_rms, ms, q->pilot_tiles);
}
