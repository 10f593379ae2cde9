/* stars.c - point sources drawn into the frame (stars.h): the stars of the
 * catalogue (star_cat.c) and bodies too small or far to be traced. */
#include "render/stars.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/rt.h"
#include "render/scene.h"

/* ---- drawing ------------------------------------------------------------------- */

/* q's direction (scene frame) dt seconds from the middle of the exposure */
static struct nc_vec3 point_dir(const struct nc_point_source *q, double dt)
{
    if (q->range_m <= 0 || dt == 0)
        return q->dir;
    return nc_v3_unit(nc_v3_add(nc_v3_scale(q->dir, q->range_m), nc_v3_scale(q->rel_velocity_m_s, dt)));
}

/* Where the camera of time t (from the middle of the exposure) images q at time t: 0, or -1 behind it. */
static int point_at(const struct nc_camera *c, const struct nc_point_source *q, double t, double *x, double *y)
{
    const struct nc_quat a = t != 0 ? nc_quat_propagate(c->attitude_q, c->angular_velocity_rad_s, t) : c->attitude_q;
    return nc_camera_project(c, nc_quat_rotate(nc_quat_conj(a), point_dir(q, t)), x, y);
}

/* *h = t - (row - mid) row_s: how far t is from the time of the row where the camera of time t sees q at time t
 * (row_s: the time from one stored row to the next, negative for a view mirrored top to bottom); -1 if q is not
 * in front of that camera. */
static int row_gap(const struct nc_camera *c, const struct nc_point_source *q, double t, double mid, double row_s,
                   double *h)
{
    double x, y;
    if (point_at(c, q, t, &x, &y) < 0)
        return -1;
    *h = t - (y - mid) * row_s;
    return 0;
}

/* The times a point is recorded at, from the middle row's, as spans ta..tb. Under a rolling shutter row y is open
 * (y - mid) row_s +- T / 2 (row_s: the time from one stored row to the next, negative for a view mirrored top to
 * bottom), so a point is recorded while |row_gap| <= T / 2, within +-open, the times a row of the frame or one
 * beside it is open. row_gap mostly goes linearly with time (the camera turns and a body moves steadily; its slope
 * is 1 - v, v the point's speed along the columns in rows per row's time): then one span, T / |slope| long about
 * the root of row_gap (the time of the row the point falls on: by secant steps from 0, the slope by a difference
 * about it), checked at its ends; else (a fast turn bends it, or it has no root) the spans a scan of row_gap over
 * +-open finds, their ends by bisection. With T = 0, the root alone, *gain 1 / |slope| (the record's density
 * there). Returns how many spans (at most max). (Until session 66 a point was drawn over T about a root found by
 * fixed-point steps, which strayed for motion along the columns: recorded as long as T whatever v.) */
struct span {
    double ta, tb;
};

static int band(const struct nc_camera *c, const struct nc_point_source *q, double t, double mid, double row_s,
                double T)
{
    double h;
    return row_gap(c, q, t, mid, row_s, &h) == 0 && fabs(h) <= 0.5 * T;
}

/* rolling_spans' scan: row_gap at 65 times over +-open; where it crosses +-T / 2 (or the point turns to or from
 * behind the camera) between two of them, the crossing by bisection; the spans between crossings whose middles are
 * in the band (so a span narrower than the scan's step is found where row_gap crosses both edges between two
 * samples). */
static int scan_spans(const struct nc_camera *c, const struct nc_point_source *q, double mid, double row_s, double T,
                      double open, struct span *sp, int max)
{
    enum { SCAN = 64, EDGES = 2 * SCAN + 2 };
    double edge[EDGES], t0 = -open, h0 = 0;
    int ne = 0, ok0 = row_gap(c, q, t0, mid, row_s, &h0) == 0;
    edge[ne++] = -open;
    for (int i = 1; i <= SCAN; i++) {
        const double t = -open + 2 * open * i / SCAN;
        double h = 0;
        const int ok = row_gap(c, q, t, mid, row_s, &h) == 0;
        for (int side = -1; side <= 1; side += 2) { /* the level side T / 2 */
            const double level = 0.5 * T * side;
            if (ok != ok0 || (ok && (h0 - level) * (h - level) < 0)) {
                double lo = t0, hi = t;
                for (int k = 0; k < 40; k++) {
                    const double m = 0.5 * (lo + hi);
                    double hm = 0;
                    const int okm = row_gap(c, q, m, mid, row_s, &hm) == 0;
                    if (okm == ok0 && (!okm || (h0 - level) * (hm - level) > 0))
                        lo = m;
                    else
                        hi = m;
                }
                edge[ne++] = hi;
            }
            if (ok != ok0)
                break; /* one edge for a turn behind the camera */
        }
        t0 = t, h0 = h, ok0 = ok;
    }
    edge[ne++] = open;
    for (int i = 1; i < ne; i++) /* in order (an interval's two crossings may come either way round) */
        for (int k = i; k > 0 && edge[k] < edge[k - 1]; k--) {
            const double e = edge[k];
            edge[k] = edge[k - 1], edge[k - 1] = e;
        }
    int n = 0;
    for (int i = 0; i + 1 < ne && n < max; i++) {
        if (!(edge[i + 1] > edge[i]) || !band(c, q, 0.5 * (edge[i] + edge[i + 1]), mid, row_s, T))
            continue;
        if (n > 0 && sp[n - 1].tb == edge[i])
            sp[n - 1].tb = edge[i + 1]; /* continues the last */
        else
            sp[n++] = (struct span){edge[i], edge[i + 1]};
    }
    return n;
}

/* The linear span's end t as the model says: in the band where it was cut to the window's end, else on the band's
 * edge, |row_gap| = T / 2 within 5 % of T. */
static int span_end_ok(const struct nc_camera *c, const struct nc_point_source *q, double t, int cut, double mid,
                       double row_s, double T)
{
    double h;
    return cut ? band(c, q, t, mid, row_s, T)
               : row_gap(c, q, t, mid, row_s, &h) == 0 && fabs(fabs(h) - 0.5 * T) <= 0.05 * T;
}

static int rolling_spans(const struct nc_camera *c, const struct nc_point_source *q, double mid, double row_s,
                         double T, struct span *sp, int max, double *gain)
{
    const double open = (mid + 1) * fabs(row_s) + 0.5 * T, bound = 1e3 * open; /* the steps' bound */
    double t0 = 0, h0, t1 = 0, h1 = NAN, hp, hm;
    int rooted = row_gap(c, q, t0, mid, row_s, &h0) == 0 &&
                 row_gap(c, q, t1 = fmin(bound, fmax(-bound, -h0)), mid, row_s, &h1) == 0;
    for (int it = 0; rooted && it < 12 && t1 != t0 && h1 != 0; it++) {
        const double t2 = t1 - h1 * (t1 - t0) / (h1 - h0);
        if (!isfinite(t2))
            break;
        t0 = t1, h0 = h1, t1 = fmin(bound, fmax(-bound, t2));
        rooted = row_gap(c, q, t1, mid, row_s, &h1) == 0;
    }
    const double e = 0.5 * fabs(row_s);
    rooted = rooted && fabs(h1) <= e && row_gap(c, q, t1 + e, mid, row_s, &hp) == 0 &&
             row_gap(c, q, t1 - e, mid, row_s, &hm) == 0;
    const double slope = rooted ? fmax(fabs(hp - hm) / (2 * e), 1e-9) : 1;
    *gain = 1 / slope;
    if (T == 0) {
        sp[0] = (struct span){t1, t1};
        return rooted && fabs(t1) <= open;
    }
    if (rooted && slope >= 0.5) { /* linear (where |1 - v| is small, h bends enough to have other roots: scan) */
        const double half = 0.5 * T / slope, ta = fmax(t1 - half, -open), tb = fmin(t1 + half, open);
        if (tb < ta) /* the root off the window: none, unless row_gap bends back into the band there */
            return band(c, q, t1 > 0 ? open : -open, mid, row_s, T) ? scan_spans(c, q, mid, row_s, T, open, sp, max)
                                                                     : 0;
        if (span_end_ok(c, q, ta, ta == -open, mid, row_s, T) && span_end_ok(c, q, tb, tb == open, mid, row_s, T)) {
            sp[0] = (struct span){ta, tb};
            return 1;
        }
    }
    return scan_spans(c, q, mid, row_s, T, open, sp, max);
}

/* Bilinear splat of e (W m^-2) at pixel coordinates (x, y) as radiance,
 * and as I/F k times that. */
static int splat(struct nc_frame *f, const struct nc_camera *c, double x, double y, double e, double k_iof)
{
    const int W = f->width_px, H = f->height_px;
    const int x0 = (int)floor(x), y0 = (int)floor(y);
    const double ax = x - x0, ay = y - y0;
    /* the solid angle the pixel sees through the lens (its true ray's, over the distortion's area Jacobian) */
    const double omega = nc_camera_pixel_sr_at(c, x, y);
    const double L = e / omega, w[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
    int in = 0;
    for (int k = 0; k < 4; k++) {
        int px = x0 + (k & 1), py = y0 + (k >> 1);
        if (px < 0 || py < 0 || px >= W || py >= H || w[k] == 0)
            continue;
        f->radiance[(size_t)py * W + px] += (float)(L * w[k]);
        f->iof[(size_t)py * W + px] += (float)(k_iof * L * w[k]);
        in = 1;
    }
    return in;
}

long nc_render_points(struct nc_renderer *r, const struct nc_scene *s, double exposure_s, double line_time_s,
                      const struct nc_point_source *p, size_t n, int occlusion, struct nc_frame *f, long *hidden)
{
    const struct nc_camera *c = &s->camera;
    *hidden = 0;
    if (f->width_px != c->width_px || f->height_px != c->height_px)
        return nc_error(NC_ERANGE, "frame is %dx%d but the camera is %dx%d", f->width_px, f->height_px,
                        c->width_px, c->height_px);
    int rc = nc_rt_update(r->rt, s); /* the bodies at the scene's (mid-exposure) poses */
    if (rc < 0)
        return rc;
    /* Each point's motion: stars are at infinity, only the camera's rotation moves them; a body's point also moves
     * across the line of sight at up to its speed over its range (rad/s; rate: a bound on every point's). */
    const double spin = nc_v3_norm(c->angular_velocity_rad_s), f_px = fmax(c->fx_px, c->fy_px);
    double rate = spin;
    for (size_t i = 0; i < n; i++)
        if (p[i].range_m > 0)
            rate = fmax(rate, spin + nc_v3_norm(p[i].rel_velocity_m_s) / p[i].range_m);
    const double turn_px = rate * exposure_s * f_px;
    /* A rolling shutter exposes row y (y - (H - 1) / 2) line_time_s after
     * the middle row (y of the stored image: the view's rows counted from
     * its last for a view mirrored top to bottom): the camera has turned by
     * then, by up to roll_px. */
    const double mid_row = 0.5 * (c->height_px - 1), roll_px = rate * line_time_s * mid_row * f_px;
    /* Only the stars the frame can show: projected at mid-exposure within
     * the frame, grown by the turn, the readout and a pixel. */
    size_t *in = malloc((n ? n : 1) * sizeof *in), m = 0;
    if (!in)
        return nc_error(-ENOMEM, "out of memory");
    const struct nc_quat to_cam = nc_quat_conj(c->attitude_q);
    const double grow = turn_px + 2 * roll_px + 2;
    for (size_t i = 0; i < n; i++) {
        double x, y;
        struct nc_vec3 d = nc_quat_rotate(to_cam, p[i].dir);
        if ((nc_camera_project(c, d, &x, &y) == 0 && x > -grow && y > -grow && x < c->width_px - 1 + grow &&
             y < c->height_px - 1 + grow) ||
            (turn_px > 0.1 * c->width_px && d.z > 0)) /* a long turn: every star ahead */
            in[m++] = i;
    }
    long drawn = 0;
    for (size_t i0 = 0; i0 < m; i0 += NC_PACKET) {
        int occ[NC_PACKET] = {0};
        const int nl = m - i0 < NC_PACKET ? (int)(m - i0) : NC_PACKET;
        struct nc_vec3 dirs[NC_PACKET];
        for (int l = 0; l < nl; l++)
            dirs[l] = p[in[i0 + (size_t)l]].dir;
        if (occlusion)
            nc_rt_occluded_dirs(r->rt, dirs, nl, INFINITY, occ);
        for (int l = 0; l < NC_PACKET && i0 + (size_t)l < m; l++) {
            const struct nc_point_source *q = &p[in[i0 + (size_t)l]];
            if (occ[l]) {
                ++*hidden;
                continue;
            }
            /* the times it is recorded at, from the middle row's (the stored image's rows), in steps at most
             * 0.1 px of its motion apart; the irradiance of each step its share of the exposure (with a zero
             * exposure, one step: a global shutter's instant, or its row's) */
            struct span sp[8] = {{-0.5 * exposure_s, 0.5 * exposure_s}};
            double gain = 1;
            const int nsp = roll_px > 0 ? rolling_spans(c, q, mid_row, c->flip_rows ? -line_time_s : line_time_s,
                                                        exposure_s, sp, 8, &gain)
                                        : 1;
            const double own = q->range_m > 0 ? spin + nc_v3_norm(q->rel_velocity_m_s) / q->range_m : spin;
            int shown = 0;
            for (int j = 0; j < nsp; j++) {
                const double ta = sp[j].ta, tb = sp[j].tb;
                const int K = (int)fmin(4096, fmax(1, ceil(own * (tb - ta) * f_px / 0.1)));
                const double share = exposure_s > 0 ? (tb - ta) / exposure_s : gain;
                for (int k = 0; k < K; k++) {
                    double x, y;
                    if (point_at(c, q, ta + (tb - ta) * (k + 0.5) / K, &x, &y) == 0)
                        shown |= splat(f, c, x, y, q->irradiance_w_m2 * share / K, q->iof_per_radiance);
                }
            }
            drawn += shown;
        }
    }
    free(in);
    return drawn;
}

/* ---- bodies smaller than a pixel ---------------------------------------------- */

/* The zoom camera's farthest distance from a body, in its bounding radii:
 * the sphere then spans 2e-4 rad, a zoom pixel some 140 steps of a float
 * ray's direction. Seen from nearer, a body gives more light than the
 * inverse square of its distance says (a Lambert sphere at zero phase: 1 +
 * 0.75 R / distance, the camera's view of its near side), so nearer would
 * err more: here by up to 7.5e-5. */
#define ZOOM_NEAR 1e4

int nc_render_point_bodies(struct nc_renderer *r, const struct nc_scene *s, struct nc_point_source *p)
{
    const struct nc_camera *c = &s->camera;
    unsigned char point[NC_MAX_BODIES] = {0};
    int n = 0;
    memset(r->as_point, 0, sizeof r->as_point);
    /* Traced, a body must meet a sample whatever its place: one through each
     * pixel's centre (one sample a pixel) misses a disk under sqrt 2 px
     * across (centred on a pixel corner), n x n jittered strata one under
     * 2 sqrt 2 / n (one that holds no whole stratum): under that it is a point. */
    const int strata = (int)lround(sqrt((double)s->render.samples_per_pixel));
    const double px_min = strata <= 1 ? M_SQRT2 : fmax(1.0, 2 * M_SQRT2 / strata);
    for (int b = 0; b < s->nbodies; b++) {
        const struct nc_vec3 rel = nc_v3_sub(s->body[b].position_m, c->position_m);
        const double d = nc_v3_norm(rel), R = s->body[b].bounding_radius_m;
        const double px = 2 * asin(R / d) * fmax(c->fx_px, c->fy_px); /* its angular diameter in pixels */
        if (d > R && px >= px_min && R / d < NC_RESOLVED_MIN_RAD)
            return nc_error(NC_ERANGE, "body '%s' is %.3g px across but its bounding sphere spans only %.3g rad "
                            "(%.3g m at %.3g m): the float rays (6e-8 rad a step) cannot trace a body under %g rad; "
                            "under %.3g px it is drawn as a point, which takes a focal length under %.3g px",
                            s->body[b].name, px, R / d, R, d, NC_RESOLVED_MIN_RAD, px_min, 0.5 * px_min / asin(R / d));
        if (!(d > R) || px >= px_min)
            continue;
        enum { Z = 32 };
        const struct nc_vec3 dir = nc_v3_scale(rel, 1 / d);
        /* Seen from its own distance the body can span less than the float
         * rays' directions resolve (6e-8 rad): the zoom's camera stands on
         * the same line of sight, at most ZOOM_NEAR radii from the body (its
         * phase the same); what lies between it and the camera is one
         * occlusion ray, and the light scales with the distances squared. */
        const double dz = fmin(d, ZOOM_NEAR * R), gap = d - dz;
        const struct nc_vec3 at = nc_v3_sub(s->body[b].position_m, nc_v3_scale(dir, dz));
        int hidden = 0;
        if (gap > 0) {
            int rc = nc_rt_update(r->rt, s), occ[NC_PACKET] = {0};
            if (rc < 0)
                return rc;
            nc_rt_occluded_dirs(r->rt, &dir, 1, gap, occ);
            hidden = occ[0];
        }
        struct nc_scene z = *s; /* shallow: shares meshes and materials */
        const double F = 12.0 / tan(asin(R / dz)); /* the bounding sphere 24 px across */
        z.camera = (struct nc_camera){.width_px = Z, .height_px = Z, .fx_px = F, .fy_px = F, .cx_px = 0.5 * (Z - 1),
                                      .cy_px = 0.5 * (Z - 1), .position_m = at};
        const struct nc_vec3 up = fabs(dir.z) < 0.9 ? nc_v3(0, 0, 1) : nc_v3(1, 0, 0);
        nc_quat_look_at(at, s->body[b].position_m, up, &z.camera.attitude_q);
        z.render.samples_per_pixel = 16;
        z.render.quality_auto = 0;
        /* its light alone: the other bodies in the zoom hide it where they are in front but give no light (they
         * are counted in the frame, or as points of their own: a moon's zoom summed the primary beside it) */
        for (int o = 0; o < s->nbodies; o++)
            r->as_point[o] = o != b;
        struct nc_frame zf;
        int rc = nc_frame_alloc(&zf, Z, Z);
        if (rc >= 0)
            rc = nc_render_frame(r, &z, &zf);
        memset(r->as_point, 0, sizeof r->as_point);
        if (rc < 0) {
            nc_frame_free(&zf);
            return rc;
        }
        double e = 0;
        struct nc_vec3 m = nc_v3(0, 0, 0);
        for (int y = 0; y < Z; y++)
            for (int x = 0; x < Z; x++) {
                const struct nc_vec3 q = nc_camera_dir(&z.camera, x, y);
                const double w = zf.radiance[y * Z + x] * nc_camera_pixel_sr(F, F, q); /* L Omega */
                e += w;
                m = nc_v3_add(m, nc_v3_scale(nc_quat_rotate(z.camera.attitude_q, nc_v3_unit(q)), w));
            }
        nc_frame_free(&zf);
        /* the centroid's offset from the line of sight, m, seen from the camera */
        const struct nc_vec3 off = e > 0 ? nc_v3_scale(nc_v3_sub(nc_v3_unit(m), dir), dz) : nc_v3(0, 0, 0);
        struct nc_vec3 sdir;
        double J = s->sun.irradiance_w_m2; /* at the body: its I/F */
        if (s->sun.has_position)
            nc_scene_sun_at(s, s->body[b].position_m, &sdir, &J);
        const struct nc_vec3 centroid = nc_v3_add(rel, off); /* from the camera, at mid-exposure */
        p[n++] = (struct nc_point_source){nc_v3_unit(centroid), hidden ? 0 : e * (dz / d) * (dz / d),
                                          J > 0 ? M_PI / J : 0, nc_v3_norm(centroid),
                                          nc_v3_sub(s->body[b].velocity_m_s, c->velocity_m_s)};
        point[b] = 1;
    }
    memcpy(r->as_point, point, sizeof point);
    return n;
}
