/* quality.h - render.quality: auto. Picks, per frame, the cheapest render
 * settings whose error stays under a fraction k (render.auto_noise_fraction)
 * of the camera's own noise (shot plus read noise, in electrons, at each
 * pixel's level), from two pilots a and b: renders at 4 samples a pixel
 * (2 x 2 strata) with their own seeds, of a staggered lattice of tiles
 * over each body's image (every second row of tiles and every second tile
 * in it where that puts 4 rows, 4 columns and 32 tiles through the image,
 * else every tile; tiles no body can reach are skipped, so a small body is
 * seen wherever it lies), half of each tile's
 * pixels (a checkerboard of 4 x 4 blocks) and the other half where a bounce
 * is taken. Each pilot also keeps its direct sunlight, the same with hard
 * shadows, and one of its samples (render.h's planes), in the renderer's
 * scratch frames:
 *   - soft shadows where the penumbra a body can cast on itself or another,
 *     2 tan(a_sun) x its diameter, spans half a pixel at its nearest range,
 *     and hard shadows are biased by more than k/2 camera sigmas RMS (the
 *     mean of (a - hard_a)(b - hard_b): two independent pairs, the Sun-disk
 *     noise of one sample cancels); a lone sphere or ellipsoid, which
 *     neither shadows nor lights itself, takes neither soft shadows nor a
 *     bounce in its pilots;
 *   - every boulder traced (render.boulder_min_px 0) where the configured
 *     cut, and the full meshes (render.lod_error_px 0) where the configured
 *     level of detail, changes b's direct light with hard shadows by more
 *     than k/2 sigmas RMS (biases that samples do not reduce; a pilot each,
 *     b's rays with hard shadows, no bounce and the setting changed);
 *   - indirect light when the pilots' mean bounce light exceeds k camera
 *     sigmas, with as many bounces as leave less than that unrendered
 *     (each bounce taken to scale the last by the pilots' ratio of indirect
 *     to direct light), at most 8;
 *   - samples per pixel: the mean over lit pixels of the Monte Carlo
 *     variance over the camera's noise variance, times sum(w^2) of the PSF
 *     kernel (independent pixel errors through the optics), at one sample
 *     (v1: the pilots' one samples) and at four (v4). Where v1 > k^2 the
 *     variance is taken to fall as S^-beta from 4 samples on, beta =
 *     log4(v1 / v4), in [1.5, 2] without a bounce (jittered strata cut an
 *     edge's variance as S^-1.5) and in [1, 1.5] with one (the paths'
 *     noise falls as S^-1): the smallest square S (4 to 256) with
 *     v4 (4 / S)^beta <= (0.7 k)^2, a margin for the pilots' own sampling
 *     error.
 * Everything is keyed by the scene's seed: the same frame gets the same
 * choice.
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
    double penumbra_px;      /* the widest penumbra any body can cast, px (a bound) */
    double hard_shadow_rms;  /* hard against soft shadows, camera sigmas RMS (0: not tried) */
    double cut_rms, lod_rms; /* the boulder cut, the level of detail against none, the same */
    int all_rocks, full_mesh; /* render.boulder_min_px and render.lod_error_px set to 0 */
    double strata_beta;      /* the variance's fall with samples, S^-beta (1: not measured, one sample chosen) */
    int pilot_tiles;         /* tiles each pilot rendered */
    double pilot_ms;
};

/* s: the scene as the renderer draws it (the camera model's render camera,
 * nc_camsys_render_camera); its render settings are replaced by the choice.
 * r is the renderer that will draw the frame (its threads do the pilots). */
int nc_quality_auto(struct nc_renderer *r, struct nc_scene *s, const struct nc_camsys *cs, double exposure_s,
                    struct nc_quality_choice *out);
/* "spp=16 bounces=1 soft=1" and the figures behind it; with timing, the
 * pilots' time too (left out of files, which must not depend on it). */
void nc_quality_describe(const struct nc_quality_choice *q, int timing, char *buf, size_t len);

#endif
