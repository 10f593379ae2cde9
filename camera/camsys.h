/* camsys.h - the physical camera: optics (aperture, transmission, passband,
 * vignetting, PSF) and the detector (QE, dark current, fixed patterns, shot
 * and read noise, full well, blooming, gain, bias, ADC, cosmic rays), turning
 * the renderer's radiance (W m^-2 sr^-1) into electrons and digital numbers.
 *
 * Every random draw comes from a counter-based generator (Random123 Philox)
 * keyed by (sensor seed, frame number, pixel, draw), so a frame is a pure
 * function of its inputs: bit-identical for any thread count and
 * reproducible from the frame number. Fixed patterns (PRNU, DSNU, hot pixels)
 * are keyed by the sensor seed alone and never change between frames.
 * Lens distortion belongs to the camera geometry (render/camera.h), not here.
 */
#ifndef NC_CAMSYS_H
#define NC_CAMSYS_H

#include <stddef.h>
#include <stdint.h>

#include "render/camera.h"
#include "camera/psf.h"
#include "core/config.h"

#define NC_PLANCK_J_S 6.62607015e-34 /* exact (SI 2019) */
#define NC_LIGHT_M_S 299792458.0     /* exact */
#define NC_STAR_TEMPS 64
#define NC_STAR_T_MIN 2000.0
#define NC_STAR_T_MAX 50000.0

enum nc_vignetting { NC_VIGNETTING_NONE, NC_VIGNETTING_COS4, NC_VIGNETTING_TABLE };
enum nc_shutter { NC_SHUTTER_GLOBAL, NC_SHUTTER_ROLLING };


struct nc_optics {
    double f_number;         /* N = focal length / aperture diameter */
    double transmission;     /* optical throughput, 0..1 */
    double band_fraction;    /* in-band fraction of the solar irradiance */
    double wavelength_m;     /* effective wavelength of the passband */
    /* Stars (camera/sky.h): for black bodies of NC_STAR_TEMPS temperatures
     * (log-spaced, NC_STAR_T_MIN..NC_STAR_T_MAX K) the photon flux through
     * the passband, int T(lambda) n(lambda) dlambda, per unit photon spectral
     * flux at 545 nm (m); star_band is 0 when only band_fraction and
     * wavelength_m were given (the band's shape is not known). */
    double star_g_m[64];
    int star_band;
    enum nc_vignetting vignetting;
    double *vig_angle_rad, *vig_factor; /* table: field angle -> factor */
    int nvig;
    struct nc_psf psf;
};

struct nc_sensor {
    double pixel_pitch_m;
    double qe;                   /* quantum efficiency at the effective wavelength */
    int shot_noise;              /* Poisson photon and dark shot noise */
    double dark_current_e_s;     /* mean dark current at dark_ref_temp_k */
    double dark_ref_temp_k, dark_doubling_k, temperature_k;
    double dsnu_e_s;             /* rms of the per-pixel dark current (fixed pattern) */
    double prnu;                 /* rms relative per-pixel response (fixed pattern) */
    double hot_pixel_fraction;   /* fraction of pixels with hot_pixel_dark_e_s extra dark current */
    double hot_pixel_dark_e_s;
    double read_noise_e;         /* rms */
    double full_well_e;
    int blooming;                /* charge above full well spills along the column */
    double gain_e_per_dn;        /* at 0 dB analog gain */
    double analog_gain_db;
    double bias_dn;
    int adc_bits;                /* 8..16 */
    double cosmic_rate_cm2_s;    /* 0 = off */
    double cosmic_track_px;      /* mean track length */
    double cosmic_e_per_px;      /* charge deposited per pixel of track */
    uint64_t seed;
    enum nc_shutter shutter;
    double line_time_s;          /* rolling shutter: delay between successive rows */
};

struct nc_camsys {
    struct nc_optics optics;
    struct nc_sensor sensor;
    int width_px, height_px;     /* the sensor */
    double pixel_area_m2;        /* a pixel's area on the sensor: pitch^2 fx / fy (f / fy tall) */
    /* The radiance image the renderer draws for it: margin_px (the PSF's half
     * width) more on every side, so light from just outside the field
     * reaches the edge pixels as through a real lens. */
    int margin_px, render_width_px, render_height_px;
    double exposure_s;           /* default exposure (config `exposure.time_s`) */
    char where[320];             /* the camera section's file, line and path, for later errors */
    float *response;             /* e- per (W m^-2 sr^-1) per second, per rendered pixel (optics, QE, vignetting) */
    float *prnu_map;             /* 1 + PRNU pattern, per sensor pixel */
    float *dark_map;             /* e-/s per sensor pixel at the operating temperature */
    float *scratch[3];           /* render-sized work buffers: a camsys serves one thread at a time */
};

/* Read `optics`, `sensor` and `exposure` under root (each optional; defaults
 * describe an ideal noise-free camera with f/8 optics). The geometry supplies
 * the field angles for vignetting and, if the sensor gives none, the pitch. */
int nc_camsys_from_config(struct nc_cfg_node *root, const struct nc_camera *geom, double focal_length_m,
                          struct nc_camsys *cs);
/* The sections nc_camsys_from_config read (optics, sensor, exposure) checked
 * for unknown keys: they have no other reader, so a caller checks them
 * before it builds a scene's bodies. */
int nc_camsys_check_sections(struct nc_cfg *cfg);
void nc_camsys_free(struct nc_camsys *cs);

/* The camera the renderer draws with for this camera model: geom with the
 * margin on every side (size render_width_px x render_height_px, principal
 * point moved by margin_px); out may be geom. */
void nc_camsys_render_camera(const struct nc_camsys *cs, const struct nc_camera *geom, struct nc_camera *out);
/* Noise-free photo-electrons (after optics and PSF): the ground truth.
 * radiance is render_width_px x render_height_px (nc_camsys_render_camera);
 * electrons is width_px x height_px. */
int nc_camsys_electrons(const struct nc_camsys *cs, const float *radiance, double exposure_s, float *electrons);
/* A frame in DN from noise-free photo-electrons: fixed patterns, dark current,
 * shot noise, cosmic rays, full well and blooming, read noise, gain, bias and
 * the ADC. dn holds width*height values in 0 .. 2^adc_bits - 1. */
int nc_camsys_digitise(const struct nc_camsys *cs, const float *electrons, double exposure_s, uint64_t frame,
                       uint16_t *dn);
/* DN per electron of the whole chain (analog gain included). */
double nc_camsys_dn_per_e(const struct nc_camsys *cs);

#endif
