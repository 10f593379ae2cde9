/* test_sumfile.c - a camera from an SPC SUM file (camera.sumfile,
 * docs/sumfiles.md) against the SUM projection written out independently:
 * a body-fixed point is predicted at (sample, line) by SCOBJ, CX, CY, CZ,
 * MMFL, K-MATRIX and CTR; the rendered geometry at that pixel must be that
 * point. For a normal and a mirrored (K22 < 0) pixel grid, with bodies[0]
 * turned in the scene frame; plus the parser's and the scene's errors.
 * The camera model's vignetting peaks at the stored principal point with
 * either grid. And SPC's ICQ shape format: a sphere written face by face with the
 * documented axes loads closed, outward and of the right size. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/shot.h"
#include "core/error.h"
#include "render/image_io.h"
#include "core/sumfile.h"
#include "testutil.h"

static void unit(double *v)
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] /= n;
}

static void cross(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* A SUM file looking at the body centre from cam_km, 256 x 200 pixels. */
static void make_sum(struct nc_sumfile *s, const double *cam_km, double k22_sign)
{
    memset(s, 0, sizeof *s);
    snprintf(s->picture, sizeof s->picture, "TEST0001");
    snprintf(s->utc, sizeof s->utc, "2020 JAN 15 12:00:00.000");
    s->npx = 256;
    s->nln = 200;
    s->mmfl_mm = 20;
    s->ctr[0] = 120.25; /* 1-based, off centre */
    s->ctr[1] = 95.5;
    const double up[3] = {0, 0, 1};
    for (int i = 0; i < 3; i++) {
        s->scobj_km[i] = -cam_km[i];
        s->cz[i] = -cam_km[i];
    }
    unit(s->cz);
    cross(up, s->cz, s->cx);
    unit(s->cx);
    cross(s->cz, s->cx, s->cy);
    s->sz[0] = 0.8, s->sz[1] = 0.6, s->sz[2] = 0.05;
    unit(s->sz);
    s->k[0] = 117.647;
    s->k[4] = k22_sign * 117.647;
}

/* SUM projection of body-fixed p_km (the docs' formula, written out). */
static void project(const struct nc_sumfile *s, const double *p_km, double *sample, double *line)
{
    double v[3] = {p_km[0] + s->scobj_km[0], p_km[1] + s->scobj_km[1], p_km[2] + s->scobj_km[2]};
    double x = s->mmfl_mm * dot(s->cx, v) / dot(s->cz, v), y = s->mmfl_mm * dot(s->cy, v) / dot(s->cz, v);
    *sample = s->ctr[0] + s->k[0] * x + s->k[1] * y;
    *line = s->ctr[1] + s->k[3] * x + s->k[4] * y;
}

static void check_view(double k22_sign, const char *body_q)
{
    const double cam_km[3] = {4, -2, 1};
    struct nc_sumfile sum;
    make_sum(&sum, cam_km, k22_sign);
    char path[4096], set[4200];
    snprintf(path, sizeof path, "%s", nc_test_path(k22_sign > 0 ? "normal.SUM" : "mirrored.SUM"));
    CHECK(nc_sumfile_write(path, &sum) == 0, "write %s", path);
    snprintf(set, sizeof set, "camera={sumfile: '%s'}", path);
    char bq[200];
    snprintf(bq, sizeof bq, "bodies.0.attitude_q=%s", body_q);
    const char *sets[] = {set, "sun={distance_au: 1.1}", bq};
    const char *yaml = "bodies:\n  - shape: {type: sphere, radius_m: 150}\n    material: {model: lambert, A: 0.2}\n"
                       "    position_m: [1000, -500, 250]\n"
                       "sun: {direction: [1, 0, 0]}\n"
                       "camera: {width_px: 8, height_px: 8, fx_px: 10, fy_px: 10, position_m: [0, 0, 0], "
                       "attitude_q: [1, 0, 0, 0]}\n"
                       "render: {samples_per_pixel: 1}\n";
    struct nc_scene s;
    nc_test_scene(yaml, sets, 3, &s);
    const struct nc_camera *c = &s.camera;
    CHECK(c->width_px == 256 && c->height_px == 200 && fabs(c->fx_px - 20 * 117.647) < 1e-9 &&
              fabs(c->fy_px - c->fx_px) < 1e-9 && c->flip_rows == (k22_sign < 0) && !c->flip_cols,
          "intrinsics %dx%d fx %g fy %g flips %d %d", c->width_px, c->height_px, c->fx_px, c->fy_px, c->flip_rows,
          c->flip_cols);
    CHECK(fabs(c->cx_px - 119.25) < 1e-12 && fabs(c->cy_px - (k22_sign > 0 ? 94.5 : 200 - 95.5)) < 1e-12,
          "principal point (%g, %g)", c->cx_px, c->cy_px);
    CHECK(fabs(nc_v3_dot(s.sun.direction, nc_v3(sum.sz[0], sum.sz[1], sum.sz[2])) - 1) < 1e-12 &&
              fabs(s.sun.distance_m / NC_AU_M - 1.1) < 1e-12,
          "Sun from SZ, distance from the scene");
    /* The camera is where SCOBJ says, relative to the body, in its frame. */
    struct nc_vec3 rel = nc_v3_sub(c->position_m, s.body[0].position_m);
    struct nc_vec3 cam_body = nc_quat_rotate(nc_quat_conj(s.body[0].attitude_q), rel);
    CHECK(nc_v3_norm(nc_v3_sub(cam_body, nc_v3(4000, -2000, 1000))) < 1e-6, "camera at (%g, %g, %g) m body-fixed",
          cam_body.x, cam_body.y, cam_body.z);

    /* Points on the sphere: predicted pixel vs what the render sees there. */
    struct nc_renderer r;
    CHECK(nc_renderer_init(&r, &s, 2) == 0, "renderer");
    const size_t plane = 256 * 200;
    float *geom = malloc(NC_GEOM_PLANES * plane * sizeof *geom);
    for (size_t i = 0; i < NC_GEOM_PLANES * plane; i++)
        geom[i] = 12345.0f; /* not what any plane holds */
    CHECK(nc_shot_geometry(&r, &s, geom, NULL) == 0, "geometry");
    /* The corners show sky (blocks no ray of which reaches the body are not
     * traced, but their planes are written). */
    const size_t corner[4] = {0, 255, plane - 256, plane - 1};
    for (int k = 0; k < 4; k++)
        CHECK(geom[NC_GEOM_BODY * plane + corner[k]] == -1 && geom[NC_GEOM_RANGE * plane + corner[k]] == 0 &&
                  geom[NC_GEOM_X * plane + corner[k]] == 0,
              "corner %d: sky (body %g)", k, geom[NC_GEOM_BODY * plane + corner[k]]);
    double worst = 0, gsd = 4.58 / (20 * 117.647) * 1e3; /* m per pixel at the range */
    int n = 0;
    for (int k = 0; k < 25; k++) {
        double d[3] = {cam_km[0] + 1.5 * sin(k), cam_km[1] + 1.5 * cos(1.3 * k), cam_km[2] + 1.2 * sin(0.7 * k)};
        unit(d);
        double p_km[3] = {0.15 * d[0], 0.15 * d[1], 0.15 * d[2]}, sample, line;
        double to_cam[3] = {cam_km[0] - p_km[0], cam_km[1] - p_km[1], cam_km[2] - p_km[2]};
        if (dot(d, to_cam) < 0.3 * sqrt(dot(to_cam, to_cam)))
            continue; /* on the far side or at the limb */
        project(&sum, p_km, &sample, &line);
        int x = (int)lround(sample - 1), y = (int)lround(line - 1);
        if (x < 0 || y < 0 || x >= 256 || y >= 200)
            continue;
        size_t o = (size_t)y * 256 + (size_t)x;
        double dx = geom[NC_GEOM_X * plane + o] - 1e3 * p_km[0], dy = geom[NC_GEOM_Y * plane + o] - 1e3 * p_km[1],
               dz = geom[NC_GEOM_Z * plane + o] - 1e3 * p_km[2];
        double err = sqrt(dx * dx + dy * dy + dz * dz);
        CHECK(geom[NC_GEOM_BODY * plane + o] == 0, "point %d: pixel (%d, %d) shows the body", k, x, y);
        worst = fmax(worst, err);
        n++;
    }
    /* Pixel centres are 0.5 px from the predicted point at worst, on a
     * surface tilted by up to ~72 deg: within 2 ground pixels. */
    CHECK(n >= 8 && worst < 2 * gsd, "%s grid, body turned by %s: %d points, worst %.3f m (pixel %.3f m)",
          k22_sign > 0 ? "normal" : "mirrored", body_q, n, worst, gsd);
    free(geom);
    nc_renderer_free(&r);
    nc_scene_free(&s);
}

static void expect_error(const char *text, const char *const *sets, int nsets, const char *needle)
{
    char path[4096], set[4200];
    snprintf(path, sizeof path, "%s", nc_test_path("bad.SUM"));
    nc_test_write(path, text);
    snprintf(set, sizeof set, "camera={sumfile: '%s'}", path);
    const char *all[4] = {set};
    for (int i = 0; i < nsets; i++)
        all[i + 1] = sets[i];
    struct nc_scene s;
    int rc = nc_test_scene_rc("bodies:\n  - shape: {type: sphere, radius_m: 150}\n    material: {model: lambert, A: "
                              "0.2}\nsun: {distance_au: 1}\ncamera: {}\n",
                              all, nsets + 1, &s);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), needle), "expected an error naming '%s', got %d: %s", needle, rc,
          rc < 0 ? nc_errmsg() : "");
    if (rc >= 0)
        nc_scene_free(&s);
}

/* out = text with the first from replaced by to. */
static void replaced(char *out, size_t len, const char *text, const char *from, const char *to)
{
    const char *at = strstr(text, from);
    snprintf(out, len, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
}

/* An ICQ sphere of radius r_km: face axes of docs/sumfiles.md (outward,
 * I direction, J direction), vertices from integer cube points so that the
 * copies on the cube's edges are equal; except that face 2's copies of
 * its edge with face 1 (J = 0) are moved by shift_km along x. */
static void write_icq(const char *path, int q, double r_km, double shift_km, int fortran)
{
    static const int ax[6][3][3] = {{{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
                                    {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}}, {{0, 1, 0}, {-1, 0, 0}, {0, 0, -1}},
                                    {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}},  {{0, 0, -1}, {1, 0, 0}, {0, 1, 0}}};
    FILE *f = fopen(path, "w");
    fprintf(f, "%10d\n", q);
    for (int face = 0; face < 6; face++)
        for (int j = 0; j <= q; j++)
            for (int i = 0; i <= q; i++) {
                double p[3];
                for (int k = 0; k < 3; k++)
                    p[k] = q * ax[face][0][k] + (2 * i - q) * ax[face][1][k] + (2 * j - q) * ax[face][2][k];
                unit(p);
                const double dx = face == 1 && j == 0 ? shift_km : 0;
                char line[128];
                snprintf(line, sizeof line, fortran ? "%.12E %.12E %.12E\n" : "%.12f %.12f %.12f\n", r_km * p[0] + dx,
                         r_km * p[1], r_km * p[2]);
                for (char *e = line; fortran && (e = strchr(e, 'E')); e++)
                    *e = 'D'; /* SPC's Fortran writes 0.25D+00 */
                fputs(line, f);
            }
    fclose(f);
}

/* The ICQ sphere at path (Q = q, 250 m) loads closed, wound outward, of
 * the sphere's area. */
static void check_closed(const char *path, int q)
{
    struct nc_mesh m;
    CHECK(nc_mesh_load(path, 1000, &m) == 0, "load ICQ: %s", nc_errmsg());
    if (m.nt == 0)
        return;
    CHECK(m.nt == 12 * q * q, "%zu triangles (12 Q^2 = %d)", m.nt, 12 * q * q);
    /* closed: every edge in exactly two triangles, once each way */
    size_t used = 0, open_edges = 0, outward = 0;
    unsigned char *seen = calloc(m.nv, 1);
    for (size_t t = 0; t < m.nt; t++) {
        struct nc_vec3 n;
        double area = nc_mesh_face(&m, t, &n);
        const double *a = m.v + 3 * (size_t)m.tri[3 * t];
        outward += area > 0 && n.x * a[0] + n.y * a[1] + n.z * a[2] > 0;
        for (int e = 0; e < 3; e++) {
            uint32_t u = m.tri[3 * t + (size_t)e], w = m.tri[3 * t + (size_t)(e + 1) % 3];
            seen[u] = 1;
            int found = 0;
            for (size_t s2 = 0; s2 < m.nt && !found; s2++)
                for (int e2 = 0; e2 < 3; e2++)
                    found |= m.tri[3 * s2 + (size_t)e2] == w && m.tri[3 * s2 + (size_t)(e2 + 1) % 3] == u;
            open_edges += !found;
        }
    }
    for (size_t i = 0; i < m.nv; i++)
        used += seen[i];
    free(seen);
    CHECK(used == (size_t)(6 * q * q + 2), "%zu vertices used after welding (6 Q^2 + 2 = %d)", used, 6 * q * q + 2);
    CHECK(open_edges == 0, "%zu edges without their opposite: not closed", open_edges);
    CHECK(outward == m.nt, "%zu of %zu triangles wound outward", outward, m.nt);
    double area = nc_mesh_area_m2(&m), sphere = 4 * M_PI * 250.0 * 250.0;
    CHECK(area < sphere && area > 0.98 * sphere, "area %.1f m^2 vs the sphere's %.1f", area, sphere);
    nc_mesh_free(&m);
}

static void check_icq(void)
{
    const int q = 16;
    const char *path = nc_test_path("SHAPE.TXT");
    write_icq(path, q, 0.25, 0, 0);
    check_closed(path, q);
    write_icq(path, q, 0.25, 0, 1);
    check_closed(path, q);
    /* Copies of an edge's vertex 0.1 mm apart (under 1e-6 of the 250 m
     * extent) are still welded: the surface stays closed. */
    write_icq(path, q, 0.25, 1e-7, 0);
    check_closed(path, q);
    /* 1 m apart: an error naming both lines, the first at fault face 2's
     * vertex I = 0, J = 0 (line 2 + (Q+1)^2), a copy of face 1's I = 0,
     * J = Q (line 2 + Q (Q+1)). */
    write_icq(path, q, 0.25, 1e-3, 0);
    struct nc_mesh m;
    char want[128];
    snprintf(want, sizeof want, "SHAPE.TXT:%d: this vertex and the one on line %d", 2 + (q + 1) * (q + 1),
             2 + q * (q + 1));
    CHECK(nc_mesh_load(path, 1000, &m) < 0 && nc_test_contains(nc_errmsg(), want) &&
              nc_test_contains(nc_errmsg(), "lie 1 m apart: not a closed ICQ surface"),
          "ICQ edge copies 1 m apart: %s (expected '%s')", nc_errmsg(), want);
    nc_test_write(nc_test_path("short.icq"), "4\n 1 2 3\n");
    CHECK(nc_mesh_load(nc_test_path("short.icq"), 1, &m) < 0 && nc_test_contains(nc_errmsg(), "1 vertices, but Q = 4 "
                                                                                                "needs 6 (Q+1)^2 = 150"),
          "short ICQ: %s", nc_errmsg());
    nc_test_write(nc_test_path("bad.icq"), "2\n 1 2 x\n");
    CHECK(nc_mesh_load(nc_test_path("bad.icq"), 1, &m) < 0 && nc_test_contains(nc_errmsg(), "bad.icq:2: expected a "
                                                                                              "vertex"),
          "bad ICQ: %s", nc_errmsg());
}

/* The optics act where the light falls: with a mirrored pixel grid (K22 < 0)
 * the cos^4 vignetting still peaks at the principal point of the stored
 * image (it peaked at the rows mirrored: 0.465 of the peak at the principal
 * point); electrons over radiance down the principal point's column, a 3 km
 * sphere filling a 256x256 frame of fx 200 px, principal point line 60.5. */
static void vignetting_where_stored(double k22_sign)
{
    const double cam_km[3] = {4, -2, 1};
    struct nc_sumfile sum;
    make_sum(&sum, cam_km, k22_sign);
    sum.nln = 256;
    sum.ctr[0] = 128.5;
    sum.ctr[1] = 60.5;
    sum.k[0] = 10;
    sum.k[4] = k22_sign * 10;
    char sumpath[4096], cfg[4096], set[4200], out[2][4096];
    snprintf(sumpath, sizeof sumpath, "%s", nc_test_path("vignette.SUM"));
    snprintf(cfg, sizeof cfg, "%s", nc_test_path("vignette.yaml"));
    CHECK(nc_sumfile_write(sumpath, &sum) == 0, "write %s", sumpath);
    nc_test_write(cfg, "bodies:\n  - shape: {type: sphere, radius_m: 3000}\n    material: {model: lambert, A: 0.2}\n"
                       "sun: {distance_au: 1.0}\nrender: {samples_per_pixel: 1}\nsensor: {qe: 1}\n"
                       "optics: {vignetting: cos4}\n");
    snprintf(set, sizeof set, "camera={sumfile: '%s'}", sumpath);
    const char *sets[] = {set};
    struct nc_scene s;
    struct nc_camsys cs;
    struct nc_sky sky;
    struct nc_renderer r;
    struct nc_shot_info info;
    float *px[2] = {NULL, NULL};
    int w = 0, h = 0;
    if (nc_shot_setup(cfg, sets, 1, &s, &cs, &sky) < 0 || nc_renderer_init(&r, &s, 2) < 0) {
        CHECK(0, "vignetting scene: %s", nc_errmsg());
        return;
    }
    for (int k = 0; k < 2; k++) {
        snprintf(out[k], sizeof out[k], "%s", nc_test_path(k ? "vignette_e.fits" : "vignette_r.fits"));
        CHECK(nc_shot(&r, &s, &cs, &sky, k ? NC_Q_ELECTRONS : NC_Q_RADIANCE, 0.01, 0, 0, out[k], NULL, 0, &info) == 0 &&
                  nc_image_read(out[k], &px[k], &w, &h) == 0 && w == 256 && h == 256,
              "vignetting: %s: %s", out[k], nc_errmsg());
    }
    int peak = -1;
    double best = 0, at_pp = 0;
    for (int y = 0; px[0] && px[1] && y < h; y++) {
        const double q = px[1][(size_t)y * (size_t)w + 128] / (double)px[0][(size_t)y * (size_t)w + 128];
        if (q > best)
            best = q, peak = y;
        if (y == 59 || y == 60)
            at_pp = fmax(at_pp, q);
    }
    printf("K22 %+g: electrons / radiance down column 128 peak at stored row %d (principal point 59.5); there %.4f "
           "of the peak\n", k22_sign, peak, at_pp / best);
    CHECK(abs(peak - 59) <= 1 && at_pp / best > 0.999, "K22 %+g: vignetting peaks at row %d, not the principal point",
          k22_sign, peak);
    free(px[0]);
    free(px[1]);
    nc_renderer_free(&r);
    nc_sky_free(&sky);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
}

int main(void)
{
    check_icq();
    vignetting_where_stored(1);
    vignetting_where_stored(-1);
    check_view(1, "[1, 0, 0, 0]");
    check_view(-1, "[0.9238795, 0.2209424, 0.1104712, 0.2946]");
    check_view(1, "[0.5, 0.5, 0.5, 0.5]");

    /* Fortran D notation, labels, unused items after K-MATRIX. */
    struct nc_sumfile sum;
    const char *good = "EX0000000001\n2020 JAN 15 12:00:00.000\n  1024  1024    10 65535   NPX, NLN, THRSH\n"
                       "    0.1252000000D+03    0.5125000000D+03    0.5125000000D+03  MMFL, CTR\n"
                       "   -0.4000000000D+01    0.2000000000D+01   -0.1000000000D+01  SCOBJ\n"
                       "    0.4472135955D+00    0.8944271910D+00    0.0000000000D+00  CX\n"
                       "    0.1951800146D+00   -0.9759000729D-01   -0.9759000729D+00  CY\n"
                       "   -0.8728715609D+00    0.4364357805D+00   -0.2182178902D+00  CZ\n"
                       "    0.7990018711D+00    0.5992514033D+00    0.4993761694D-01  SZ\n"
                       " 117.64700   0.00000   0.00000   0.00000 117.64700   0.00000  K-MATRIX\n"
                       "    0.00000D+00    0.00000D+00    0.00000D+00    0.00000D+00  DISTORTION\n"
                       "LANDMARKS\nAA0001    466.69    192.64\nLIMB FITS\nEND FILE\n";
    nc_test_write(nc_test_path("good.SUM"), good);
    CHECK(nc_sumfile_read(nc_test_path("good.SUM"), &sum) == 0 && sum.npx == 1024 && sum.mmfl_mm == 125.2 &&
              sum.ctr[1] == 512.5 && sum.scobj_km[0] == -4 && fabs(sum.cy[2] + 0.9759000729) < 1e-15 &&
              sum.k[4] == 117.647 && !strcmp(sum.utc, "2020 JAN 15 12:00:00.000"),
          "D notation: %s", nc_errmsg());

    char bad[2048];
    /* labels glued to the last number, as fixed-width Fortran output can print them (an outside check found
     * such a line reported missing) */
    replaced(bad, sizeof bad, good, "   -0.9759000729D+00  CY", "   -0.9759000729D+00CY");
    char glued[2048];
    replaced(glued, sizeof glued, bad, "   0.00000  K-MATRIX", "   0.00000K-MATRIX");
    nc_test_write(nc_test_path("glued.SUM"), glued);
    CHECK(nc_sumfile_read(nc_test_path("glued.SUM"), &sum) == 0 && fabs(sum.cy[2] + 0.9759000729) < 1e-15 &&
              sum.k[4] == 117.647 && sum.k[5] == 0,
          "labels glued to their numbers: %s", nc_errmsg());
    /* a NUL byte after a label: the rest of the line would be lost unseen */
    const size_t glen = strlen(good), at = (size_t)(strstr(good, "SCOBJ\n") - good) + 5;
    memcpy(bad, good, glen);
    memmove(bad + at + 4, bad + at, glen - at);
    memcpy(bad + at, "\0 .1", 4);
    nc_test_write_bytes(nc_test_path("nul.SUM"), bad, glen + 4);
    CHECK(nc_sumfile_read(nc_test_path("nul.SUM"), &sum) < 0 &&
              nc_test_contains(nc_errmsg(), "nul.SUM:5: a NUL byte at column 68"),
          "NUL: %s", nc_errmsg());
    /* CR LF line ends and a byte-order mark (a Windows editor's); the 1024-byte limit is of a line's text */
    char crlf[4096], *w = crlf + sizeof "\xef\xbb\xbf" - 1;
    memcpy(crlf, "\xef\xbb\xbf", 3);
    w += sprintf(w, "%1024s", "EX0000000001"); /* the name padded to 1024 bytes */
    for (const char *c = strchr(good, '\n'); *c; c++)
        w += sprintf(w, *c == '\n' ? "\r\n" : "%c", *c);
    nc_test_write(nc_test_path("crlf.SUM"), crlf);
    CHECK(nc_sumfile_read(nc_test_path("crlf.SUM"), &sum) == 0 && !strcmp(sum.picture, "EX0000000001") &&
              !strcmp(sum.utc, "2020 JAN 15 12:00:00.000") && sum.npx == 1024 && sum.k[4] == 117.647,
          "CR LF and a byte-order mark: %s", nc_errmsg());
    snprintf(bad, sizeof bad, "EX0000000001\r%s", strchr(good, '\n') + 1); /* a lone CR ends no line */
    expect_error(bad, NULL, 0, "bad.SUM:1: a carriage return at column 13 inside the line");
    snprintf(bad, sizeof bad, "%.*s", (int)(strstr(good, "   -0.8728") - good), good); /* no CZ and after */
    expect_error(bad, NULL, 0, "no CZ line");
    replaced(bad, sizeof bad, good, "   -0.8728715609D+00    0.4364357805D+00   -0.2182178902D+00",
             "    0.8728715609D+00   -0.4364357805D+00    0.2182178902D+00");
    expect_error(bad, NULL, 0, "left-handed");
    replaced(bad, sizeof bad, good, " 0.00000 117.64700", " 0.50000 117.64700"); /* K21 */
    expect_error(bad, NULL, 0, "bad.SUM:10: K-MATRIX: K12 = 0, K21 = 0.5 skew the pixel grid, moving pixels by up to "
                               "2.17 px");
    /* DART DRACO's K21 = 0.0031 px/mm moves these pixels by 0.013 px at most: taken as none */
    replaced(bad, sizeof bad, good, " 0.00000 117.64700", " 0.00310 117.64700");
    nc_test_write(nc_test_path("skew.SUM"), bad);
    CHECK(nc_sumfile_read(nc_test_path("skew.SUM"), &sum) == 0, "a skew of 0.013 px: %s", nc_errmsg());
    replaced(bad, sizeof bad, good, "   0.00000  K-MATRIX", "   0.10000  K-MATRIX"); /* K23 */
    expect_error(bad, NULL, 0, "K13 = 0, K23 = 0.1: NavCam's camera has no such terms");
    replaced(bad, sizeof bad, good, "    0.00000D+00    0.00000D+00  DISTORTION", "    0.00000D+00    0.20000D-02  DISTORTION");
    expect_error(bad, NULL, 0, "bad.SUM:11: DISTORTION: 0 0 0 0.002: NavCam does not model SPC's distortion");
    replaced(bad, sizeof bad, good, "    0.2000000000D+01   -0.1000000000D+01  SCOBJ",
             "    0.2000X00000D+01   -0.1000000000D+01  SCOBJ");
    expect_error(bad, NULL, 0, "bad.SUM:5: SCOBJ: '0.2000X00000D+01' is not a number");
    replaced(bad, sizeof bad, good, "  SZ\n", "  SZ\n 0.6 0.8 0  SZ\n");
    expect_error(bad, NULL, 0, "bad.SUM:10: SZ: given twice (lines 9 and 10)");
    replaced(bad, sizeof bad, good, "  K-MATRIX\n", "  K-MATRIX  DISTORTION\n"); /* was read as K-MATRIX */
    expect_error(bad, NULL, 0, "bad.SUM:10: the line is labelled both K-MATRIX and DISTORTION: one label a line");
    /* The ranges the configuration's camera keys take (a K11 of 1e-30 gave an empty frame) */
    replaced(bad, sizeof bad, good, " 117.64700   0.00000   0.00000   0.00000 117.64700",
             " 1.0D-30   0.00000   0.00000   0.00000 117.64700");
    expect_error(bad, NULL, 0, "bad.SUM:10: K-MATRIX: MMFL x K11, K22 give focal lengths of 1.2");
    /* Axes off unit length or perpendicular within 1e-3 are made
     * orthonormal keeping CZ, the boresight: CX 1.0005 long, then CX . CY
     * = 9e-4 (CY turned about CZ). */
    const char *cx = "    0.4472135955D+00    0.8944271910D+00    0.0000000000D+00  CX";
    const double cz[3] = {-0.8728715609, 0.4364357805, -0.2182178902};
    char line[128];
    for (int k = 0; k < 2; k++) {
        const double *c0 = (const double[]){0.4472135955, 0.8944271910, 0}, e = 9e-4;
        const double *cy0 = (const double[]){0.1951800146, -0.09759000729, -0.9759000729};
        if (k == 0)
            snprintf(line, sizeof line, "%.10f %.10f %.10f  CX", 1.0005 * c0[0], 1.0005 * c0[1], 1.0005 * c0[2]);
        else
            snprintf(line, sizeof line, "%.10f %.10f %.10f  CX", c0[0] + e * cy0[0], c0[1] + e * cy0[1],
                     c0[2] + e * cy0[2]);
        replaced(bad, sizeof bad, good, cx, line);
        nc_test_write(nc_test_path("axes.SUM"), bad);
        CHECK(nc_sumfile_read(nc_test_path("axes.SUM"), &sum) == 0, "axes within 1e-3: %s", nc_errmsg());
        struct nc_vec3 z = nc_quat_rotate(sum.q, nc_v3(0, 0, 1)), x = nc_quat_rotate(sum.q, nc_v3(1, 0, 0));
        double dz = nc_v3_norm(nc_v3_sub(z, nc_v3_unit(nc_v3(cz[0], cz[1], cz[2])))),
               dx = nc_v3_norm(nc_v3_sub(x, nc_v3(c0[0], c0[1], c0[2])));
        CHECK(dz < 1e-9 && dx < 1e-9 + (k ? e : 0), "%s: the boresight %.3g from CZ, +X %.3g from CX",
              k ? "CX . CY 9e-4" : "CX 1.0005 long", dz, dx);
    }
    snprintf(line, sizeof line, "%.10f %.10f %.10f  CX", 1.0015 * 0.4472135955, 1.0015 * 0.8944271910, 0.0);
    replaced(bad, sizeof bad, good, cx, line);
    expect_error(bad, NULL, 0, "bad.SUM:6: CX: not a unit vector (length 1.0015");
    const char *sun_pos[] = {"sun={position_m: [1.0e11, 0, 0]}"};
    expect_error(good, sun_pos, 1, "instead of sun.position_m");
    replaced(bad, sizeof bad, good, "  CY\n", " 0.3  CY\n");
    expect_error(bad, NULL, 0, "CY: expected 3 numbers before the label, found 4");
    const char *with_dir[] = {"sun={direction: [1, 0, 0], distance_au: 1}"};
    expect_error(good, with_dir, 1, "remove sun.direction");
    const char *no_dist[] = {"sun={}"};
    expect_error(good, no_dist, 1, "distance_au");
    const char *with_size[] = {"camera.width_px=100"};
    expect_error(good, with_size, 1, "remove width_px");
    /* The limits of every camera and body (core/pose.h): a SUM file's SCOBJ too (it went unchecked: a blank
     * frame and a false warning of a camera inside a body), bodies' positions, speeds up to the speed of light
     * (a camera faster than light lost its stars to NaN directions) */
    replaced(bad, sizeof bad, good, "   -0.4000000000D+01    0.2000000000D+01",
             "   -0.4000000000D+13    0.2000000000D+01");
    expect_error(bad, NULL, 0, "camera.sumfile: SCOBJ puts the camera 4e+15 m from bodies[0]'s centre, beyond "
                               "1e+15 m (SCOBJ is in km)");
    const char *far_body[] = {"bodies.0.position_m=[0, 1e300, 0]"},
               *fast_body[] = {"bodies.0.velocity_m_s=[3e8, 0, 0]"},
               *fast_camera[] = {"camera.velocity_m_s=[0, 0, -3e9]"};
    expect_error(good, far_body, 1, "bodies[0].position_m: 1e+300 m from the scene's origin, beyond 1e+15 m");
    const char *just_beyond[] = {"bodies.0.position_m=[1000000000000001, 0, 0]"}; /* as many digits as that takes */
    expect_error(good, just_beyond, 1, "bodies[0].position_m: 1000000000000001 m from the scene's origin");
    expect_error(good, fast_body, 1, "bodies[0].velocity_m_s: 3e+08 m/s, beyond the speed of light, 299792458 m/s");
    expect_error(good, fast_camera, 1, "camera.velocity_m_s: 3e+09 m/s, beyond the speed of light");
    return nc_test_end();
}
