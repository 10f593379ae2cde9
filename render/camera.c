/* camera.c - reading the camera section of a scene configuration. */
#include "render/camera.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "core/pose.h"
#include "core/sumfile.h"

/* camera.sumfile: intrinsics from an SPC SUM file (core/sumfile.h). The
 * natural view is rendered with +X along CX and +Y along CY; a negative K11
 * or K22 mirrors the stored image, which the writers apply (flip_*). */
static int sumfile_intrinsics(struct nc_cfg_node *map, struct nc_camera *c, struct nc_sumfile *sum)
{
    static const char *const own[] = {"width_px", "height_px", "focal_length_m", "pixel_pitch_m", "fx_px",
                                      "fy_px", "cx_px", "cy_px", "position_m", "attitude_q", "look_at_m", "up"};
    for (size_t i = 0; i < sizeof own / sizeof own[0]; i++)
        if (nc_cfg_get(map, own[i]))
            return nc_cfg_key_error(map, own[i], "the SUM file (camera.sumfile) sets the size, intrinsics "
                                                 "and pose: remove %s", own[i]);
    const struct nc_cfg_node *node = nc_cfg_get(map, "sumfile");
    char path[4096], why[600];
    nc_cfg_resolve_path(node, node->value, path, sizeof path);
    if (nc_sumfile_read(path, sum) < 0) {
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_cfg_error(node, "%s", why);
    }
    const double *k = sum->k; /* K12, K21: a skew of 0.05 px at most (nc_sumfile_read), taken as none */
    c->width_px = sum->npx;
    c->height_px = sum->nln;
    c->fx_px = sum->mmfl_mm * fabs(k[0]);
    c->fy_px = sum->mmfl_mm * fabs(k[4]);
    c->focal_length_m = sum->mmfl_mm * 1e-3;
    c->flip_cols = k[0] < 0;
    c->flip_rows = k[4] < 0;
    /* 1-based centres to 0-based; mirrored: x_stored = W - 1 - x_rendered. */
    c->cx_px = c->flip_cols ? sum->npx - sum->ctr[0] : sum->ctr[0] - 1;
    c->cy_px = c->flip_rows ? sum->nln - sum->ctr[1] : sum->ctr[1] - 1;
    c->from_sumfile = 1;
    c->sumfile_sun = nc_v3_unit(nc_v3(sum->sz[0], sum->sz[1], sum->sz[2]));
    snprintf(c->sumfile_utc, sizeof c->sumfile_utc, "%s", sum->utc);
    return 0;
}

static void distort(const struct nc_camera *c, double x, double y, double *xd, double *yd, double J[2][2]);

static int camera_read(struct nc_cfg_node *map, struct nc_camera *c, struct nc_sumfile *sum)
{
    int rc;
    memset(c, 0, sizeof *c);
    long w = 0, h = 0;
    if (nc_cfg_get(map, "sumfile")) {
        if ((rc = sumfile_intrinsics(map, c, sum)) < 0)
            return rc;
        goto distortion;
    }
    if ((rc = nc_cfg_int(map, "width_px", 1, 16384, &w)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "width_px", "image width in pixels");
    if ((rc = nc_cfg_int(map, "height_px", 1, 16384, &h)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "height_px", "image height in pixels");
    c->width_px = (int)w;
    c->height_px = (int)h;

    double f = 0, pitch = 0, fx = 0, fy = 0;
    int hf, hp, hfx, hfy;
    if ((hf = nc_cfg_double(map, "focal_length_m", 1e-6, 100, &f)) < 0 ||
        (hp = nc_cfg_double(map, "pixel_pitch_m", 1e-8, 1e-2, &pitch)) < 0 ||
        (hfx = nc_cfg_double(map, "fx_px", NC_FOCAL_MIN_PX, NC_FOCAL_MAX_PX, &fx)) < 0 ||
        (hfy = nc_cfg_double(map, "fy_px", NC_FOCAL_MIN_PX, NC_FOCAL_MAX_PX, &fy)) < 0)
        return hf < 0 ? hf : hp < 0 ? hp : hfx < 0 ? hfx : hfy;
    if ((hf || hp) && (hfx || hfy))
        return nc_cfg_key_error(map, hf ? "focal_length_m" : "pixel_pitch_m",
                                "give either focal_length_m and pixel_pitch_m, or fx_px and fy_px, not both");
    if (hf || hp) {
        if (!hf || !hp)
            return nc_cfg_missing(map, hf ? "pixel_pitch_m" : "focal_length_m",
                                  "focal_length_m and pixel_pitch_m together (metres)");
        c->fx_px = c->fy_px = f / pitch;
        c->focal_length_m = f;
    } else if (hfx || hfy) {
        if (!hfx || !hfy)
            return nc_cfg_missing(map, hfx ? "fy_px" : "fx_px", "fx_px and fy_px together (pixels)");
        c->fx_px = fx;
        c->fy_px = fy;
    } else {
        return nc_cfg_missing(map, "focal_length_m", "focal_length_m and pixel_pitch_m, or fx_px and fy_px");
    }
    c->cx_px = 0.5 * (c->width_px - 1);
    c->cy_px = 0.5 * (c->height_px - 1);
    if ((rc = nc_cfg_double(map, "cx_px", -NC_PRINCIPAL_MAX_PX, NC_PRINCIPAL_MAX_PX, &c->cx_px)) < 0 ||
        (rc = nc_cfg_double(map, "cy_px", -NC_PRINCIPAL_MAX_PX, NC_PRINCIPAL_MAX_PX, &c->cy_px)) < 0)
        return rc;

distortion:;
    struct nc_cfg_node *dist;
    if ((rc = nc_cfg_map(map, "distortion", &dist)) < 0)
        return rc;
    if (rc) {
        const char *keys[] = {"k1", "k2", "k3", "p1", "p2"};
        double *vals[] = {&c->k1, &c->k2, &c->k3, &c->p1, &c->p2};
        for (int i = 0; i < 5; i++)
            if ((rc = nc_cfg_double(dist, keys[i], -100, 100, vals[i])) < 0)
                return rc;
        c->distorted = c->k1 != 0 || c->k2 != 0 || c->k3 != 0 || c->p1 != 0 || c->p2 != 0;
        double at[2], frac;
        if ((rc = nc_camera_unfolded(c, 0, at, &frac)) > 0)
            return rc == 1 ? nc_cfg_error(dist, "this distortion cannot be inverted at pixel (%g, %g): the lens "
                                                "model folds over inside the image", at[0], at[1])
                           : nc_cfg_error(dist, "this distortion folds over inside the image (towards pixel (%g, "
                                                "%g), at %.0f %% of the way): its inverse is not unique",
                                          at[0], at[1], 100 * frac);
    }
    return 0;
}

int nc_camera_intrinsics_from_config(struct nc_cfg_node *map, struct nc_camera *c)
{
    struct nc_sumfile sum;
    return camera_read(map, c, &sum);
}

int nc_camera_from_config(struct nc_cfg_node *map, struct nc_camera *c)
{
    struct nc_sumfile sum;
    int rc = camera_read(map, c, &sum);
    if (rc < 0)
        return rc;
    if ((rc = nc_cfg_vec3_max(map, "velocity_m_s", NC_SPEED_MAX_M_S, "m/s", NC_SPEED_MAX_TEXT, &c->velocity_m_s)) < 0 ||
        (rc = nc_cfg_vec3(map, "angular_velocity_rad_s", &c->angular_velocity_rad_s)) < 0)
        return rc;
    if (c->from_sumfile) { /* the pose in bodies[0]'s frame (the scene moves it with that body) */
        c->position_m = nc_v3(-1e3 * sum.scobj_km[0], -1e3 * sum.scobj_km[1], -1e3 * sum.scobj_km[2]);
        c->attitude_q = sum.q;
        if (!(nc_v3_norm(c->position_m) <= NC_CAMERA_MAX_M)) /* SCOBJ in metres read as km, say */
            return nc_cfg_key_error(map, "sumfile", "SCOBJ puts the camera %g m from bodies[0]'s centre, beyond "
                                    NC_CAMERA_MAX_TEXT " (SCOBJ is in km)", nc_v3_norm(c->position_m));
        return 0;
    }
    if ((rc = nc_cfg_vec3_max(map, "position_m", NC_CAMERA_MAX_M, "m from the scene's origin", NC_CAMERA_MAX_TEXT,
                              &c->position_m)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "position_m", "[x, y, z] in metres, scene frame");
    struct nc_vec3 target, up = nc_v3(0, 0, 1);
    int hq = nc_cfg_quat(map, "attitude_q", &c->attitude_q);
    int ht = nc_cfg_vec3(map, "look_at_m", &target);
    int hu = nc_cfg_vec3(map, "up", &up);
    if (hq < 0 || ht < 0 || hu < 0)
        return hq < 0 ? hq : ht < 0 ? ht : hu;
    if (hq && ht)
        return nc_cfg_key_error(map, "look_at_m", "give either attitude_q or look_at_m, not both");
    if (hu && !ht)
        return nc_cfg_key_error(map, "up", "'up' only goes with look_at_m");
    if (ht) {
        if ((rc = nc_quat_look_at(c->position_m, target, up, &c->attitude_q)) < 0) {
            char why[256];
            snprintf(why, sizeof why, "%s", nc_errmsg());
            /* the target on the camera is look_at_m's fault; an 'up' zero or along the sight, up's if given */
            const int up_at_fault = hu && !nc_v3_is_zero(nc_v3_sub(target, c->position_m));
            return nc_cfg_key_error(map, up_at_fault ? "up" : "look_at_m", "%s (from position_m to look_at_m)", why);
        }
    } else if (!hq) {
        return nc_cfg_missing(map, "attitude_q", "[w, x, y, z] camera-to-scene, or look_at_m");
    }
    return 0;
}

/* Distort normalised coordinates (x, y) -> (xd, yd), with the Jacobian. */
static void distort(const struct nc_camera *c, double x, double y, double *xd, double *yd, double J[2][2])
{
    double r2 = x * x + y * y, rad = 1 + r2 * (c->k1 + r2 * (c->k2 + r2 * c->k3));
    double drad = c->k1 + r2 * (2 * c->k2 + 3 * c->k3 * r2); /* d rad / d r2 */
    *xd = x * rad + 2 * c->p1 * x * y + c->p2 * (r2 + 2 * x * x);
    *yd = y * rad + c->p1 * (r2 + 2 * y * y) + 2 * c->p2 * x * y;
    if (J) {
        J[0][0] = rad + 2 * x * x * drad + 2 * c->p1 * y + 6 * c->p2 * x;
        J[0][1] = 2 * x * y * drad + 2 * c->p1 * x + 2 * c->p2 * y;
        J[1][0] = 2 * x * y * drad + 2 * c->p1 * x + 2 * c->p2 * y;
        J[1][1] = rad + 2 * y * y * drad + 6 * c->p1 * y + 2 * c->p2 * x;
    }
}

int nc_camera_unfolded(const struct nc_camera *c, int margin_px, double at[2], double *frac)
{
    if (!c->distorted)
        return 0;
    /* The area samples reach: the pixels' edges, margin_px pixels beyond
     * the image on every side; its corners and edges' midpoints. */
    const double lo = -margin_px - 0.5, hx = c->width_px - 0.5 + margin_px, hy = c->height_px - 0.5 + margin_px;
    const double pts[8][2] = {{lo, lo}, {hx, lo}, {lo, hy}, {hx, hy}, {0.5 * (lo + hx), lo}, {0.5 * (lo + hx), hy},
                              {lo, 0.5 * (lo + hy)}, {hx, 0.5 * (lo + hy)}};
    for (int i = 0; i < 8; i++) {
        at[0] = pts[i][0], at[1] = pts[i][1];
        double x, y;
        /* the round trip: the inverse unique at that point ... */
        const struct nc_vec3 d = nc_camera_ray(c, pts[i][0], pts[i][1]);
        if (nc_camera_project(c, d, &x, &y) < 0 || fabs(x - pts[i][0]) > 1e-6 || fabs(y - pts[i][1]) > 1e-6)
            return 1;
        /* ... and unfolded on the way there: the round trip holds for any
         * root, also one beyond a fold (k1 -1.2, k2 0.5 over a 64 px frame
         * of fx 44: pixels 48 and 49 of the middle row saw radii 0.55 and
         * 1.22), so along the ray from the centre the map's Jacobian stays
         * positive */
        for (int k = 1; k <= 512; k++) {
            double xd, yd, J[2][2];
            distort(c, d.x * k / 512, d.y * k / 512, &xd, &yd, J);
            if (!(J[0][0] * J[1][1] - J[0][1] * J[1][0] > 0)) {
                *frac = k / 512.0;
                return 2;
            }
        }
    }
    return 0;
}

struct nc_vec3 nc_camera_ray(const struct nc_camera *c, double px, double py)
{
    double xd = (px - c->cx_px) / c->fx_px, yd = (py - c->cy_px) / c->fy_px;
    if (!c->distorted)
        return nc_v3(xd, yd, 1.0);
    /* Newton on distort(x, y) = (xd, yd), from the distorted point. */
    double x = xd, y = yd;
    for (int it = 0; it < 50; it++) {
        double fx, fy, J[2][2];
        distort(c, x, y, &fx, &fy, J);
        double ex = fx - xd, ey = fy - yd, det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
        if (!(fabs(det) > 1e-300))
            break;
        double dx = (J[1][1] * ex - J[0][1] * ey) / det, dy = (J[0][0] * ey - J[1][0] * ex) / det;
        x -= dx;
        y -= dy;
        if (fabs(dx) + fabs(dy) < 1e-15 * (1 + fabs(x) + fabs(y)))
            break;
    }
    return nc_v3(x, y, 1.0);
}

double nc_camera_pixel_sr_at(const struct nc_camera *c, double px, double py)
{
    const struct nc_vec3 d = nc_camera_ray(c, px, py);
    double det = 1;
    if (c->distorted) { /* a pixel's area in the undistorted plane is 1 / (fx fy det J) */
        double xd, yd, J[2][2];
        distort(c, d.x, d.y, &xd, &yd, J);
        det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    }
    return nc_camera_pixel_sr(c->fx_px, c->fy_px, d) / det;
}

int nc_camera_project(const struct nc_camera *c, struct nc_vec3 d, double *px, double *py)
{
    if (!(d.z > 0))
        return -1;
    double xd, yd;
    distort(c, d.x / d.z, d.y / d.z, &xd, &yd, NULL);
    *px = c->fx_px * xd + c->cx_px;
    *py = c->fy_px * yd + c->cy_px;
    return 0;
}
