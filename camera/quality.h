/* quality.h - render.quality: auto. Picks, per frame, the cheapest render
 * settings whose error stays under a fraction k (render.auto_noise_fraction)
 * of the camera's own noise (shot plus read noise, in electrons, at each
 * pixel's level):
 *   - soft shadows when the penumbra a body can cast on itself or another,
 *     2 tan(a_sun) x its diameter, spans half a pixel at its nearest range;
 *   - indirect light when a pilot's mean bounce light exceeds k camera
 *     sigmas, with as many bounces as leave less than that unrendered
 *     (each bounce taken to scale the last by the pilot's ratio of indirect
 *     to direct light), at most 8;
 *   - samples per pixel from two pilots with different seeds: the mean over
 *     lit pixels of the Monte Carlo variance at one sample over the camera's
 *     noise variance, divided by k^2, rounded up to a square (1 to 256).
 * The pilots render one sample a pixel in every fourth row of tiles (every
 * row for frames under 8 tile rows). Everything is keyed by the scene's
 * seed: the same frame gets the same choice.
 */
#ifndef NC_CAMERA_QUALITY_H
#define NC_CAMERA_QUALITY_H

#include "camera/camsys.h"
#include "render/render.h"

struct nc_quality_choice {
    int samples_per_pixel, bounces, soft_shadows;
    double mc_to_noise_var;  /* mean over lit pixels of (MC variance at 1 sample / camera noise variance) */
    double indirect_sigma;   /* mean bounce light over the camera's noise sigma */
    double indirect_ratio;   /* bounce light over direct light */
    double penumbra_px;
    double pilot_ms;
};

/* s: the scene as the renderer draws it (the camera model's render camera,
 * nc_camsys_render_camera); its render settings are replaced by the choice.
 * r is the renderer that will draw the frame (its threads do the pilots). */
int nc_quality_auto(struct nc_renderer *r, struct nc_scene *s, const struct nc_camsys *cs, double exposure_s,
                    struct nc_quality_choice *out);
/* "spp=16 bounces=1 soft=1" and the figures behind it. */
void nc_quality_describe(const struct nc_quality_choice *q, char *buf, size_t len);

#endif
