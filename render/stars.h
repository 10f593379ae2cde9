/* stars.h - a star catalogue and point sources in the rendered frame.
 *
 * The catalogue: stars with ICRS (J2000 equatorial) positions at an epoch,
 * proper motions, Johnson V and B-V. NavCam's own index file (docs/stars.md)
 * holds them brightest first, so stars down to a limiting magnitude are a
 * prefix of it: fainter ones cost nothing. `navcam stars` writes the index
 * from KStars' stars.dat (Debian package kstars-data: Hipparcos and Tycho
 * to V 8.99).
 *
 * The scene frame is the ICRS (J2000 equatorial) frame for stars.
 */
#ifndef NC_STARS_H
#define NC_STARS_H

#include <stddef.h>

#include "core/vec.h"
#include "render/render.h"
#include "render/sun.h"

struct nc_star {
    double ra_rad, dec_rad;       /* ICRS, at the catalogue's epoch */
    float pm_ra_mas_yr;           /* proper motion in RA times cos(dec), mas/yr */
    float pm_dec_mas_yr;          /* mas/yr */
    float v_mag, b_v;             /* Johnson V, B-V */
};

struct nc_star_cat {
    size_t n;
    struct nc_star *star; /* brightest first */
    double epoch_jyear;   /* Julian year of the positions (2000.0 for J2000) */
};

/* Read KStars' stars.dat (fixed columns: RA hhmmss.ss, Dec sddmmss.s, pmRA
 * cos(dec) and pmDec in mas/yr, parallax, V, B-V, ...; J2000). */
int nc_star_cat_read_kstars(const char *path, struct nc_star_cat *c);
/* NavCam's index: write and load (docs/stars.md gives the layout). */
int nc_star_cat_write(const struct nc_star_cat *c, const char *path);
int nc_star_cat_load(const char *path, struct nc_star_cat *c);
void nc_star_cat_free(struct nc_star_cat *c);
/* Stars brighter than v_mag: the length of that prefix. */
size_t nc_star_cat_count_to(const struct nc_star_cat *c, double v_mag);

/* Unit vector to the star at jyear (Julian years), proper motion applied
 * along the tangent plane. */
struct nc_vec3 nc_star_direction(const struct nc_star *s, double epoch_jyear, double jyear);
/* Stellar aberration: the apparent direction of unit vector p for an
 * observer moving at v_m_s (same frame), special relativity exact. */
struct nc_vec3 nc_aberrate(struct nc_vec3 p, struct nc_vec3 v_m_s);

/* A point source at infinity (a star): its direction (scene frame, unit) and
 * its irradiance at the aperture in the renderer's units (W m^-2 as the
 * solar-equivalent total the camera model's band_fraction applies to);
 * iof_per_radiance, pi / J for a body lit by the solar irradiance J (its
 * I/F is pi L / J), 0 for a star (none in the I/F plane). A body drawn as
 * a point also has its distance (0 for a star: at infinity) and its
 * velocity relative to the camera, so that it moves over the exposure as it
 * moves, not only as the camera turns (its direction at time t from the
 * middle, dir range_m + rel_velocity_m_s t, made unit). */
struct nc_point_source {
    struct nc_vec3 dir;
    double irradiance_w_m2;
    double iof_per_radiance; /* sr m^2 W^-1 */
    double range_m;
    struct nc_vec3 rel_velocity_m_s; /* scene frame */
};

/* Add point sources to frame f (the scene camera's size; its pose is the
 * one at mid-exposure): each is drawn where the lens images it, its
 * irradiance spread bilinearly over the four pixels around that point (so
 * the centroid keeps the sub-pixel position) as radiance E / Omega_pixel
 * (and I/F, iof_per_radiance times that); over the exposure (exposure_s,
 * the camera's rates) it moves as the camera turns and a body's point as
 * it moves, in steps of at most 0.1 px; with a rolling shutter (line_time_s
 * > 0; 0: global, row y read (y - (H - 1) / 2) line_time_s after the middle
 * one) it is drawn where it is while the row it is on is open (about the
 * row it falls on, T / |1 - v| long, v its speed along the columns in rows
 * per row's time; docs/camera.md). With occlusion, a body in front hides it (traced with r's
 * ray tracer at the scene's poses). Returns how many were drawn (in the
 * frame and not hidden), or < 0 on error; *hidden counts the hidden ones. */
long nc_render_points(struct nc_renderer *r, const struct nc_scene *s, double exposure_s, double line_time_s,
                      const struct nc_point_source *p, size_t n, int occlusion, struct nc_frame *f, long *hidden);

/* The scene's bodies that are smaller than a pixel from its camera (their
 * bounding sphere's angular diameter under one pixel): each one's light as
 * a point source, its irradiance at the aperture and its brightness
 * centroid, from a 32 x 32 render (16 samples a pixel) of the scene zoomed
 * onto it from the same place (so its phase, shadows and anything in front
 * are as the camera sees them). Sets r->as_point for them; returns how many
 * were written to p (NC_MAX_BODIES at most), or < 0 on error. A ray-traced
 * sub-pixel body is hit by few samples or none: as a point its light is
 * all there, where it is. */
int nc_render_point_bodies(struct nc_renderer *r, const struct nc_scene *s, struct nc_point_source *p);
/* A body a pixel or more across whose bounding sphere's angular radius is
 * under this (a narrow-angle camera of fx over 5e5 px far from a small
 * body) is an error there: float rays step by 6e-8 rad, so its limb would
 * be traced to tens of percent of its radius. */
#define NC_RESOLVED_MIN_RAD 1e-6

#endif
