/* camsys.c - optics and detector: configuration, the per-pixel response and
 * fixed patterns, and the radiance -> electrons -> DN chain (camsys.h). */
#include "camsys.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "rng.h"
#include "vmath.h"

/* Solar spectrum for tabulated passbands: a 5772 K black body (IAU 2015
 * nominal solar effective temperature), normalised to the total irradiance. */
#define SUN_TEFF_K 5772.0

static double planck_lambda(double lambda_m, double t_k)
{
    const double h = NC_PLANCK_J_S, c = NC_LIGHT_M_S, kb = 1.380649e-23;
    return 2.0 * h * c * c / pow(lambda_m, 5) / expm1(h * c / (lambda_m * kb * t_k));
}

/* band_fraction = int B T / int B; wavelength = int B T lambda / int B T. */
static int passband_table(struct nc_cfg_node *tab, struct nc_optics *o)
{
    size_t n = tab->nchild;
    if (n < 2)
        return nc_cfg_error(tab, "expected at least two [wavelength_m, transmission] rows");
    double prev = 0, num = 0, den = 0, wsum = 0;
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
    /* Trapezoids on a fine grid inside each table interval. */
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
    free(row);
    if (!(num > 0))
        return nc_cfg_error(tab, "the passband transmits nothing");
    o->band_fraction = num / den;
    o->wavelength_m = wsum / num;
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
    if ((hn = nc_cfg_double(m, "f_number", 0.3, 1000, &o->f_number)) < 0)
        return hn;
    if ((hd = nc_cfg_double(m, "aperture_diameter_m", 1e-6, 100, &d)) < 0)
        return hd;
    if (hn && hd)
        return nc_cfg_error(nc_cfg_get(m, "aperture_diameter_m"), "give either f_number or aperture_diameter_m, not both");
    if (hd) {
        if (!(focal_length_m > 0))
            return nc_cfg_error(nc_cfg_get(m, "aperture_diameter_m"),
                                "needs camera.focal_length_m (the camera gives fx_px); give f_number instead");
        o->f_number = focal_length_m / d;
    }
    if ((rc = nc_cfg_double(m, "transmission", 0, 1, &o->transmission)) < 0)
        return rc;
    struct nc_cfg_node *pb, *tab;
    int hp = nc_cfg_map(m, "passband", &pb), ht = nc_cfg_seq(m, "passband_table", &tab);
    if (hp < 0 || ht < 0)
        return hp < 0 ? hp : ht;
    if (hp && ht)
        return nc_cfg_error(tab, "give either passband or passband_table, not both");
    if (hp && ((rc = nc_cfg_double(pb, "band_fraction", 0, 1, &o->band_fraction)) < 0 ||
               (rc = nc_cfg_double(pb, "wavelength_m", 1e-8, 1e-4, &o->wavelength_m)) < 0))
        return rc;
    if (ht && (rc = passband_table(tab, o)) < 0)
        return rc;
    struct nc_cfg_node *vig = nc_cfg_get(m, "vignetting");
    if (vig && vig->kind == NC_CFG_SCALAR) {
        static const char *const kinds[] = {"none", "cos4", NULL};
        int k;
        if ((rc = nc_cfg_enum(m, "vignetting", kinds, &k)) < 0)
            return rc;
        o->vignetting = k == 0 ? NC_VIGNETTING_NONE : NC_VIGNETTING_COS4;
    } else if (vig) {
        if (vig->kind != NC_CFG_SEQ || vig->nchild < 2)
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
                return nc_cfg_error(r, "expected [field_angle_deg, factor] with increasing angles in 0..90");
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
            if ((rc = nc_psf_image(file, &o->psf)) < 0) {
                char why[600];
                snprintf(why, sizeof why, "%s", nc_errmsg());
                return nc_cfg_error(nc_cfg_get(psf, "file"), "%s", why);
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
    if (!(s->pixel_pitch_m > 0))
        return nc_cfg_missing(m, "pixel_pitch_m", "the pixel pitch in metres (the camera gives fx_px)");
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
        (rc = nc_cfg_double(m, "dsnu_e_s", 0, 1e9, &s->dsnu_e_s)) < 0 ||
        (rc = nc_cfg_double(m, "prnu", 0, 1, &s->prnu)) < 0 ||
        (rc = nc_cfg_double(m, "hot_pixel_fraction", 0, 1, &s->hot_pixel_fraction)) < 0 ||
        (rc = nc_cfg_double(m, "hot_pixel_dark_e_s", 0, 1e9, &s->hot_pixel_dark_e_s)) < 0 ||
        (rc = nc_cfg_double(m, "read_noise_e", 0, 1e6, &s->read_noise_e)) < 0 ||
        (rc = nc_cfg_double(m, "full_well_e", 1, 1e9, &s->full_well_e)) < 0 ||
        (rc = nc_cfg_double(m, "gain_e_per_dn", 1e-6, 1e9, &s->gain_e_per_dn)) < 0 ||
        (rc = nc_cfg_double(m, "analog_gain_db", -60, 60, &s->analog_gain_db)) < 0 ||
        (rc = nc_cfg_double(m, "bias_dn", 0, 65535, &s->bias_dn)) < 0)
        return rc;
    if ((rc = nc_cfg_enum(m, "blooming", bools, &b)) < 0)
        return rc;
    if (rc)
        s->blooming = b;
    if ((rc = nc_cfg_int(m, "adc_bits", 8, 16, &v)) < 0)
        return rc;
    if (rc)
        s->adc_bits = (int)v;
    if ((rc = nc_cfg_int(m, "seed", 0, 0x7fffffffL, &v)) < 0)
        return rc;
    if (rc)
        s->seed = (uint64_t)v;
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
    if (s->shutter == NC_SHUTTER_ROLLING && !(s->line_time_s > 0))
        return nc_cfg_missing(m, "line_time_s", "the delay between successive rows of a rolling shutter, seconds");
    if (s->bias_dn > ldexp(1.0, s->adc_bits) - 1)
        return nc_cfg_error(nc_cfg_get(m, "bias_dn"), "bias %g DN does not fit a %d-bit ADC", s->bias_dn, s->adc_bits);
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

int nc_camsys_from_config(struct nc_cfg_node *root, const struct nc_camera *geom, double focal_length_m,
                          struct nc_camsys *cs)
{
    memset(cs, 0, sizeof *cs);
    cs->width_px = geom->width_px;
    cs->height_px = geom->height_px;
    cs->exposure_s = 0.01;
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

    size_t n = (size_t)cs->width_px * (size_t)cs->height_px;
    cs->response = malloc(n * sizeof(float));
    cs->prnu_map = malloc(n * sizeof(float));
    cs->dark_map = malloc(n * sizeof(float));
    cs->scratch[0] = malloc(n * sizeof(float));
    cs->scratch[1] = malloc(n * sizeof(float));
    if (!cs->response || !cs->prnu_map || !cs->dark_map || !cs->scratch[0] || !cs->scratch[1]) {
        rc = nc_error(-ENOMEM, "out of memory");
        goto fail;
    }
    const struct nc_optics *o = &cs->optics;
    const struct nc_sensor *s = &cs->sensor;
    /* Camera equation for an object at infinity: focal-plane irradiance
     * E = L tau pi / (4 N^2) V(theta); electrons/s = QE E A_pix lambda/(h c). */
    double k = s->qe * o->band_fraction * o->transmission * M_PI / (4.0 * o->f_number * o->f_number) *
               s->pixel_pitch_m * s->pixel_pitch_m * o->wavelength_m / (NC_PLANCK_J_S * NC_LIGHT_M_S);
    double dark = s->dark_current_e_s * exp2((s->temperature_k - s->dark_ref_temp_k) / s->dark_doubling_k);
    for (int y = 0; y < cs->height_px; y++)
        for (int x = 0; x < cs->width_px; x++) {
            size_t p = (size_t)y * (size_t)cs->width_px + (size_t)x;
            struct nc_vec3 d = nc_camera_ray(geom, x, y);
            double theta = acos(d.z / nc_v3_norm(d));
            cs->response[p] = (float)(k * vignette(o, theta));
            /* Fixed patterns: keyed by the sensor seed only. */
            double u[4], z1, z2;
            nc_rng4(s->seed, NC_RNG_FIXED_PATTERN, 0, (uint32_t)p, 0, u);
            nc_normal2(u[0], u[1], &z1, &z2);
            cs->prnu_map[p] = (float)fmax(0.0, 1.0 + s->prnu * z1);
            double dp = fmax(0.0, dark + s->dsnu_e_s * z2);
            if (u[2] < s->hot_pixel_fraction)
                dp += s->hot_pixel_dark_e_s;
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
    free(cs->scratch[0]);
    free(cs->scratch[1]);
    free(cs->optics.vig_angle_rad);
    free(cs->optics.vig_factor);
    nc_psf_free(&cs->optics.psf);
    memset(cs, 0, sizeof *cs);
}

double nc_camsys_dn_per_e(const struct nc_camsys *cs)
{
    return exp10(cs->sensor.analog_gain_db / 20.0) / cs->sensor.gain_e_per_dn;
}

/* Photo-electrons: radiance x response x exposure. Far beyond any full well,
 * charge is capped so that a float holds it; NaN fails both comparisons and
 * becomes 0. */
__attribute__((target_clones("avx2", "default")))
static void scale_row(const float *restrict radiance, const float *restrict response, double exposure_s, size_t n,
                      float *restrict out)
{
    const float t = (float)exposure_s;
    for (size_t p = 0; p < n; p++) {
        float v = radiance[p] * response[p] * t;
        out[p] = v > 0 ? (v < 1e30f ? v : 1e30f) : 0.0f;
    }
}

int nc_camsys_electrons(const struct nc_camsys *cs, const float *radiance, double exposure_s, float *electrons)
{
    if (!(cs->sensor.pixel_pitch_m > 0))
        return nc_error(NC_ECONFIG, "electrons and DN need the pixel pitch: set camera.focal_length_m with "
                                    "camera.pixel_pitch_m, or sensor.pixel_pitch_m");
    size_t n = (size_t)cs->width_px * (size_t)cs->height_px;
    float *tmp = cs->optics.psf.size > 1 ? cs->scratch[0] : electrons;
    scale_row(radiance, cs->response, exposure_s, n, tmp);
    if (tmp != electrons)
        return nc_psf_apply_scratch(&cs->optics.psf, tmp, electrons, cs->width_px, cs->height_px, cs->scratch[1]);
    return 0;
}

/* Exact Poisson sampling by inversion (used below 32 e-), given
 * p0 = exp(-lambda) and a uniform u: the smallest k with CDF(k) >= u. */
static inline float poisson_inversion(double lambda, double p0, double u)
{
    double p = p0, cdf = p;
    int k = 0;
    while (u > cdf && k < 200) {
        k++;
        p *= lambda / k;
        cdf += p;
    }
    return (float)k;
}

/* Cosmic-ray charge for this frame, added into e (keyed by seed and frame). */
static void cosmic_rays(const struct nc_camsys *cs, double exposure_s, uint64_t frame, double *e)
{
    const struct nc_sensor *s = &cs->sensor;
    const int W = cs->width_px, H = cs->height_px;
    double area_cm2 = W * H * s->pixel_pitch_m * s->pixel_pitch_m * 1e4;
    double mean = s->cosmic_rate_cm2_s * area_cm2 * exposure_s, u[4];
    nc_rng4(s->seed, NC_RNG_COSMIC, frame, 0xffffffffu, 0, u);
    /* Number of hits: Poisson by inversion in blocks of uniforms. */
    long hits = 0;
    {
        double p = exp(-fmin(mean, 700)), cdf = p;
        if (mean < 500) {
            while (u[0] > cdf && hits < 1000000) {
                hits++;
                p *= mean / hits;
                cdf += p;
            }
        } else {
            double z1, z2;
            nc_normal2(u[1], u[2], &z1, &z2);
            hits = (long)fmax(0.0, floor(mean + sqrt(mean) * z1 + 0.5));
        }
    }
    for (long h = 0; h < hits; h++) {
        nc_rng4(s->seed, NC_RNG_COSMIC, frame, (uint32_t)h, 1, u);
        double x = u[0] * W, y = u[1] * H, a = 2 * M_PI * u[2], len = -s->cosmic_track_px * log(u[3]);
        /* Charge per pixel of projected track; a track shorter than a pixel
         * (near-normal incidence) still crosses the whole depth of one. */
        int steps = (int)ceil(len / 0.5) + 1;
        double q = s->cosmic_e_per_px * (len > 1.0 ? len : 1.0) / steps;
        for (int k = 0; k < steps; k++) {
            double t = steps > 1 ? (double)k / (steps - 1) : 0.0;
            int px = (int)floor(x + t * len * cos(a)), py = (int)floor(y + t * len * sin(a));
            if (px >= 0 && px < W && py >= 0 && py < H)
                e[(size_t)py * W + px] += q;
        }
    }
}

/* q[x]: electrons after shot noise, or -1 where exact inversion must decide
 * (lambda < 32 and u > P(0)). Single precision (24-bit: whole electrons are
 * exact below 16.7 M e-), selects and no branches, so that it vectorises. */
__attribute__((target_clones("avx2", "default")))
static void charge_row(const float *restrict lam, const float *restrict p0, const float *restrict u,
                       const float *restrict zs, int W, int shot, float *restrict q)
{
    for (int x = 0; x < W; x++) {
        float hi = floorf(lam[x] + sqrtf(lam[x]) * zs[x] + 0.5f);
        hi = hi > 0 ? hi : 0.0f;
        float lo = u[x] <= p0[x] ? 0.0f : -1.0f;
        q[x] = !shot ? lam[x] : lam[x] >= 32.0f ? hi : lo;
    }
}

/* DN = round(bias + (min(q, full well) + read noise z) g), clipped. */
__attribute__((target_clones("avx2", "default")))
static void digitise_row(const float *restrict q, const float *restrict zr, int W, float fw, float rn_e, float bias,
                         float g, float top, uint16_t *restrict dn)
{
    for (int x = 0; x < W; x++) {
        float v = floorf(bias + ((q[x] < fw ? q[x] : fw) + rn_e * zr[x]) * g + 0.5f);
        v = v < 0 ? 0 : v > top ? top : v;
        dn[x] = (uint16_t)(int32_t)v;
    }
}

/* The ADC: round to nearest, clip to 0 .. top. */
static inline uint16_t adc(double v, double top)
{
    v += 0.5;
    if (!(v > 0))
        return 0;
    return v >= top ? (uint16_t)top : (uint16_t)(uint32_t)v;
}

/* The random numbers of one image row: for each pair of pixels one Philox
 * call keyed by (seed, frame, pair) gives four 24-bit uniforms in (0, 1):
 * Box-Muller pair A (u0, u1) gives both pixels' read-noise normals, pair B
 * (u2, u3) their shot-noise normals at high counts; at low counts u2 and u3
 * are instead the uniforms of exact Poisson sampling (pair B then unused). No
 * draw serves twice in one pixel. Single precision and vector batches:
 * plenty for noise, and the whole frame takes a few milliseconds. */
struct row_rng {
    uint32_t *w;                 /* 4 words per pair */
    float *u, *lr, *ang, *s, *c; /* 2 per pixel each */
    float *zr, *zs;              /* per pixel: read-noise and shot-noise normals */
};

__attribute__((target_clones("avx2", "default")))
static void row_normals(const struct nc_camsys *cs, uint64_t frame, int y, int W, struct row_rng *b)
{
    const int pairs = (W + 1) / 2;
    uint32_t *const w[4] = {b->w, b->w + pairs, b->w + 2 * pairs, b->w + 3 * pairs};
    nc_rng_words(cs->sensor.seed, NC_RNG_PIXEL_NOISE, frame, (uint32_t)((size_t)y * (size_t)pairs), 0,
                 (size_t)pairs, w);
    const float scale = 0x1.0p-24f;
    for (int k = 0; k < pairs; k++) {
        float u0 = ((float)(w[0][k] >> 8) + 0.5f) * scale, u1 = ((float)(w[1][k] >> 8) + 0.5f) * scale;
        float u2 = ((float)(w[2][k] >> 8) + 0.5f) * scale, u3 = ((float)(w[3][k] >> 8) + 0.5f) * scale;
        b->u[2 * k] = u2;
        b->u[2 * k + 1] = u3;
        b->lr[2 * k] = u0;
        b->lr[2 * k + 1] = u2;
        b->ang[2 * k] = 2.0f * u1;
        b->ang[2 * k + 1] = 2.0f * u3;
    }
    nc_vlogf(b->lr, (size_t)2 * pairs);
    nc_vsincospif(b->ang, b->s, b->c, (size_t)2 * pairs);
    for (int i = 0; i < 2 * pairs; i++)
        b->lr[i] = sqrtf(-2.0f * b->lr[i]);
    /* Even pixels take the cosines, odd pixels the sines. */
    for (int k = 0; k < pairs; k++) {
        b->zr[2 * k] = b->lr[2 * k] * b->c[2 * k];
        b->zr[2 * k + 1] = b->lr[2 * k] * b->s[2 * k];
        b->zs[2 * k] = b->lr[2 * k + 1] * b->c[2 * k + 1];
        b->zs[2 * k + 1] = b->lr[2 * k + 1] * b->s[2 * k + 1];
    }
}

int nc_camsys_digitise(const struct nc_camsys *cs, const float *electrons, double exposure_s, uint64_t frame,
                       uint16_t *dn)
{
    const struct nc_sensor *s = &cs->sensor;
    const int W = cs->width_px, H = cs->height_px;
    const size_t n = (size_t)W * (size_t)H;
    const double fw = s->full_well_e, g = nc_camsys_dn_per_e(cs), top = ldexp(1.0, s->adc_bits) - 1.0;
    const int pairs = (W + 1) / 2, nb = 2 * pairs;
    /* Charge and read-noise normals for the whole frame only when charge moves
     * between pixels (cosmic rays, blooming); otherwise row by row. */
    const int whole = s->blooming || s->cosmic_rate_cm2_s > 0;
    double *e = whole ? malloc(n * sizeof *e) : NULL;
    float *rn = whole ? malloc(n * sizeof *rn) : NULL;
    float *buf = malloc((size_t)nb * 8 * sizeof *buf);
    uint32_t *words = malloc((size_t)pairs * 4 * sizeof *words);
    float *lam = malloc((size_t)nb * 2 * sizeof *lam), *q = lam + nb;
    if (!buf || !words || !lam || (whole && (!e || !rn))) {
        free(e);
        free(rn);
        free(buf);
        free(words);
        free(lam);
        return nc_error(-ENOMEM, "out of memory");
    }
    struct row_rng b = {words, buf, buf + nb, buf + 2 * nb, buf + 3 * nb, buf + 4 * nb, buf + 6 * nb, buf + 7 * nb};
    float *p0 = buf + 5 * nb;
    for (int y = 0; y < H; y++) {
        const size_t o = (size_t)y * (size_t)W;
        row_normals(cs, frame, y, W, &b);
        /* Charge: response pattern and dark current; exp(-lambda) for the
         * low-count pixels in one batch. */
        const float t = (float)exposure_s;
        for (int x = 0; x < W; x++) {
            lam[x] = electrons[o + x] * cs->prnu_map[o + x] + cs->dark_map[o + x] * t;
            p0[x] = lam[x] < 40.0f ? -lam[x] : -40.0f;
        }
        if (s->shot_noise)
            nc_vexpf(p0, (size_t)W);
        /* Charge after shot noise, branch-free for the common cases: the
         * normal approximation at >= 32 e-, and k = 0 at low counts when
         * u <= P(0); the rest (low counts, k >= 1) by exact inversion below. */
        charge_row(lam, p0, b.u, b.zs, W, s->shot_noise, q);
        for (int x = 0; x < W; x++)
            if (q[x] < 0)
                q[x] = poisson_inversion(lam[x], p0[x], b.u[x]);
        if (whole) {
            for (int x = 0; x < W; x++) {
                e[o + x] = q[x];
                rn[o + x] = b.zr[x];
            }
            continue;
        }
        digitise_row(q, b.zr, W, (float)fw, (float)s->read_noise_e, (float)s->bias_dn, (float)g, (float)top, dn + o);
    }
    free(buf);
    free(words);
    free(lam);
    if (!whole)
        return 0;
    if (s->cosmic_rate_cm2_s > 0)
        cosmic_rays(cs, exposure_s, frame, e);
    /* Full well: the excess is lost, or with blooming spills half up and half
     * down the column, cascading through saturated pixels. */
    if (s->blooming) {
        double *up = malloc((size_t)H * sizeof *up);
        if (!up) {
            free(e);
            free(rn);
            return nc_error(-ENOMEM, "out of memory");
        }
        for (int x = 0; x < W; x++) {
            double carry = 0;
            for (int y = 0; y < H; y++) {
                double *v = &e[(size_t)y * W + x];
                double ex = *v > fw ? *v - fw : 0;
                *v -= ex;
                up[y] = 0.5 * ex;
                *v += carry;
                carry = 0.5 * ex;
                if (*v > fw) {
                    carry += *v - fw;
                    *v = fw;
                }
            }
            carry = 0;
            for (int y = H - 1; y >= 0; y--) {
                double *v = &e[(size_t)y * W + x];
                *v += carry;
                carry = up[y];
                if (*v > fw) {
                    carry += *v - fw;
                    *v = fw;
                }
            }
        }
        free(up);
    }
    for (size_t p = 0; p < n; p++)
        dn[p] = adc(s->bias_dn + ((e[p] < fw ? e[p] : fw) + s->read_noise_e * rn[p]) * g, top);
    free(e);
    free(rn);
    return 0;
}
