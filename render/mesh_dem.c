/* mesh_dem.c - meshes from elevation data (mesh.h): a terrain tile from a
 * height image, and a sphere displaced by an equirectangular elevation map.
 * No I/O: the caller reads the images. */
#include "render/mesh.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "render/albedo_map.h"

int nc_mesh_dem_tile(const float *h, int w, int rows, const struct nc_dem_tile_params *p, struct nc_mesh *out)
{
    *out = (struct nc_mesh){0};
    if (w < 2 || rows < 2 || (size_t)w * (size_t)rows > NC_DEM_MAX_PIXELS)
        return nc_error(NC_ERANGE, "a DEM needs 2x2 to %d pixels, got %dx%d", NC_DEM_MAX_PIXELS, w, rows);
    const size_t nv = (size_t)w * (size_t)rows, ncell = (size_t)(w - 1) * (size_t)(rows - 1);
    out->v = malloc(3 * nv * sizeof *out->v);
    out->tri = malloc(6 * ncell * sizeof *out->tri);
    if (!out->v || !out->tri) {
        nc_mesh_free(out);
        return nc_error(-ENOMEM, "out of memory for a %dx%d DEM", w, rows);
    }
    /* The tile's centre C on the sphere and its east and north unit vectors. */
    const double d2r = M_PI / 180.0, la = p->lat_deg * d2r, lo = p->lon_deg * d2r;
    const double C[3] = {cos(la) * cos(lo), cos(la) * sin(lo), sin(la)}, E[3] = {-sin(lo), cos(lo), 0},
                 N[3] = {-sin(la) * cos(lo), -sin(la) * sin(lo), cos(la)};
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < w; c++) {
            const size_t i = (size_t)r * (size_t)w + (size_t)c;
            const double e = (c - 0.5 * (w - 1)) * p->pixel_m[0], n = (0.5 * (rows - 1) - r) * p->pixel_m[1];
            const double z = isfinite(h[i]) ? p->height_offset_m + p->height_scale * h[i] : 0.0;
            double *v = out->v + 3 * i;
            if (!(fabs(z) <= NC_MESH_MAX_M)) {
                nc_mesh_free(out);
                return nc_error(NC_ERANGE, "a height of %g m at row %d, column %d is beyond %g m (height_scale, or not "
                                "an elevation image?)", z, r, c, NC_MESH_MAX_M);
            }
            if (p->radius_m > 0 && !(p->radius_m + z > 0)) {
                nc_mesh_free(out);
                return nc_error(NC_ERANGE, "the DEM goes below the sphere's centre (%g m under a %g m radius, row %d, "
                                "column %d)", -z, p->radius_m, r, c);
            }
            if (p->radius_m > 0) { /* gnomonic: the tangent plane's point projected onto the sphere */
                double d[3], len = 0;
                for (int k = 0; k < 3; k++) {
                    d[k] = C[k] + (e * E[k] + n * N[k]) / p->radius_m;
                    len += d[k] * d[k];
                }
                len = sqrt(len);
                for (int k = 0; k < 3; k++)
                    v[k] = (p->radius_m + z) * d[k] / len;
            } else {
                v[0] = e, v[1] = n, v[2] = z;
            }
        }
    /* Two triangles a cell, wound counter-clockwise seen from above (+z or
     * outward); a cell with a corner that is not finite is a hole. */
    size_t nt = 0;
    for (int r = 0; r + 1 < rows; r++)
        for (int c = 0; c + 1 < w; c++) {
            const uint32_t a = (uint32_t)((size_t)(r + 1) * (size_t)w + (size_t)c), b = a + 1,
                           d = (uint32_t)((size_t)r * (size_t)w + (size_t)c), e = d + 1;
            if (!(isfinite(h[a]) && isfinite(h[b]) && isfinite(h[d]) && isfinite(h[e])))
                continue;
            uint32_t *t = out->tri + 3 * nt;
            t[0] = a, t[1] = b, t[2] = e, t[3] = a, t[4] = e, t[5] = d;
            nt += 2;
        }
    if (nt == 0) {
        nc_mesh_free(out);
        return nc_error(NC_ERANGE, "the DEM has no cell with four finite corners");
    }
    out->nv = nv;
    out->nt = nt;
    return nc_mesh_check_extent(out, "the DEM tile");
}

int nc_mesh_globe(double radius_m, int subdivisions, const struct nc_albedo_map *elevation, struct nc_mesh *out)
{
    struct nc_asteroid_params ap = {.radii_m = {radius_m, radius_m, radius_m}, .subdivisions = subdivisions};
    int rc = nc_mesh_asteroid(&ap, out); /* no lumps, no craters: an icosphere on the sphere */
    if (rc < 0)
        return rc;
    for (size_t i = 0; i < out->nv; i++) {
        double *v = out->v + 3 * i;
        struct nc_vec3 p = nc_v3(v[0], v[1], v[2]);
        double r = nc_v3_norm(p), s = (radius_m + nc_albedo_map_factor(elevation, p)) / r;
        if (!(s > 0)) {
            nc_mesh_free(out);
            return nc_error(NC_ERANGE, "the elevation map goes below the centre (%g m under a %g m radius)",
                            -nc_albedo_map_factor(elevation, p), radius_m);
        }
        for (int k = 0; k < 3; k++)
            v[k] *= s;
    }
    return nc_mesh_check_extent(out, "the globe");
}
