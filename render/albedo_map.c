/* albedo_map.c - loading (through image_io) and bilinear sampling of
 * equirectangular albedo maps. */
#include "render/albedo_map.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/image_io.h"

/* signed_values: any finite value (elevation maps); else >= 0 (albedo). */
static int load(const char *path, double lon_left_deg, int east, double scale, int signed_values,
                struct nc_albedo_map **out)
{
    struct nc_albedo_map *m = calloc(1, sizeof *m);
    if (!m)
        return nc_error(-ENOMEM, "out of memory");
    int rc = nc_image_read(path, &m->value, &m->width_px, &m->height_px);
    if (rc >= 0 && (m->width_px < 1 || m->height_px < 1)) { /* sampled with a wrap and a clamp: a pixel at least */
        const int w = m->width_px, h = m->height_px;
        nc_albedo_map_free(m);
        return nc_error(NC_EIMAGE, "%s: %dx%d pixels: an empty map", path, w, h);
    }
    if (rc < 0) {
        free(m);
        return rc;
    }
    size_t n = (size_t)m->width_px * (size_t)m->height_px;
    for (size_t i = 0; i < n; i++)
        if (!((signed_values || m->value[i] >= 0) && isfinite(m->value[i]))) {
            int x = (int)(i % (size_t)m->width_px), y = (int)(i / (size_t)m->width_px);
            nc_albedo_map_free(m);
            return nc_error(NC_EIMAGE, "%s: pixel (%d, %d) is %s", path, x, y,
                            signed_values ? "not finite" : "negative or not finite; albedo maps need values >= 0");
        }
    m->lon_left_rad = lon_left_deg * (M_PI / 180.0);
    m->east = east;
    m->scale = scale;
    *out = m;
    return 0;
}

int nc_albedo_map_load(const char *path, double lon_left_deg, int east, double scale, struct nc_albedo_map **out)
{
    return load(path, lon_left_deg, east, scale, 0, out);
}

static int from_config(struct nc_cfg_node *map, int signed_values, struct nc_albedo_map **out)
{
    static const char *const dirs[] = {"east", "west", NULL};
    const char *file;
    double lon_left = -180, scale = 1;
    int dir = 0, rc;
    if ((rc = nc_cfg_string(map, "file", &file)) <= 0)
        return rc ? rc : nc_cfg_missing(map, "file", "an equirectangular image readable by OpenImageIO");
    if ((rc = nc_cfg_double(map, "lon_left_deg", -360, 360, &lon_left)) < 0 ||
        (rc = nc_cfg_enum(map, "lon_direction", dirs, &dir)) < 0 ||
        (rc = nc_cfg_double(map, "scale", signed_values ? -1e9 : 0, 1e9, &scale)) < 0)
        return rc;
    if (!out) /* the keys alone */
        return 0;
    const struct nc_cfg_node *fn = nc_cfg_get(map, "file");
    char path[4096];
    nc_cfg_resolve_path(fn, file, path, sizeof path);
    if ((rc = load(path, lon_left, dir == 0, scale, signed_values, out)) < 0) {
        char why[800];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_cfg_error(fn, "%s", why);
    }
    return 0;
}

int nc_albedo_map_from_config(struct nc_cfg_node *map, struct nc_albedo_map **out)
{
    return from_config(map, 0, out);
}

int nc_elevation_map_from_config(struct nc_cfg_node *map, struct nc_albedo_map **out)
{
    return from_config(map, 1, out);
}

double nc_albedo_map_factor(const struct nc_albedo_map *m, struct nc_vec3 p)
{
    double lon = atan2(p.y, p.x), r = nc_v3_norm(p);
    double lat = r > 0 ? asin(fmax(-1.0, fmin(1.0, p.z / r))) : 0.0;
    double turns = (m->east ? lon - m->lon_left_rad : m->lon_left_rad - lon) / (2.0 * M_PI);
    turns -= floor(turns);
    double x = turns * m->width_px - 0.5, y = (0.5 - lat / M_PI) * m->height_px - 0.5;
    double fx = floor(x), fy = floor(y);
    double tx = x - fx, ty = y - fy;
    int W = m->width_px, H = m->height_px;
    int x0 = ((int)fx % W + W) % W, x1 = (x0 + 1) % W;
    int y0 = (int)fy, y1 = y0 + 1;
    y0 = y0 < 0 ? 0 : y0 >= H ? H - 1 : y0;
    y1 = y1 < 0 ? 0 : y1 >= H ? H - 1 : y1;
    const float *v = m->value;
    double top = (1 - tx) * v[(size_t)y0 * W + x0] + tx * v[(size_t)y0 * W + x1];
    double bot = (1 - tx) * v[(size_t)y1 * W + x0] + tx * v[(size_t)y1 * W + x1];
    return ((1 - ty) * top + ty * bot) * m->scale;
}

void nc_albedo_map_free(struct nc_albedo_map *m)
{
    if (!m)
        return;
    free(m->value);
    free(m);
}
