/* sun.c - the Sun in the frame (sun.h). */
#include "render/sun.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/rt.h"

/* Angle from the boresight of the edge of the frame less m pixels on every
 * side along image direction (ux, uy). */
static double edge_angle(const struct nc_camera *c, int m, double ux, double uy)
{
    const double cx = c->cx_px - m, cy = c->cy_px - m, n = hypot(ux, uy);
    if (!(n > 0))
        return 0;
    ux /= n, uy /= n;
    double t = INFINITY; /* from the principal point to the border */
    if (ux > 0)
        t = fmin(t, (c->width_px - 2 * m - 0.5 - cx) / ux);
    if (ux < 0)
        t = fmin(t, (-0.5 - cx) / ux);
    if (uy > 0)
        t = fmin(t, (c->height_px - 2 * m - 0.5 - cy) / uy);
    if (uy < 0)
        t = fmin(t, (-0.5 - cy) / uy);
    const struct nc_vec3 d = nc_v3_unit(nc_camera_dir(c, cx + m + t * ux, cy + m + t * uy));
    return acos(fmin(1, d.z));
}

/* A disk under SUN_POINTS_PX pixels in radius is drawn by SUN_POINTS
 * points spread evenly over it (a golden-angle spiral, each an equal share
 * of its irradiance), each traced for bodies in front and added to the
 * pixel it falls in: its light is all there, however small it is against
 * the pixels (a grid of samples a pixel misses a disk smaller than its
 * spacing, or doubles it). */
#define SUN_POINTS_PX 4.0
enum { SUN_POINTS = 1024 };

static int sun_points(struct nc_renderer *r, const struct nc_scene *s, struct nc_vec3 sun, double theta, double irr,
                      struct nc_frame *f, struct nc_sun_view *v)
{
    const struct nc_camera *c = &s->camera;
    struct nc_vec3 e1, e2;
    nc_v3_basis(sun, &e1, &e2);
    const double golden = M_PI * (3 - sqrt(5.0)), share = irr / SUN_POINTS;
    long lit = 0;
    for (int k0 = 0; k0 < SUN_POINTS; k0 += NC_PACKET) {
        struct nc_vec3 w[NC_PACKET];
        int occ[NC_PACKET] = {0};
        for (int i = 0; i < NC_PACKET; i++) {
            const int k = k0 + i;
            const double rho = tan(theta) * sqrt((k + 0.5) / SUN_POINTS), phi = k * golden;
            const struct nc_vec3 off = nc_v3_add(nc_v3_scale(e1, rho * cos(phi)), nc_v3_scale(e2, rho * sin(phi)));
            w[i] = nc_v3_unit(nc_v3_add(sun, off));
        }
        nc_rt_occluded_dirs(r->rt, w, NC_PACKET, INFINITY, occ);
        for (int i = 0; i < NC_PACKET; i++) {
            double x, y;
            if (occ[i] || nc_camera_project(c, nc_quat_rotate(nc_quat_conj(c->attitude_q), w[i]), &x, &y) < 0)
                continue;
            lit++;
            const long px = lround(x), py = lround(y);
            if (px < 0 || py < 0 || px >= f->width_px || py >= f->height_px)
                continue;
            const double omega = nc_camera_pixel_sr(c->fx_px, c->fy_px, nc_camera_ray(c, (double)px, (double)py));
            f->radiance[(size_t)py * f->width_px + (size_t)px] += (float)(share / omega);
            v->drawn_w_m2 += share;
        }
    }
    v->hidden = lit == 0;
    return 0;
}

int nc_render_sun(struct nc_renderer *r, const struct nc_scene *s, double near_deg, struct nc_frame *f,
                  struct nc_sun_view *v)
{
    const struct nc_camera *c = &s->camera;
    memset(v, 0, sizeof *v);
    struct nc_vec3 sun;
    double irr;
    nc_scene_sun_at(s, c->position_m, &sun, &irr);
    const double theta = nc_scene_sun_radius_from(s, c->position_m); /* seen from the camera */
    const struct nc_vec3 d = nc_quat_rotate(nc_quat_conj(c->attitude_q), sun); /* camera frame */
    const double off = acos(fmax(-1, fmin(1, d.z)));
    v->off_axis_deg = off * 180 / M_PI;
    /* the field's edge along the Sun's azimuth (behind the camera: the
     * widest half-angle): the sensor's, for what is reported, and the drawn
     * image's with the camera model's margin, for what is drawn (the PSF
     * spreads a disk in the margin into the edge pixels) */
    double half[2] = {0, 0};
    for (int w = 0; w < 2; w++) {
        const int m = w ? 0 : c->margin_px;
        if (d.x != 0 || d.y != 0)
            half[w] = edge_angle(c, m, d.x * c->fx_px, d.y * c->fy_px);
        if (d.z <= 0 || !(half[w] > 0))
            for (int k = 0; k < 4; k++)
                half[w] = fmax(half[w], edge_angle(c, m, k & 1 ? 1 : -1, k & 2 ? 1 : -1));
    }
    v->edge_deg = (off - theta - half[0]) * 180 / M_PI;
    v->in_field = v->edge_deg < 0;
    v->near_field = !v->in_field && v->edge_deg < near_deg;
    if (!(off - theta - half[1] < 0))
        return 0;
    /* The disk's pixels: around its projected centre, or the whole frame
     * when the centre does not project (a disk wider than the field). */
    double sx, sy;
    int x0 = 0, y0 = 0, x1 = f->width_px - 1, y1 = f->height_px - 1;
    if (nc_camera_project(c, d, &sx, &sy) == 0) {
        const double rpx = 2 * tan(theta) * fmax(c->fx_px, c->fy_px) + 2; /* distortion: a generous box */
        x0 = (int)fmax(0, floor(sx - rpx)), x1 = (int)fmin(x1, ceil(sx + rpx));
        y0 = (int)fmax(0, floor(sy - rpx)), y1 = (int)fmin(y1, ceil(sy + rpx));
    }
    int rc = nc_rt_update(r->rt, s);
    if (rc < 0)
        return rc;
    if (tan(theta) * fmax(c->fx_px, c->fy_px) < SUN_POINTS_PX)
        return sun_points(r, s, sun, theta, irr, f, v);
    /* a uniform disk of radiance L and angular radius theta gives the irradiance E = integral of L cos(alpha) over
     * it = pi L sin^2 theta (E / its solid angle drew it (1 + cos theta) / 2 too dim: 6 % at 0.01 au) */
    const double L = irr / (M_PI * sin(theta) * sin(theta)), cos_theta = cos(theta);
    enum { SUB = 8 };
    long lit = 0, seen = 0;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            /* the samples of this pixel inside the disk, traced 16 at a time */
            struct nc_vec3 w[NC_PACKET];
            int n = 0, open = 0;
            for (int k = 0; k <= SUB * SUB; k++) {
                if (k < SUB * SUB) {
                    struct nc_vec3 q = nc_v3_unit(
                        nc_camera_ray(c, x - 0.5 + (k % SUB + 0.5) / SUB, y - 0.5 + (k / SUB + 0.5) / SUB));
                    w[n] = nc_quat_rotate(c->attitude_q, q);
                    if (nc_v3_dot(w[n], sun) < cos_theta)
                        continue;
                    n++;
                }
                if (n == NC_PACKET || (k == SUB * SUB && n > 0)) {
                    int occ[NC_PACKET] = {0};
                    nc_rt_occluded_dirs(r->rt, w, n, INFINITY, occ);
                    for (int i = 0; i < n; i++)
                        open += !occ[i];
                    seen += n;
                    n = 0;
                }
            }
            if (open == 0)
                continue;
            lit += open;
            const double cov = (double)open / (SUB * SUB);
            const struct nc_vec3 dir = nc_camera_ray(c, x, y);
            const double omega = nc_camera_pixel_sr(c->fx_px, c->fy_px, dir);
            f->radiance[(size_t)y * f->width_px + x] += (float)(L * cov);
            /* the irradiance on a plane facing the Sun: cos alpha from the disk's centre */
            v->drawn_w_m2 += L * cov * omega * nc_v3_dot(nc_quat_rotate(c->attitude_q, nc_v3_unit(dir)), sun);
        }
    v->hidden = seen > 0 && lit == 0;
    return 0;
}

void nc_sun_view_warning(const struct nc_sun_view *v, char *buf, size_t len)
{
    if (v->in_field)
        snprintf(buf, len, "%s", v->hidden ? "sun in field, hidden by a body" : "sun in field");
    else if (v->near_field)
        snprintf(buf, len, "sun %.1f deg from the field", v->edge_deg);
    else if (len)
        buf[0] = 0;
}

void nc_sun_view_text(const struct nc_sun_view *v, char *buf, size_t len)
{
    char warning[80];
    nc_sun_view_warning(v, warning, sizeof warning);
    if (!warning[0]) {
        if (len)
            buf[0] = 0;
        return;
    }
    snprintf(buf, len, "off_axis_deg=%.4f edge_deg=%.4f in_field=%d hidden=%d warning=%s", v->off_axis_deg,
             v->edge_deg, v->in_field, v->hidden, warning);
}
