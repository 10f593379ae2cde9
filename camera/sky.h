/* sky.h - stars in the frame: the catalogue (render/stars.h) turned into
 * point sources through the camera's passband, aperture, QE and exposure.
 *
 * Configuration (docs/stars.md): the top-level `stars` section,
 *   stars: {catalogue: FILE, limit_mag: auto | V, epoch_jyear: 2026.9,
 *           observer_velocity_m_s: [x, y, z]}
 * The scene frame is the ICRS. The frame's epoch is epoch_jyear plus the
 * simulation time; the observer's velocity (stellar aberration) is
 * observer_velocity_m_s (the scene origin's, relative to the solar system
 * barycentre) plus the camera's own velocity.
 *
 * Photometry: a star of V and B-V is a black body at the temperature B-V
 * gives (Ballesteros 2012), scaled to 9.96e7 photons s^-1 m^-2 nm^-1 at
 * 545 nm for V = 0 (f_lambda = 3.631e-11 W m^-2 nm^-1, Bessell, Castelli &
 * Plez 1998), integrated through the passband's shape.
 */
#ifndef NC_SKY_H
#define NC_SKY_H

#include "camera/camsys.h"
#include "core/config.h"
#include "render/stars.h"

struct nc_sky {
    int on;
    struct nc_star_cat cat;
    char path[1024];
    char where[320];           /* the stars section's file, line and path, for later errors */
    int limit_auto;            /* limit_mag: auto */
    double limit_mag;          /* when not auto */
    double epoch_jyear;        /* at simulation time 0 */
    struct nc_vec3 observer_velocity_m_s;
    /* prepared for one camera model (nc_sky_prepare) */
    struct nc_vec3 *dir;       /* at dir_jyear, unaberrated */
    double dir_jyear;
    double *e_w_m2;            /* solar-equivalent irradiance at the aperture (the renderer's unit) */
    double *e_per_s;           /* photo-electrons per second (noise-free, on axis, no vignetting) */
    double g_max_m;            /* the most band photons per 545 nm photon flux, over colours */
    double aperture_m2;
    struct nc_point_source *pts;
};

/* What one frame's stars were. */
struct nc_sky_stats {
    double limit_mag;          /* the limiting magnitude used */
    long considered, drawn, hidden;
};

/* The `stars` section of cfg (absent: sky->on = 0), its keys checked (an
 * unknown one is an error, before the index is loaded). Loads the index. */
int nc_sky_from_config(struct nc_cfg *cfg, struct nc_sky *sky);
/* Photometry for this camera model and geometry (fx_px); call again when
 * either changes. */
int nc_sky_prepare(struct nc_sky *sky, const struct nc_camsys *cs, const struct nc_camera *geom);
void nc_sky_free(struct nc_sky *sky);

/* A star's in-band photons s^-1 m^-2 at the aperture (before transmission
 * and QE). */
double nc_star_band_photons(const struct nc_optics *o, double v_mag, double b_v);
/* Effective temperature from B-V (Ballesteros 2012, EPL 97, 34008). */
double nc_star_teff_k(double b_v);

/* The faintest V this exposure can show: a star of that V and the most
 * favourable colour gives 0.1 of the pixel noise (read and dark) in total,
 * or a twentieth of a DN without noise. */
double nc_sky_limit_mag(const struct nc_sky *sky, const struct nc_camsys *cs, double exposure_s);

/* Add the stars to the radiance frame f, rendered for scene s (the camera
 * with the camera model's margin, nc_camsys_render_camera; poses at mid-
 * exposure, t_sim_s after simulation time 0). */
int nc_sky_draw(struct nc_sky *sky, struct nc_renderer *r, const struct nc_camsys *cs, const struct nc_scene *s,
                double t_sim_s, double exposure_s, struct nc_frame *f, struct nc_sky_stats *st);

#endif
