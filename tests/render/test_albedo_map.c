/* test_albedo_map.c - equirectangular albedo maps: longitude origin and
 * direction, bilinear filtering with wrap-around, and the effect on a render. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/albedo_map.h"
#include "core/error.h"
#include "render/image_io.h"
#include "testutil.h"

/* 8 x 4 map: western hemisphere (columns 0-3 when the left edge is -180 deg
 * east) 0.5, eastern hemisphere 1.0. */
static const char *write_map(void)
{
    float v[32];
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 8; x++)
            v[y * 8 + x] = x < 4 ? 0.5f : 1.0f;
    const char *path = nc_test_path("hemispheres.exr");
    if (nc_image_write(path, v, 8, 4, NULL, 0, NULL) < 0) {
        fprintf(stderr, "%s\n", nc_errmsg());
        exit(2);
    }
    return path;
}

static struct nc_vec3 lonlat(double lon_deg, double lat_deg)
{
    double l = lon_deg * M_PI / 180, b = lat_deg * M_PI / 180;
    return nc_v3(cos(b) * cos(l), cos(b) * sin(l), sin(b));
}

int main(void)
{
    const char *path = write_map();
    struct nc_albedo_map *m;
    CHECK(nc_albedo_map_load(path, -180, 1, 2.0, &m) == 0, "load: %s", nc_errmsg());
    /* Pixel centres are at lon = -180 + (c + 0.5) 45 deg. */
    CHECK(fabs(nc_albedo_map_factor(m, lonlat(-157.5, 0)) - 1.0) < 1e-6, "west centre (0.5 x scale 2)");
    CHECK(fabs(nc_albedo_map_factor(m, lonlat(157.5, 30)) - 2.0) < 1e-6, "east centre");
    CHECK(fabs(nc_albedo_map_factor(m, lonlat(0, 0)) - 1.5) < 1e-6, "bilinear between columns 3 and 4: %g",
          nc_albedo_map_factor(m, lonlat(0, 0)));
    CHECK(fabs(nc_albedo_map_factor(m, lonlat(180, -60)) - 1.5) < 1e-6, "wrap between the last and first column: %g",
          nc_albedo_map_factor(m, lonlat(180, -60)));
    CHECK(fabs(nc_albedo_map_factor(m, lonlat(-168.75, 89.9)) - 1.25) < 1e-6, "quarter way, near the pole: %g",
          nc_albedo_map_factor(m, lonlat(-168.75, 89.9)));
    CHECK(fabs(nc_albedo_map_factor(m, nc_v3(0, 0, -5)) - nc_albedo_map_factor(m, lonlat(0, -90))) < 1e-12, "south pole");
    nc_albedo_map_free(m);
    /* Westward maps: left edge at +180, longitude decreasing to the right. */
    CHECK(nc_albedo_map_load(path, 180, 0, 1.0, &m) == 0, "load west");
    CHECK(fabs(nc_albedo_map_factor(m, lonlat(157.5, 0)) - 0.5) < 1e-6, "west-positive: column 0 is at 157.5 E");
    CHECK(fabs(nc_albedo_map_factor(m, lonlat(-22.5, 0)) - 1.0) < 1e-6, "west-positive: column 4 is at 22.5 W");
    nc_albedo_map_free(m);

    /* In a render: a Lommel-Seeliger sphere seen at zero phase from lon 90 E
     * (factor 1) and from lon 90 W (factor 0.5). */
    char yaml[2048];
    snprintf(yaml, sizeof yaml,
             "bodies:\n"
             "  - shape: {type: sphere, radius_m: 1000}\n"
             "    material:\n"
             "      model: lommel_seeliger\n"
             "      w: 0.4\n"
             "      albedo_map: {file: '%s', lon_left_deg: -180, lon_direction: east}\n"
             "sun: {direction: [0, 1, 0]}\n"
             "camera: {width_px: 33, height_px: 33, fx_px: 100, fy_px: 100, position_m: [0, 8000, 0],\n"
             "         look_at_m: [0, 0, 0], up: [0, 0, 1]}\n",
             path);
    double centre[2];
    for (int side = 0; side < 2; side++) {
        const char *sets[] = {side ? "camera.position_m=[0, -8000, 0]" : "render.seed=0",
                              side ? "sun.direction=[0, -1, 0]" : "render.seed=0"};
        struct nc_scene s;
        nc_test_scene(yaml, sets, 2, &s);
        struct nc_frame f;
        nc_test_render(&s, 1, &f);
        centre[side] = f.iof[16 * 33 + 16];
        nc_frame_free(&f);
        nc_scene_free(&s);
    }
    double want = M_PI * 0.4 / (8 * M_PI); /* I/F = pi w/(8 pi) at i = e */
    CHECK(fabs(centre[0] - want) < 1e-6 && fabs(centre[1] - 0.5 * want) < 1e-6,
          "rendered I/F east %.6g (want %.6g), west %.6g (want %.6g)", centre[0], want, centre[1], 0.5 * want);

    /* Bad maps. */
    float bad[4] = {0.1f, -0.2f, 0.3f, 0.4f};
    const char *badp = nc_test_path("negative.exr");
    nc_image_write(badp, bad, 2, 2, NULL, 0, NULL);
    CHECK(nc_albedo_map_load(badp, 0, 1, 1, &m) < 0 && nc_test_contains(nc_errmsg(), "negative.exr: pixel (1, 0)"),
          "negative map value: %s", nc_errmsg());
    { /* a FITS image of 8x0 pixels, header alone: refused (it crashed the render: a division by its 0 width) */
        char hdr[2880 + 1];
        const char *cards[] = {"SIMPLE  =                    T", "BITPIX  =                  -32",
                               "NAXIS   =                    2", "NAXIS1  =                    8",
                               "NAXIS2  =                    0", "END"};
        memset(hdr, ' ', 2880);
        for (int i = 0; i < 6; i++)
            memcpy(hdr + 80 * i, cards[i], strlen(cards[i]));
        hdr[2880] = 0;
        const char *emptyp = nc_test_path("empty.fits");
        nc_test_write(emptyp, hdr);
        CHECK(nc_albedo_map_load(emptyp, 0, 1, 1, &m) < 0 &&
                  nc_test_contains(nc_errmsg(), "8x0 pixels: an empty image"),
              "an empty map: %s", nc_errmsg());
    }
    struct nc_scene s;
    const char *sets[] = {"bodies.0.material.albedo_map.file=/no/such/map.exr"};
    CHECK(nc_test_scene_rc(yaml, sets, 1, &s) < 0 &&
              nc_test_contains(nc_errmsg(), "bodies[0].material.albedo_map.file: /no/such/map.exr"),
          "missing map: %s", nc_errmsg());
    return nc_test_end();
}
