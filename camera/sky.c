/* sky.c - stars through the camera model (sky.h). */
#include "camera/sky.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

#define V0_PHOTONS_S_M2_M 9.96e16 /* V = 0 at 545 nm: 3.631e-11 W m^-2 nm^-1 / (h c / 545 nm), per metre */
#define JYEAR_S (365.25 * 86400.0)

double nc_star_teff_k(double b_v)
{
    const double x = fmin(fmax(b_v, -0.4), 2.0); /* the formula's range */
    return 4600.0 * (1.0 / (0.92 * x + 1.7) + 1.0 / (0.92 * x + 0.62));
}

/* star_g_m at temperature t, linear in log t between the table's rows. */
static double band_g(const struct nc_optics *o, double t_k)
{
    double u = log(fmin(fmax(t_k, NC_STAR_T_MIN), NC_STAR_T_MAX) / NC_STAR_T_MIN) /
               log(NC_STAR_T_MAX / NC_STAR_T_MIN) * (NC_STAR_TEMPS - 1);
    int k = (int)fmin(floor(u), NC_STAR_TEMPS - 2);
    double a = u - k;
    return (1 - a) * o->star_g_m[k] + a * o->star_g_m[k + 1];
}

double nc_star_band_photons(const struct nc_optics *o, double v_mag, double b_v)
{
    return V0_PHOTONS_S_M2_M * pow(10.0, -0.4 * v_mag) * band_g(o, nc_star_teff_k(b_v));
}

int nc_sky_from_config(struct nc_cfg *cfg, struct nc_sky *sky)
{
    memset(sky, 0, sizeof *sky);
    struct nc_cfg_node *m;
    int rc = nc_cfg_map(cfg->root, "stars", &m);
    if (rc <= 0)
        return rc;
    struct nc_cfg_node *cat = nc_cfg_get(m, "catalogue");
    const char *file = NULL;
    if ((rc = nc_cfg_string(m, "catalogue", &file)) < 0)
        return rc;
    if (!file)
        return nc_cfg_missing(m, "catalogue", "a NavCam star index (`navcam stars index`, docs/stars.md)");
    nc_cfg_resolve_path(cat, file, sky->path, sizeof sky->path);
    sky->limit_auto = 1;
    struct nc_cfg_node *lim = nc_cfg_get(m, "limit_mag");
    if (lim && !(lim->kind == NC_CFG_SCALAR && lim->value && !strcmp(lim->value, "auto"))) {
        sky->limit_auto = 0;
        char *end = NULL;
        if (lim->kind == NC_CFG_SCALAR && lim->value && (strtod(lim->value, &end), end == lim->value || *end))
            return nc_cfg_key_error(m, "limit_mag", "expected auto or a magnitude in -30..30, got '%s'", lim->value);
        if ((rc = nc_cfg_double(m, "limit_mag", -30, 30, &sky->limit_mag)) < 0)
            return rc;
    }
    sky->epoch_jyear = 2000.0;
    if ((rc = nc_cfg_double(m, "epoch_jyear", 1000, 3000, &sky->epoch_jyear)) < 0 ||
        (rc = nc_cfg_vec3(m, "observer_velocity_m_s", &sky->observer_velocity_m_s)) < 0)
        return rc;
    if (!(nc_v3_norm(sky->observer_velocity_m_s) < 0.01 * 299792458.0))
        return nc_cfg_key_error(m, "observer_velocity_m_s", "expected a speed below 1 %% of light's");
    if ((rc = nc_cfg_check_unused_in(cfg, m)) < 0) /* its one reader: a typo is not a default */
        return rc;
    nc_cfg_where(m, sky->where, sizeof sky->where);
    if ((rc = nc_star_cat_load(sky->path, &sky->cat)) < 0) {
        char why[512];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_cfg_error(cat, "%s", why);
    }
    sky->on = 1;
    return 0;
}

void nc_sky_free(struct nc_sky *sky)
{
    nc_star_cat_free(&sky->cat);
    free(sky->dir);
    free(sky->e_w_m2);
    free(sky->e_per_s);
    free(sky->pts);
    memset(sky, 0, sizeof *sky);
}

int nc_sky_prepare(struct nc_sky *sky, const struct nc_camsys *cs, const struct nc_camera *geom)
{
    if (!sky->on)
        return 0;
    const struct nc_optics *o = &cs->optics;
    if (!o->star_band)
        return nc_error(NC_ECONFIG, "%s: the camera's passband needs its shape (optics.passband {from_m, to_m} "
                                    "or optics.passband_table), not only band_fraction and wavelength_m", sky->where);
    if (!(cs->sensor.pixel_pitch_m > 0 && geom->fx_px > 0))
        return nc_error(NC_ECONFIG, "%s: their light needs the aperture's area: give camera.focal_length_m with "
                                    "camera.pixel_pitch_m (or sensor.pixel_pitch_m) and optics.f_number", sky->where);
    const size_t n = sky->cat.n;
    free(sky->e_w_m2);
    free(sky->e_per_s);
    sky->e_w_m2 = malloc(n * sizeof *sky->e_w_m2);
    sky->e_per_s = malloc(n * sizeof *sky->e_per_s);
    if (!sky->dir)
        sky->dir = malloc(n * sizeof *sky->dir), sky->dir_jyear = NAN;
    if (!sky->pts)
        sky->pts = malloc(n * sizeof *sky->pts);
    if (!sky->e_w_m2 || !sky->e_per_s || !sky->dir || !sky->pts)
        return nc_error(-ENOMEM, "out of memory");
    /* the aperture's area from the focal length (fx times the pitch) and the f-number */
    const double hc = NC_PLANCK_J_S * NC_LIGHT_M_S, f_m = geom->fx_px * cs->sensor.pixel_pitch_m;
    const double area = M_PI * f_m * f_m / (4 * o->f_number * o->f_number);
    sky->aperture_m2 = area;
    /* over the colours stars are drawn with (B-V clamped to -0.4..2.0):
     * band_g is linear between the table's rows, so its largest value on
     * that range is at an end or at a row within it */
    const double t_red = nc_star_teff_k(2.0), t_blue = nc_star_teff_k(-0.4);
    sky->g_max_m = fmax(band_g(o, t_red), band_g(o, t_blue));
    for (int k = 0; k < NC_STAR_TEMPS; k++) {
        const double t_k = NC_STAR_T_MIN * pow(NC_STAR_T_MAX / NC_STAR_T_MIN, (double)k / (NC_STAR_TEMPS - 1));
        if (t_k > t_red && t_k < t_blue)
            sky->g_max_m = fmax(sky->g_max_m, o->star_g_m[k]);
    }
    for (size_t i = 0; i < n; i++) {
        const double ph = nc_star_band_photons(o, sky->cat.star[i].v_mag, sky->cat.star[i].b_v);
        sky->e_w_m2[i] = ph * hc / o->wavelength_m / o->band_fraction;
        sky->e_per_s[i] = ph * area * o->transmission * cs->sensor.qe;
    }
    return 0;
}

double nc_sky_limit_mag(const struct nc_sky *sky, const struct nc_camsys *cs, double exposure_s)
{
    if (!sky->limit_auto)
        return sky->limit_mag;
    const struct nc_sensor *sn = &cs->sensor;
    const double e0 = V0_PHOTONS_S_M2_M * sky->g_max_m * sky->aperture_m2 * cs->optics.transmission * sn->qe * exposure_s;
    const double dark_e_s = sn->dark_current_e_s * exp2((sn->temperature_k - sn->dark_ref_temp_k) / sn->dark_doubling_k);
    const double noise = sqrt(sn->read_noise_e * sn->read_noise_e + dark_e_s * exposure_s);
    const double thr = fmax(0.1 * noise, 0.05 / nc_camsys_dn_per_e(cs));
    return e0 > 0 ? 2.5 * log10(e0 / thr) : -30;
}

int nc_sky_draw(struct nc_sky *sky, struct nc_renderer *r, const struct nc_camsys *cs, const struct nc_scene *s,
                double t_sim_s, double exposure_s, struct nc_frame *f, struct nc_sky_stats *st)
{
    memset(st, 0, sizeof *st);
    if (!sky->on)
        return 0;
    const struct nc_camera *c = &s->camera;
    st->limit_mag = nc_sky_limit_mag(sky, cs, exposure_s);
    const size_t n = nc_star_cat_count_to(&sky->cat, st->limit_mag);
    /* Directions at the frame's epoch rounded to 1e-4 year (53 min), so
     * that they are a function of the frame's time alone (not of the frames
     * drawn before) and recomputed at most that often: Barnard's star, the
     * fastest (10.4 arcsec/yr), moves 2.5e-9 rad in half a step. */
    const double jyear = 1e-4 * nearbyint((sky->epoch_jyear + t_sim_s / JYEAR_S) / 1e-4);
    if (!(jyear == sky->dir_jyear)) {
        for (size_t i = 0; i < sky->cat.n; i++)
            sky->dir[i] = nc_star_direction(&sky->cat.star[i], sky->cat.epoch_jyear, jyear);
        sky->dir_jyear = jyear;
    }
    /* Candidates: within the cone around the boresight that holds the
     * frame's corners, grown by the turn over the exposure and a rolling
     * shutter's rows, the aberration (v / c) and two pixels. */
    const struct nc_vec3 z = nc_quat_rotate(c->attitude_q, nc_v3(0, 0, 1));
    double half = 0;
    const double cx[2] = {-0.5, c->width_px - 0.5}, cy[2] = {-0.5, c->height_px - 0.5};
    for (int k = 0; k < 4; k++) {
        struct nc_vec3 d = nc_v3_unit(nc_camera_ray(c, cx[k & 1], cy[k >> 1]));
        half = fmax(half, acos(fmin(1, d.z)));
    }
    const struct nc_vec3 v = nc_v3_add(sky->observer_velocity_m_s, c->velocity_m_s);
    if (!(nc_v3_norm(v) < NC_LIGHT_M_S)) /* each is within its limit, their sum need not be */
        return nc_error(NC_ERANGE, "stars: the camera's velocity and observer_velocity_m_s add up to %.10g m/s, not "
                        "under the speed of light", nc_v3_norm(v));
    const double rows_s = cs->sensor.shutter == NC_SHUTTER_ROLLING ? cs->sensor.line_time_s * c->height_px : 0;
    half += 0.5 * nc_v3_norm(c->angular_velocity_rad_s) * (exposure_s + rows_s) + 1.1 * nc_v3_norm(v) / NC_LIGHT_M_S +
            2.0 / fmin(c->fx_px, c->fy_px);
    const double cmin = half < M_PI ? cos(half) : -1;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (nc_v3_dot(sky->dir[i], z) < cmin)
            continue;
        sky->pts[m++] = /* at infinity, no I/F */
            (struct nc_point_source){.dir = nc_aberrate(sky->dir[i], v), .irradiance_w_m2 = sky->e_w_m2[i]};
    }
    const double line_s = cs->sensor.shutter == NC_SHUTTER_ROLLING ? cs->sensor.line_time_s : 0;
    long hidden = 0, drawn = nc_render_points(r, s, exposure_s, line_s, sky->pts, m, 1, f, &hidden);
    if (drawn < 0)
        return (int)drawn;
    st->considered = (long)m;
    st->drawn = drawn;
    st->hidden = hidden;
    return 0;
}
