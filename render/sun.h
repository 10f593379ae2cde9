/* sun.h - the Sun seen from the camera: where it is against the frame
 * (in it, near it: stray light) and its disk drawn into the frame. */
#ifndef NC_SUN_H
#define NC_SUN_H

#include <stddef.h>

#include "render/render.h"

/* Where the Sun is for the camera, and what of it the frame shows. "Near"
 * the field: within NC_SUN_NEAR_DEG of its edge (stray light in a real
 * camera's baffle). */
#define NC_SUN_NEAR_DEG 10.0
struct nc_sun_view {
    double off_axis_deg; /* the Sun's centre from the boresight */
    double edge_deg;     /* from the frame's edge (pinhole, along the Sun's azimuth); < 0: in the frame */
    int in_field;        /* part of its disk is in the frame */
    int near_field;      /* within near_deg outside the frame: stray light */
    int hidden;          /* in the field, but every sample of its disk is behind a body */
    double drawn_w_m2;   /* irradiance at the aperture drawn into the frame */
};
/* Describe the Sun's place relative to the frame of scene s (poses at
 * mid-exposure) and, when its disk reaches the frame, draw it: a uniform
 * disk of the Sun's angular radius theta and radiance E / (pi sin^2 theta)
 * (E the solar irradiance at the camera), 8 x 8 samples a pixel,
 * each traced for bodies in front; a disk under 4 px in radius as 1024
 * points spread over it, each a 1024th of E, traced and added to the pixel
 * it falls in. The camera model then saturates and blooms it like any
 * light. */
int nc_render_sun(struct nc_renderer *r, const struct nc_scene *s, double near_deg, struct nc_frame *f,
                  struct nc_sun_view *v);
/* "sun in field", "sun in field, hidden by a body", "sun 4.2 deg from the
 * field" or "" (far from it), into buf. */
void nc_sun_view_warning(const struct nc_sun_view *v, char *buf, size_t len);
/* The frame's metadata of it (navcam:sun_view, FITS SUNVIEW) into buf:
 * "off_axis_deg=... edge_deg=... in_field=... hidden=..." and the warning,
 * when the Sun is in or near the field; "" otherwise. */
void nc_sun_view_text(const struct nc_sun_view *v, char *buf, size_t len);

#endif
