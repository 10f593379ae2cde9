/* camsys_config.c - the camera model from its configuration (camsys.h):
 * optics (aperture, passband, vignetting, PSF), the sensor's parameters,
 * and the per-pixel response and fixed patterns they imply. */
#include "camera/camsys.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/rng.h"
#include "core/error.h"

/* The most dark current a pixel may have at its temperature, e-/s: 1e9 (the
 * largest full well) in a microsecond; far more than any sensor, far less
 * than a float's range over an hour's exposure. */
#define DARK_MAX_E_S 1e15

/* Solar spectrum for tabulated passbands: a 5772 K black body (IAU 2015
 * nominal solar effective temperature), normalised to the total irradiance. */
#define SUN_TEFF_K 5772.0

static double planck_lambda(double lambda_m, double t_k)
{
    const double h = NC_PLANCK_J_S, c = NC_LIGHT_M_S, kb = 1.380649e-23;
    return 2.0 * h * c * c / pow(lambda_m, 5) / expm1(h * c / (lambda_m * kb * t_k));
}

/* A passband through the solar spectrum: band_fraction = int B T / int B,
 * wavelength = int B T lambda / int B T (the energy-weighted effective
 * wavelength, which turns in-band power into photons). row[i] = {lambda_m,
 * transmission}, linear between rows; n >= 2, wavelengths increasing. */
static void passband_integrate(const double (*row)[2], size_t n, struct nc_optics *o)
{
    double num = 0, den = 0, wsum = 0;
    /* Midpoints of a fine grid inside each table interval. */
    for (size_t i = 0; i + 1 < n; i++)
        for (int s = 0; s < 64; s++) {
            double a = (s + 0.5) / 64, l = row[i][0] + a * (row[i + 1][0] - row[i][0]);
            double t = row[i][1] + a * (row[i + 1][1] - row[i][1]), dl = (row[i + 1][0] - row[i][0]) / 64;
            double b = planck_lambda(l, SUN_TEFF_K) * dl;
            num += b * t;
            wsum += b * t * l;
        }
    /* The whole spectrum, 50 nm to 100 um, on a logarithmic grid. */
    for (int s = 0; s < 20000; s++) {
        double l0 = 5e-8 * pow(2000.0, s / 20000.0), l1 = 5e-8 * pow(2000.0, (s + 1) / 20000.0);
        den += planck_lambda(0.5 * (l0 + l1), SUN_TEFF_K) * (l1 - l0);
    }
    o->band_fraction = num / den;
    o->wavelength_m = num > 0 ? wsum / num : 0;
    /* Stars: photons through the band of a black body at each temperature,
     * per photon spectral flux at 545 nm (photons ~ B lambda). */
    for (int k = 0; k < NC_STAR_TEMPS; k++) {
        const double tk = NC_STAR_T_MIN * pow(NC_STAR_T_MAX / NC_STAR_T_MIN, k / (NC_STAR_TEMPS - 1.0));
        const double ref = planck_lambda(545e-9, tk) * 545e-9;
        double g = 0;
        for (size_t i = 0; i + 1 < n; i++)
            for (int s = 0; s < 64; s++) {
                double a = (s + 0.5) / 64, l = row[i][0] + a * (row[i + 1][0] - row[i][0]);
                double t = row[i][1] + a * (row[i + 1][1] - row[i][1]), dl = (row[i + 1][0] - row[i][0]) / 64;
                g += t * planck_lambda(l, tk) * l * dl;
            }
        o->star_g_m[k] = g / ref;
    }
    o->star_band = 1;
}

static int passband_table(struct nc_cfg_node *tab, struct nc_optics *o)
{
    size_t n = tab->nchild;
    if (n < 2)
        return nc_cfg_error(tab, "expected at least two [wavelength_m, transmission] rows");
    double prev = 0;
    double (*row)[2] = calloc(n, sizeof *row);
    if (!row)
        return nc_error(-ENOMEM, "out of memory");
    for (size_t i = 0; i < n; i++) {
        struct nc_cfg_node *r = tab->child[i];
        r->used = 1;
        if (r->kind != NC_CFG_SEQ || r->nchild != 2) {
            free(row);
            return nc_cfg_error(r, "expected [wavelength_m, transmission]");
        }
        for (int k = 0; k < 2; k++) {
            char *end;
            r->child[k]->used = 1;
            row[i][k] = strtod(r->child[k]->value ? r->child[k]->value : "", &end);
            if (!r->child[k]->value || *end || !isfinite(row[i][k])) {
                free(row);
                return nc_cfg_error(r->child[k], "expected a number");
            }
        }
        if (!(row[i][0] > 1e-8 && row[i][0] < 1e-4) || !(row[i][1] >= 0 && row[i][1] <= 1) || row[i][0] <= prev) {
            free(row);
            return nc_cfg_error(r, "expected increasing wavelengths in metres (1e-8..1e-4) and transmission in 0..1");
        }
        prev = row[i][0];
    }
    passband_integrate((const double (*)[2])row, n, o);
    free(row);
    if (!(o->band_fraction > 0))
        return nc_cfg_error(tab, "the passband transmits nothing");
    return 0;
}

/* `optics.passband`: either the band as it acts on the Sun (band_fraction
 * and wavelength_m, computed elsewhere), or its edges (from_m, to_m: a flat
 * filter, integrated here through the 5772 K solar spectrum). */
static int passband_map(struct nc_cfg_node *pb, struct nc_optics *o)
{
    double from = 0, to = 0;
    int hb, hw, hf, ht;
    if ((hb = nc_cfg_double(pb, "band_fraction", 0, 1, &o->band_fraction)) < 0)
        return hb;
    if ((hw = nc_cfg_double(pb, "wavelength_m", 1e-8, 1e-4, &o->wavelength_m)) < 0)
        return hw;
    if ((hf = nc_cfg_double(pb, "from_m", 1e-8, 1e-4, &from)) < 0)
        return hf;
    if ((ht = nc_cfg_double(pb, "to_m", 1e-8, 1e-4, &to)) < 0)
        return ht;
    if ((hb || hw) && (hf || ht))
        return nc_cfg_error(pb, "give either band_fraction and wavelength_m, or from_m and to_m (the band's edges), "
                                "not both");
    if (!(hf || ht))
        return 0;
    if (!hf || !ht)
        return nc_cfg_missing(pb, hf ? "to_m" : "from_m", "both edges of the band, in metres");
    if (!(to > from))
        return nc_cfg_key_error(pb, "to_m", "expected to_m > from_m, got %g <= %g", to, from);
    const double row[2][2] = {{from, 1}, {to, 1}};
    passband_integrate(row, 2, o);
    return 0;
}

static int optics_from_config(struct nc_cfg_node *m, double focal_length_m, struct nc_optics *o)
{
    int rc, hn, hd;
    double d = 0;
    o->f_number = 8.0;
    o->transmission = 1.0;
    o->band_fraction = 1.0;
    o->wavelength_m = 550e-9;
    o->vignetting = NC_VIGNETTING_COS4;
    if (!m)
        return 0;
    /* N >= 0.5: the irradiance L pi / (4 N^2) is at most pi L, a lens filling the hemisphere */
    if ((hn = nc_cfg_double(m, "f_number", 0.5, 1000, &o->f_number)) < 0)
        return hn;
    if ((hd = nc_cfg_double(m, "aperture_diameter_m", 1e-6, 100, &d)) < 0)
        return hd;
    if (hn && hd)
        return nc_cfg_key_error(m, "aperture_diameter_m", "give either f_number or aperture_diameter_m, not both");
    if (hd) {
        if (!(focal_length_m > 0))
            return nc_cfg_key_error(m, "aperture_diameter_m",
                                    "needs camera.focal_length_m (the camera gives fx_px); give f_number instead");
        o->f_number = focal_length_m / d;
        if (o->f_number < 0.5)
            return nc_cfg_key_error(m, "aperture_diameter_m", "an aperture of %g m on a %g m focal length is f/%.3g; "
                                    "no lens is faster than f/0.5", d, focal_length_m, o->f_number);
    }
    if ((rc = nc_cfg_double(m, "transmission", 0, 1, &o->transmission)) < 0)
        return rc;
    struct nc_cfg_node *pb, *tab;
    int hp = nc_cfg_map(m, "passband", &pb), ht = nc_cfg_seq(m, "passband_table", &tab);
    if (hp < 0 || ht < 0)
        return hp < 0 ? hp : ht;
    if (hp && ht)
        return nc_cfg_error(tab, "give either passband or passband_table, not both");
    if (hp && (rc = passband_map(pb, o)) < 0)
        return rc;
    if (ht && (rc = passband_table(tab, o)) < 0)
        return rc;
    struct nc_cfg_node *vig = nc_cfg_get(m, "vignetting");
    if (vig && vig->kind == NC_CFG_SCALAR) {
        static const char *const kinds[] = {"none", "cos4", NULL};
        int k;
        if (nc_cfg_enum(m, "vignetting", kinds, &k) < 0)
            return nc_cfg_error(vig, "expected none, cos4, or a table [[field_angle_deg, factor], ...]");
        o->vignetting = k == 0 ? NC_VIGNETTING_NONE : NC_VIGNETTING_COS4;
    } else if (vig) {
        if (vig->kind != NC_CFG_SEQ || vig->nchild < 1) /* one row: a constant factor */
            return nc_cfg_error(vig, "expected none, cos4, or a table [[field_angle_deg, factor], ...]");
        o->vignetting = NC_VIGNETTING_TABLE;
        o->nvig = (int)vig->nchild;
        o->vig_angle_rad = calloc(vig->nchild, sizeof(double));
        o->vig_factor = calloc(vig->nchild, sizeof(double));
        if (!o->vig_angle_rad || !o->vig_factor)
            return nc_error(-ENOMEM, "out of memory");
        for (size_t i = 0; i < vig->nchild; i++) {
            struct nc_cfg_node *r = vig->child[i];
            r->used = 1;
            double a, f;
            char *e1 = NULL, *e2 = NULL;
            if (r->kind != NC_CFG_SEQ || r->nchild != 2 || !r->child[0]->value || !r->child[1]->value ||
                ((a = strtod(r->child[0]->value, &e1)), *e1) || ((f = strtod(r->child[1]->value, &e2)), *e2) ||
                !(a >= 0 && a < 90) || !(f >= 0 && f <= 10) || (i && a * M_PI / 180 <= o->vig_angle_rad[i - 1]))
                return nc_cfg_error(r, "expected [field_angle_deg, factor] with increasing angles in 0..90 and a "
                                       "factor in 0..10");
            r->child[0]->used = r->child[1]->used = 1;
            o->vig_angle_rad[i] = a * M_PI / 180;
            o->vig_factor[i] = f;
        }
    }
    struct nc_cfg_node *psf;
    if ((rc = nc_cfg_map(m, "psf", &psf)) < 0)
        return rc;
    if (rc) {
        static const char *const kinds[] = {"none", "gaussian", "airy", "image", NULL};
        int k = 0;
        if ((rc = nc_cfg_enum(psf, "type", kinds, &k)) <= 0)
            return rc ? rc : nc_cfg_missing(psf, "type", "none, gaussian, airy or image");
        o->psf.kind = (enum nc_psf_kind)k;
        if (k == NC_PSF_GAUSSIAN) {
            if ((rc = nc_cfg_double(psf, "sigma_px", 0.01, 100, &o->psf.sigma_px)) <= 0)
                return rc ? rc : nc_cfg_missing(psf, "sigma_px", "the Gaussian's standard deviation in pixels");
        } else if (k == NC_PSF_IMAGE) {
            const char *file;
            if ((rc = nc_cfg_string(psf, "file", &file)) <= 0)
                return rc ? rc : nc_cfg_missing(psf, "file", "a kernel image (odd width and height)");
            char path[4096]; /* relative to the configuration file, as every file there */
            nc_cfg_resolve_path(nc_cfg_get(psf, "file"), file, path, sizeof path);
            if ((rc = nc_psf_image(path, &o->psf)) < 0) {
                char why[600];
                snprintf(why, sizeof why, "%s", nc_errmsg());
                return nc_cfg_key_error(psf, "file", "%s", why);
            }
        }
    }
    return 0;
}

static int sensor_from_config(struct nc_cfg_node *m, const struct nc_camera *geom, double pitch_m, struct nc_sensor *s)
{
    int rc;
    long v;
    memset(s, 0, sizeof *s);
    s->pixel_pitch_m = pitch_m;
    s->qe = 1.0;
    s->shot_noise = 1;
    s->dark_ref_temp_k = 293.15;
    s->dark_doubling_k = 6.0;
    s->temperature_k = s->dark_ref_temp_k;
    s->full_well_e = 1e5;
    s->gain_e_per_dn = 1.0;
    s->adc_bits = 16;
    s->seed = 1;
    s->cosmic_track_px = 5;
    s->cosmic_e_per_px = 1000;
    if (!m) { /* an ideal noise-free sensor; without a known pitch, no radiometry */
        s->shot_noise = 0;
        return 0;
    }
    static const char *const bools[] = {"false", "true", NULL};
    int b;
    if ((rc = nc_cfg_double(m, "pixel_pitch_m", 1e-8, 1e-2, &s->pixel_pitch_m)) < 0)
        return rc;
    /* One pitch for geometry and radiometry: the camera's (focal_length_m /
     * fx_px) when it has one. */
    if (rc && pitch_m > 0 && fabs(s->pixel_pitch_m - pitch_m) > 1e-9 * pitch_m)
        return nc_cfg_key_error(m, "pixel_pitch_m",
                                "%g m disagrees with the camera's pixel pitch %g m (camera.pixel_pitch_m, or "
                                "focal_length_m / fx_px); give the pitch once, in camera",
                                s->pixel_pitch_m, pitch_m);
    if (!(s->pixel_pitch_m > 0))
        return nc_cfg_missing(m, "pixel_pitch_m",
                              "the pixel pitch in metres: a camera given by fx_px has no pixel size, and the camera "
                              "model (read for every quantity) needs one: give sensor.pixel_pitch_m, or the camera's "
                              "focal_length_m and pixel_pitch_m");
    if ((rc = nc_cfg_double(m, "qe", 0, 1, &s->qe)) < 0)
        return rc;
    if ((rc = nc_cfg_enum(m, "shot_noise", bools, &b)) < 0)
        return rc;
    if (rc)
        s->shot_noise = b;
    if ((rc = nc_cfg_double(m, "dark_current_e_s", 0, 1e9, &s->dark_current_e_s)) < 0 ||
        (rc = nc_cfg_double(m, "dark_ref_temp_k", 1, 1000, &s->dark_ref_temp_k)) < 0 ||
        (rc = nc_cfg_double(m, "dark_doubling_k", 0.1, 1000, &s->dark_doubling_k)) < 0)
        return rc;
    s->temperature_k = s->dark_ref_temp_k;
    if ((rc = nc_cfg_double(m, "temperature_k", 1, 1000, &s->temperature_k)) < 0 ||
        (rc = nc_cfg_double(m, "dsnu_e_s", 0, 1e9, &s->dsnu_e_s)) < 0)
        return rc;
    if (s->dsnu_e_s > 0 && !(s->dark_current_e_s > 0))
        return nc_cfg_key_error(m, "dsnu_e_s", "a dark signal non-uniformity scales the mean dark current: "
                                               "give dark_current_e_s > 0 (or dsnu_e_s: 0)");
    if ((rc = nc_cfg_double(m, "prnu", 0, 1, &s->prnu)) < 0 ||
        (rc = nc_cfg_double(m, "hot_pixel_fraction", 0, 1, &s->hot_pixel_fraction)) < 0 ||
        (rc = nc_cfg_double(m, "hot_pixel_dark_e_s", 0, 1e9, &s->hot_pixel_dark_e_s)) < 0 ||
        (rc = nc_cfg_double(m, "read_noise_e", 0, 1e6, &s->read_noise_e)) < 0 ||
        (rc = nc_cfg_double(m, "full_well_e", 1, 1e9, &s->full_well_e)) < 0 ||
        (rc = nc_cfg_double(m, "gain_e_per_dn", 1e-6, 1e9, &s->gain_e_per_dn)) < 0 ||
        (rc = nc_cfg_double(m, "analog_gain_db", -60, 60, &s->analog_gain_db)) < 0 ||
        (rc = nc_cfg_double(m, "bias_dn", 0, 65535, &s->bias_dn)) < 0)
        return rc;
    /* the dark current at the sensor's temperature, hot pixels included */
    const double tscale = exp2((s->temperature_k - s->dark_ref_temp_k) / s->dark_doubling_k),
                 dark_max = (s->dark_current_e_s + s->hot_pixel_dark_e_s) * tscale;
    if (!(dark_max <= DARK_MAX_E_S))
        return nc_cfg_key_error(m, "temperature_k",
                                "the dark current at %g K (doubling every %g K from %g e-/s at %g K; hot pixels %g "
                                "e-/s) reaches %.3g e-/s a pixel: more than %g (a full well filled in a microsecond)",
                                s->temperature_k, s->dark_doubling_k, s->dark_current_e_s, s->dark_ref_temp_k,
                                s->hot_pixel_dark_e_s, dark_max, DARK_MAX_E_S);
    if ((rc = nc_cfg_enum(m, "blooming", bools, &b)) < 0)
        return rc;
    if (rc)
        s->blooming = b;
    if ((rc = nc_cfg_int(m, "adc_bits", 8, 16, &v)) < 0)
        return rc;
    if (rc)
        s->adc_bits = (int)v;
    if ((rc = nc_cfg_seed(m, "seed", &s->seed)) < 0)
        return rc;
    struct nc_cfg_node *cr;
    if ((rc = nc_cfg_map(m, "cosmic_rays", &cr)) < 0)
        return rc;
    if (rc && ((rc = nc_cfg_double(cr, "rate_cm2_s", 0, 1e6, &s->cosmic_rate_cm2_s)) < 0 ||
               (rc = nc_cfg_double(cr, "track_length_px", 0, 1e4, &s->cosmic_track_px)) < 0 ||
               (rc = nc_cfg_double(cr, "e_per_px", 0, 1e9, &s->cosmic_e_per_px)) < 0))
        return rc;
    static const char *const shutters[] = {"global", "rolling", NULL};
    int sh = 0;
    if ((rc = nc_cfg_enum(m, "shutter", shutters, &sh)) < 0)
        return rc;
    s->shutter = (enum nc_shutter)sh;
    if ((rc = nc_cfg_double(m, "line_time_s", 0, 1, &s->line_time_s)) < 0)
        return rc;
    if (s->shutter == NC_SHUTTER_ROLLING && rc == 0) /* 0 given: every row at once, as a global shutter */
        return nc_cfg_missing(m, "line_time_s", "the delay between successive rows of a rolling shutter, seconds");
    if (s->bias_dn > ldexp(1.0, s->adc_bits) - 1)
        return nc_cfg_key_error(m, "bias_dn", "bias %g DN does not fit a %d-bit ADC", s->bias_dn, s->adc_bits);
    (void)geom;
    return 0;
}

/* Vignetting factor at field angle theta (rad). */
static double vignette(const struct nc_optics *o, double theta)
{
    if (o->vignetting == NC_VIGNETTING_NONE)
        return 1.0;
    if (o->vignetting == NC_VIGNETTING_COS4) {
        double c = cos(theta);
        return c * c * c * c;
    }
    const double *a = o->vig_angle_rad, *f = o->vig_factor;
    int n = o->nvig;
    if (theta <= a[0])
        return f[0];
    if (theta >= a[n - 1])
        return f[n - 1];
    int i = 1;
    while (a[i] < theta)
        i++;
    double t = (theta - a[i - 1]) / (a[i] - a[i - 1]);
    return f[i - 1] + t * (f[i] - f[i - 1]);
}

/* exp(mu + sigma z), z standard normal, has mean 1 and relative rms cv. */
static void lognormal(double cv, double *mu, double *sigma)
{
    *sigma = sqrt(log1p(cv * cv));
    *mu = -0.5 * *sigma * *sigma;
}

int nc_camsys_from_config(struct nc_cfg_node *root, const struct nc_camera *geom, double focal_length_m,
                          struct nc_camsys *cs)
{
    memset(cs, 0, sizeof *cs);
    cs->width_px = geom->width_px;
    cs->height_px = geom->height_px;
    cs->exposure_s = 0.01;
    const struct nc_cfg_node *cam = nc_cfg_get(root, "camera");
    if (cam)
        nc_cfg_where(cam, cs->where, sizeof cs->where);
    else
        snprintf(cs->where, sizeof cs->where, "camera");
    struct nc_cfg_node *om = NULL, *sm = NULL, *em = NULL;
    int rc;
    if ((rc = nc_cfg_map(root, "optics", &om)) < 0 || (rc = nc_cfg_map(root, "sensor", &sm)) < 0 ||
        (rc = nc_cfg_map(root, "exposure", &em)) < 0)
        return rc;
    double pitch = focal_length_m > 0 ? focal_length_m / geom->fx_px : 0;
    if ((rc = optics_from_config(om, focal_length_m, &cs->optics)) < 0 ||
        (rc = sensor_from_config(sm, geom, pitch, &cs->sensor)) < 0)
        goto fail;
    if (em && (rc = nc_cfg_double(em, "time_s", 0, 3600, &cs->exposure_s)) < 0)
        goto fail;
    if (cs->optics.psf.kind == NC_PSF_GAUSSIAN)
        rc = nc_psf_gaussian(cs->optics.psf.sigma_px, &cs->optics.psf);
    else if (cs->optics.psf.kind == NC_PSF_AIRY)
        rc = nc_psf_airy(cs->optics.wavelength_m, cs->optics.f_number, cs->sensor.pixel_pitch_m, &cs->optics.psf);
    if (rc < 0)
        goto fail;

    /* A real lens spreads light from outside the field into the edge
     * pixels: the renderer draws margin_px more pixels on every side (the
     * PSF's half width), the PSF acts on that larger image, and the sensor
     * sees the middle. */
    cs->margin_px = cs->optics.psf.size > 1 ? cs->optics.psf.size / 2 : 0;
    double at[2], frac; /* the lens must be unfolded over the margin too: its light came from the other side */
    if ((rc = nc_camera_unfolded(geom, cs->margin_px, at, &frac)) > 0) {
        struct nc_cfg_node *psf = om ? nc_cfg_get(om, "psf") : NULL;
        rc = nc_cfg_error(psf ? psf : om ? om : root, "the PSF's margin (%d px around the image, drawn to spread "
                          "light from outside the field) reaches where camera.distortion folds over (%s pixel (%g, "
                          "%g)): its inverse is not unique there; a smaller PSF or a milder distortion",
                          cs->margin_px, rc == 1 ? "at" : "towards", at[0], at[1]);
        goto fail;
    }
    cs->render_width_px = cs->width_px + 2 * cs->margin_px;
    cs->render_height_px = cs->height_px + 2 * cs->margin_px;
    size_t n = (size_t)cs->width_px * (size_t)cs->height_px;
    size_t nr = (size_t)cs->render_width_px * (size_t)cs->render_height_px;
    cs->response = malloc(nr * sizeof(float));
    cs->prnu_map = malloc(n * sizeof(float));
    cs->dark_map = malloc(n * sizeof(float));
    for (int i = 0; i < 3 && cs->margin_px > 0; i++) /* the PSF's work buffers */
        if (!(cs->scratch[i] = malloc(nr * sizeof(float))))
            rc = -ENOMEM;
    if (!cs->response || !cs->prnu_map || !cs->dark_map || rc < 0) {
        rc = nc_error(-ENOMEM, "out of memory");
        goto fail;
    }
    const struct nc_optics *o = &cs->optics;
    const struct nc_sensor *s = &cs->sensor;
    /* Camera equation for an object at infinity: focal-plane irradiance
     * E = L tau pi / (4 N^2) V(theta); electrons/s = QE E A_pix lambda/(h c).
     * The pitch is along x (f / fx); a pixel is f / fy tall: A_pix = pitch^2 fx / fy. */
    cs->pixel_area_m2 = s->pixel_pitch_m * s->pixel_pitch_m * (geom->fx_px / geom->fy_px);
    double k = s->qe * o->band_fraction * o->transmission * M_PI / (4.0 * o->f_number * o->f_number) *
               cs->pixel_area_m2 * o->wavelength_m / (NC_PLANCK_J_S * NC_LIGHT_M_S);
    /* Dark current doubles every dark_doubling_k: the mean, the per-pixel
     * non-uniformity and the hot pixels alike (the pattern is the sensor's,
     * its scale the temperature's). DSNU is a log-normal factor of mean 1 and
     * relative rms dsnu_e_s / dark_current_e_s: never negative, so nothing is
     * clipped and the mean dark current follows the law at every temperature.
     * PRNU the same, of relative rms prnu (a normal factor 1 + prnu z was
     * clipped at 0: at prnu 1 the mean response was 1.087, the rms 0.87). */
    double tscale = exp2((s->temperature_k - s->dark_ref_temp_k) / s->dark_doubling_k);
    double dark = s->dark_current_e_s * tscale;
    double cv = s->dark_current_e_s > 0 ? s->dsnu_e_s / s->dark_current_e_s : 0;
    double ln_mu, ln_sigma, pr_mu, pr_sigma;
    lognormal(cv, &ln_mu, &ln_sigma);
    lognormal(s->prnu, &pr_mu, &pr_sigma);
    const int m = cs->margin_px;
    for (int y = 0; y < cs->render_height_px; y++)
        for (int x = 0; x < cs->render_width_px; x++) {
            struct nc_vec3 d = nc_camera_ray(geom, x - m, y - m);
            double theta = acos(d.z / nc_v3_norm(d));
            /* a distorted pixel sees the solid angle nc_camera_pixel_sr_at gives, not the pinhole's (1/fx fy
             * times cos^3, in k and V): flux is conserved (a barrel lens's edge pixels see more sky) */
            const double omega = geom->distorted ? nc_camera_pixel_sr_at(geom, x - m, y - m) /
                                                       nc_camera_pixel_sr(geom->fx_px, geom->fy_px, d)
                                                 : 1.0;
            cs->response[(size_t)y * (size_t)cs->render_width_px + (size_t)x] = (float)(k * vignette(o, theta) * omega);
        }
    for (int y = 0; y < cs->height_px; y++)
        for (int x = 0; x < cs->width_px; x++) {
            size_t p = (size_t)y * (size_t)cs->width_px + (size_t)x;
            /* Fixed patterns: keyed by the sensor seed only. */
            double u[4], z1, z2;
            nc_rng4(s->seed, NC_RNG_FIXED_PATTERN, 0, (uint32_t)p, 0, u);
            nc_normal2(u[0], u[1], &z1, &z2);
            cs->prnu_map[p] = (float)exp(pr_mu + pr_sigma * z1);
            double dp = dark * exp(ln_mu + ln_sigma * z2);
            if (u[2] < s->hot_pixel_fraction)
                dp += s->hot_pixel_dark_e_s * tscale;
            cs->dark_map[p] = (float)dp;
        }
    return 0;
fail:
    nc_camsys_free(cs);
    return rc;
}

void nc_camsys_free(struct nc_camsys *cs)
{
    free(cs->response);
    free(cs->prnu_map);
    free(cs->dark_map);
    for (int i = 0; i < 3; i++)
        free(cs->scratch[i]);
    free(cs->optics.vig_angle_rad);
    free(cs->optics.vig_factor);
    nc_psf_free(&cs->optics.psf);
    memset(cs, 0, sizeof *cs);
}

void nc_camsys_render_camera(const struct nc_camsys *cs, const struct nc_camera *geom, struct nc_camera *out)
{
    struct nc_camera c = *geom;
    c.width_px = cs->render_width_px;
    c.height_px = cs->render_height_px;
    c.cx_px += cs->margin_px;
    c.cy_px += cs->margin_px;
    c.margin_px = cs->margin_px;
    *out = c;
}

int nc_camsys_check_sections(struct nc_cfg *cfg)
{
    static const char *const sections[] = {"optics", "sensor", "exposure"};
    int rc = 0;
    for (int i = 0; i < 3 && rc >= 0; i++)
        rc = nc_cfg_check_unused_in(cfg, nc_cfg_get(cfg->root, sections[i]));
    return rc;
}
