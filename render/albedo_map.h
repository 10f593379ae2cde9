/* albedo_map.h - equirectangular albedo maps: an image over planetocentric
 * longitude and latitude that scales a material's albedo parameter (w or A).
 *
 * Longitude is east-positive, lon = atan2(y, x) in the body-fixed frame (+x
 * is the prime meridian, +z the north pole); latitude is asin(z / |p|). The
 * image's top row is at +90 deg, its bottom row at -90 deg; its left edge is at
 * lon_left_deg and longitude increases to the right eastward or westward.
 * Pixel centres sit at (column + 0.5, row + 0.5); sampling is bilinear,
 * wrapping in longitude and clamping in latitude.
 */
#ifndef NC_ALBEDO_MAP_H
#define NC_ALBEDO_MAP_H

#include "core/config.h"
#include "core/vec.h"

struct nc_albedo_map {
    int width_px, height_px;
    float *value;        /* first channel, row-major, top row first */
    double lon_left_rad; /* longitude of the left edge */
    int east;            /* 1: longitude increases to the right eastward */
    double scale;        /* factor = value * scale */
};

int nc_albedo_map_load(const char *path, double lon_left_deg, int east, double scale, struct nc_albedo_map **out);
/* Keys: file, lon_left_deg (default -180), lon_direction (east|west, default
 * east), scale (default 1). */
int nc_albedo_map_from_config(struct nc_cfg_node *map, struct nc_albedo_map **out);
/* The same map read as elevations (scene_dem.c): values of any sign, scale
 * in metres per image unit (default 1), sampled by nc_albedo_map_factor.
 * out NULL: its keys read and checked, no image loaded. */
int nc_elevation_map_from_config(struct nc_cfg_node *map, struct nc_albedo_map **out);
/* Albedo factor (or elevation) at body-fixed point p (any length, not the origin). */
double nc_albedo_map_factor(const struct nc_albedo_map *m, struct nc_vec3 p);
void nc_albedo_map_free(struct nc_albedo_map *m);

#endif
