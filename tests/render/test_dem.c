/* test_dem.c - shapes from elevation data (mesh_dem.c, scene_dem.c): a DEM
 * tile's vertices where its georeferencing puts them, flat and on a sphere,
 * holes where the image has no data; a globe's vertices at the reference
 * radius plus the map's elevation; and a lunar landing tile on a Moon-sized
 * sphere rendered from 1 m above it, in the Moon-fixed frame, with ranges
 * to 10 um of the exact ones and uniform, acne-free shading. Config
 * errors name the file, line and key. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/image_io.h"
#include "render/rt.h"
#include "testutil.h"

#define R_MOON 1737400.0

static void check_tile(void)
{
    enum { W = 9, H = 7 };
    float h[W * H];
    for (int i = 0; i < W * H; i++)
        h[i] = (float)(0.25 * (i % W) - 0.5 * (i / W));
    struct nc_dem_tile_params p = {.pixel_m = {2, 3}, .height_scale = 2, .height_offset_m = 10};
    struct nc_mesh m;
    CHECK(nc_mesh_dem_tile(h, W, H, &p, &m) == 0, "%s", nc_errmsg());
    double worst = 0;
    for (int r = 0; r < H; r++)
        for (int c = 0; c < W; c++) {
            const double *v = m.v + 3 * (r * W + c);
            worst = fmax(worst, fabs(v[0] - (c - 4) * 2.0) + fabs(v[1] - (3 - r) * 3.0) +
                                    fabs(v[2] - (10 + 2 * h[r * W + c])));
        }
    CHECK(m.nt == 2 * (W - 1) * (H - 1) && worst < 1e-12, "flat tile: %zu triangles, worst vertex off by %g m", m.nt,
          worst);
    /* every face points up (+z): counter-clockwise from above */
    int up = 1;
    for (size_t t = 0; t < m.nt; t++) {
        struct nc_vec3 n;
        nc_mesh_face(&m, t, &n);
        up &= n.z > 0.5;
    }
    CHECK(up, "a face of the flat tile points down");
    nc_mesh_free(&m);
    /* no data: the four cells around a NaN pixel are holes */
    h[3 * W + 4] = NAN;
    CHECK(nc_mesh_dem_tile(h, W, H, &p, &m) == 0 && m.nt == 2 * (W - 1) * (H - 1) - 8,
          "a NaN pixel left %zu triangles", m.nt);
    nc_mesh_free(&m);
    /* a value no elevation has (the ray tracer aborted on it): refused, naming the pixel */
    h[3 * W + 4] = 3e38f;
    CHECK(nc_mesh_dem_tile(h, W, H, &p, &m) < 0 && nc_test_contains(nc_errmsg(), "at row 3, column 4 is beyond 1e+10 m"),
          "a height of 3e38: %s", nc_errmsg());
    h[3 * W + 4] = 0;
    /* on a sphere: the centre pixel at (lat, lon), every vertex at radius + height */
    p.radius_m = R_MOON, p.lat_deg = 30, p.lon_deg = 45;
    CHECK(nc_mesh_dem_tile(h, W, H, &p, &m) == 0, "%s", nc_errmsg());
    double rad_err = 0;
    for (int i = 0; i < W * H; i++) {
        const double *v = m.v + 3 * i;
        rad_err = fmax(rad_err, fabs(sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - (R_MOON + 10 + 2 * h[i])));
    }
    const double *c = m.v + 3 * (3 * W + 4);
    double rc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double lat = asin(c[2] / rc) * 180 / M_PI, lon = atan2(c[1], c[0]) * 180 / M_PI;
    /* the east neighbour is 2 m east: its longitude larger, latitude the same */
    const double *e = m.v + 3 * (3 * W + 5);
    double de = sqrt(pow(e[0] - c[0], 2) + pow(e[1] - c[1], 2) + pow(e[2] - c[2], 2));
    printf("tile on a sphere: radius error %.2g m, centre at %.9f N %.9f E, east neighbour %.6f m away\n", rad_err, lat,
           lon, de);
    CHECK(rad_err < 1e-8 && fabs(lat - 30) < 1e-9 && fabs(lon - 45) < 1e-9, "centre at %g, %g", lat, lon);
    CHECK(fabs(de - sqrt(4 + pow(2 * (h[3 * W + 5] - h[3 * W + 4]), 2))) < 1e-3, "east neighbour %g m away", de);
    nc_mesh_free(&m);
    /* heights below the sphere's centre are an error, as on a globe */
    p.height_offset_m = -2 * R_MOON;
    CHECK(nc_mesh_dem_tile(h, W, H, &p, &m) < 0 && nc_test_contains(nc_errmsg(), "below the sphere's centre"),
          "a tile below the centre: %s", nc_errmsg());
}

/* A flat (height 0) tile on the Moon's sphere at 30 N 45 E, seen straight
 * down from 1 m above its centre vertex with a narrow camera: every pixel is
 * on the body (the central row and column of pixels look straight along the
 * grid lines through that vertex: watertight triangle tests keep them from
 * slipping between triangles), its range is the exact distance to the
 * sphere (the 0.5 m facets depart from it by 2e-8 m), and the Lambert
 * shading is uniform. */
static void check_landing(void)
{
    enum { W = 65 };
    float *h = calloc(W * W, sizeof *h);
    const char *dem = nc_test_path("flat.fits");
    CHECK(nc_image_write(dem, h, W, W, NULL, 0, NULL) == 0, "%s", nc_errmsg());
    free(h);
    const double la = 30 * M_PI / 180, lo = 45 * M_PI / 180;
    struct nc_vec3 C = nc_v3(cos(la) * cos(lo), cos(la) * sin(lo), sin(la)), N = nc_v3(-sin(la) * cos(lo), -sin(la) * sin(lo), cos(la));
    struct nc_vec3 cam = nc_v3_scale(C, R_MOON + 1.0), sun = nc_v3_unit(nc_v3_add(C, N));
    char yaml[2048];
    snprintf(yaml, sizeof yaml,
             "bodies:\n"
             "  - shape: {type: dem, file: '%s', pixel_m: 0.5, on_sphere: {radius_m: %.1f, lat_deg: 30, lon_deg: 45}}\n"
             "    material: {model: lambert, A: 0.12}\n"
             "sun: {direction: [%.17g, %.17g, %.17g]}\n"
             "camera: {width_px: 64, height_px: 64, fx_px: 1000, fy_px: 1000, cx_px: 32, cy_px: 32,\n"
             "         position_m: [%.17g, %.17g, %.17g], look_at_m: [0, 0, 0], up: [%.17g, %.17g, %.17g]}\n"
             "render: {samples_per_pixel: 1}\n",
             dem, R_MOON, sun.x, sun.y, sun.z, cam.x, cam.y, cam.z, N.x, N.y, N.z);
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    struct nc_frame f;
    nc_test_render(&s, 2, &f);
    struct nc_mat3 Rc = nc_quat_to_mat(s.camera.attitude_q);
    double worst = 0, lo_L = INFINITY, hi_L = 0;
    int missed = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            size_t i = (size_t)y * 64 + x;
            /* exact range along the pixel centre's ray to the sphere (pixel
             * (x, y) is centred on those coordinates; one sample there) */
            struct nc_vec3 d = nc_v3_unit(nc_mat_mul_v(&Rc, nc_camera_dir(&s.camera, x, y)));
            double b = nc_v3_dot(cam, d), cc = nc_v3_dot(cam, cam) - R_MOON * R_MOON;
            double t = -b - sqrt(b * b - cc);
            if (!(f.coverage[i] > 0)) {
                missed++;
                continue;
            }
            worst = fmax(worst, fabs(f.range_m[i] - t));
            lo_L = fmin(lo_L, f.radiance[i]);
            hi_L = fmax(hi_L, f.radiance[i]);
        }
    printf("landing at 1 m on a Moon-sized sphere: %d pixels missed, range within %.3g m of exact, radiance %.6g to "
           "%.6g\n", missed, worst, lo_L, hi_L);
    CHECK(missed == 0 && worst < 1e-5, "%d missed, range off by %g m", missed, worst);
    CHECK(hi_L / lo_L - 1 < 1e-3, "shading varies by %.3g", hi_L / lo_L - 1);
    nc_frame_free(&f);
    nc_scene_free(&s);
}

/* A globe: each vertex at the reference radius plus the map's elevation. */
static void check_globe(void)
{
    enum { MW = 72, MH = 36 };
    float map[MW * MH];
    for (int r = 0; r < MH; r++)
        for (int c = 0; c < MW; c++)
            map[r * MW + c] = (float)(r < MH / 2 ? 2.0 : -3.0); /* north +2 km, south -3 km */
    const char *file = nc_test_path("elev.tif");
    CHECK(nc_image_write(file, map, MW, MH, NULL, 0, NULL) == 0, "%s", nc_errmsg());
    char yaml[1024];
    snprintf(yaml, sizeof yaml,
             "bodies:\n"
             "  - shape: {type: globe, radius_m: 1000000, subdivisions: 4, elevation_map: {file: '%s', scale: 1000}}\n"
             "    material: {model: lambert, A: 0.1}\n"
             "sun: {direction: [1, 0, 0]}\n"
             "camera: {width_px: 32, height_px: 32, fx_px: 20, fy_px: 20, position_m: [5000000, 0, 0], "
             "look_at_m: [0, 0, 0], up: [0, 0, 1]}\n",
             file);
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    int ok = 1;
    size_t far_from_equator = 0;
    for (size_t i = 0; i < s.body[0].mesh.nv; i++) {
        const double *v = s.body[0].mesh.v + 3 * i;
        double r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), lat = asin(v[2] / r) * 180 / M_PI;
        if (fabs(lat) < 6) /* the map's north/south step is blended across its middle rows */
            continue;
        far_from_equator++;
        ok &= fabs(r - (1000000 + (lat > 0 ? 2000 : -3000))) < 1e-6;
    }
    CHECK(ok && far_from_equator > 1000 && s.body[0].shape == NC_SHAPE_MESH, "globe radii off the map (%zu vertices)",
          far_from_equator);
    nc_scene_free(&s);
    /* the largest radius a globe takes, 1e10 m, at subdivisions 4: its vertices a rounding beyond it (refused) */
    for (int i = 0; i < MW * MH; i++)
        map[i] = 0;
    CHECK(nc_image_write(file, map, MW, MH, NULL, 0, NULL) == 0, "%s", nc_errmsg());
    const char *largest[] = {"bodies[0].shape.radius_m=1e10", "camera.position_m=[3e10, 0, 0]"};
    const int rc = nc_test_scene_rc(yaml, largest, 2, &s);
    CHECK(rc >= 0, "a globe of radius 1e10 m: %s", nc_errmsg());
    if (rc >= 0)
        nc_scene_free(&s);
    /* errors name the key */
    const char *base = "bodies:\n  - shape: {type: dem, file: nowhere.fits}\n    material: {model: lambert, A: 0.1}\n"
                       "sun: {direction: [1, 0, 0]}\ncamera: {width_px: 8, height_px: 8, fx_px: 8, fy_px: 8, "
                       "position_m: [0, 0, -10], attitude_q: [1, 0, 0, 0]}\n";
    CHECK(nc_test_scene_rc(base, NULL, 0, &s) < 0 && nc_test_contains(nc_errmsg(), "pixel_m"), "no pixel_m: %s",
          nc_errmsg());
    const char *sets[] = {"bodies[0].shape.pixel_m=1"};
    CHECK(nc_test_scene_rc(base, sets, 1, &s) < 0 && nc_test_contains(nc_errmsg(), "nowhere.fits"),
          "a missing file: %s", nc_errmsg());
    const char *globe[] = {"bodies[0].shape={type: globe, radius_m: 1000}"};
    CHECK(nc_test_scene_rc(base, globe, 1, &s) < 0 && nc_test_contains(nc_errmsg(), "elevation_map"),
          "a globe without a map: %s", nc_errmsg());
}

int main(void)
{
    check_tile();
    check_landing();
    check_globe();
    return nc_test_end();
}
