/* test_mesh.c - mesh loading: what must load (long comment headers, unused
 * vertices, relative and slashed OBJ indices, PLY ASCII and binary) and what
 * must fail with a clear message, never a crash. The meshes are made here.
 * Smooth shading (shape.normals: smooth): a coarse icosphere shaded with its
 * vertex normals comes closer to the exact sphere than its flat facets, and
 * gives no light where its facet is turned away from the Sun. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "render/mesh.h"
#include "testutil.h"

static const char *write_tmp(const char *name, const char *text)
{
    const char *p = nc_test_path(name);
    nc_test_write(p, text);
    return p;
}

static void expect_fail(const char *name, const char *text, const char *needle)
{
    const char *p = write_tmp(name, text);
    struct nc_mesh m;
    int rc = nc_mesh_load(p, 1.0, &m);
    CHECK(rc < 0, "%s: should fail", name);
    if (rc >= 0) {
        nc_mesh_free(&m);
        return;
    }
    CHECK(nc_test_contains(nc_errmsg(), needle), "%s: message '%s' lacks '%s'", name, nc_errmsg(), needle);
    CHECK(nc_test_contains(nc_errmsg(), name), "%s: message '%s' does not name the file", name, nc_errmsg());
    printf("ok  %-16s -> %s\n", name, nc_errmsg());
}

/* Relative RMS difference of the I/F of a 1280-face icosphere from the
 * exact sphere, Lambert, over the pixels both light fully. */
static double icosphere_error(const char *normals)
{
    const char *yaml = "bodies:\n"
                       "  - shape: {type: sphere, radius_m: 1000}\n"
                       "    material: {model: lambert, A: 0.2}\n"
                       "sun: {direction: [0.5, -0.8660254, 0]}\n"
                       "camera: {width_px: 128, height_px: 128, focal_length_m: 0.05, pixel_pitch_m: 2e-4,\n"
                       "         position_m: [0, -4000, 0], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n"
                       "render: {samples_per_pixel: 4}\n";
    char shape[160], norm[64];
    snprintf(shape, sizeof shape,
             "bodies[0].shape={type: asteroid, radii_m: [1000, 1000, 1000], subdivisions: 3, craters: 0, "
             "lump_amplitude: 0}");
    snprintf(norm, sizeof norm, "bodies[0].shape.normals=%s", normals);
    const char *sets[] = {shape, norm};
    struct nc_scene exact, mesh;
    struct nc_frame fe, fm;
    nc_test_scene(yaml, NULL, 0, &exact);
    nc_test_scene(yaml, sets, 2, &mesh);
    nc_test_render(&exact, 2, &fe);
    nc_test_render(&mesh, 2, &fm);
    double se = 0, sr = 0;
    int finite = 1;
    for (int i = 0; i < 128 * 128; i++) {
        finite &= isfinite(fm.iof[i]);
        if (fe.coverage[i] == 1 && fm.coverage[i] == 1 && fe.iof[i] > 0.01 && fm.iof[i] > 0) {
            se += (fm.iof[i] - fe.iof[i]) * (fm.iof[i] - fe.iof[i]);
            sr += fe.iof[i] * fe.iof[i];
        }
    }
    CHECK(finite, "%s: every pixel finite", normals);
    nc_frame_free(&fe);
    nc_frame_free(&fm);
    nc_scene_free(&exact);
    nc_scene_free(&mesh);
    return sqrt(se / sr);
}

/* A 320-face icosphere with smooth normals, one sample a pixel (its centre), at phases 90 to 130 deg: a pixel
 * whose centre's ray meets a facet turned away from the Sun (well inside it: its barycentric coordinates over
 * 0.02) is dark, whatever the shading normal there (an outside check found 0 to 13 such pixels a frame lit, at up
 * to 13 % of the peak: their shadow rays started along the shading normal and left the facet). */
static void backlit_facets(void)
{
    const char *yaml = "bodies:\n"
                       "  - shape: {type: asteroid, radii_m: [100, 100, 100], subdivisions: 2, craters: 0, "
                       "lump_amplitude: 0, normals: smooth}\n"
                       "    material: {model: lambert, A: 0.3}\n"
                       "sun: {direction: [1, 0, 0]}\n"
                       "camera: {width_px: 192, height_px: 192, fx_px: 1300, fy_px: 1300,\n"
                       "         position_m: [0, -1500, 0], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n"
                       "render: {samples_per_pixel: 1}\n";
    int dark_facets = 0, lit_wrongly = 0;
    for (int deg = 90; deg <= 130; deg += 4) {
        char sun[96];
        snprintf(sun, sizeof sun, "sun.direction=[%.17g, %.17g, 0.05]", sin(deg * M_PI / 180), -cos(deg * M_PI / 180));
        const char *sets[] = {sun};
        struct nc_scene s;
        struct nc_frame f;
        nc_test_scene(yaml, sets, 1, &s);
        nc_test_render(&s, 2, &f);
        const struct nc_mesh *m = &s.body[0].mesh;
        const struct nc_vec3 o = s.camera.position_m, sd = nc_v3_unit(s.sun.direction);
        for (int y = 0; y < 192; y++)
            for (int x = 0; x < 192; x++) {
                const struct nc_vec3 d =
                    nc_v3_unit(nc_quat_rotate(s.camera.attitude_q, nc_camera_dir(&s.camera, x, y)));
                double t, inside;
                struct nc_vec3 bn;
                if (!nc_test_mesh_hit(m, o, d, &t, &bn, &inside) || inside < 0.02)
                    continue;
                if (nc_v3_dot(bn, sd) < 0) {
                    dark_facets++;
                    lit_wrongly += f.radiance[y * 192 + x] > 0;
                }
            }
        nc_frame_free(&f);
        nc_scene_free(&s);
    }
    printf("smooth icosphere, phases 90-130 deg: %d pixels well inside facets turned from the Sun, %d lit\n",
           dark_facets, lit_wrongly);
    CHECK(dark_facets > 1000 && lit_wrongly == 0, "%d of %d pixels on facets turned from the Sun lit", lit_wrongly,
          dark_facets);
}

int main(void)
{
    backlit_facets();
    double flat = icosphere_error("flat"), smooth = icosphere_error("smooth");
    printf("icosphere of 1280 faces against the sphere: I/F RMS %.4f flat, %.4f smooth\n", flat, smooth);
    CHECK(smooth < 0.5 * flat, "smooth normals %.4f, flat %.4f", smooth, flat);

    /* A long comment header, unused vertices, normals, texture coordinates,
     * slashed and negative indices. */
    char obj[200000];
    size_t n = 0;
    for (int i = 0; i < 2000; i++)
        n += (size_t)snprintf(obj + n, sizeof obj - n, "# header line %d of a long provenance comment\n", i);
    snprintf(obj + n, sizeof obj - n,
             "o tetra\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 9 9 9\nv 8 8 8\nvn 0 0 1\nvt 0 0\n"
             "f 1 3 2\nf 1/1/1 2/1/1 4/1/1\nf 1//1 4//1 3//1\nf -5 -4 -3\ns off\n");
    struct nc_mesh m;
    int rc = nc_mesh_load(write_tmp("ok.obj", obj), 1000.0, &m);
    CHECK(rc == 0, "ok.obj: %s", nc_errmsg());
    if (rc == 0) {
        CHECK(m.nv == 6 && m.nt == 4, "ok.obj: %zu vertices %zu triangles", m.nv, m.nt);
        CHECK(m.v[3 * 1] == 1000.0, "km -> m scale");
        CHECK(m.tri[9] == 1 && m.tri[10] == 2 && m.tri[11] == 3, "negative indices: %u %u %u", m.tri[9], m.tri[10],
              m.tri[11]);
        CHECK(fabs(nc_mesh_bounding_radius(&m) - 1000.0) < 1e-9, "bounding radius ignores unused vertices: %g",
              nc_mesh_bounding_radius(&m));
        nc_mesh_free(&m);
    }
    expect_fail("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", "quad.obj:5: face with 4 vertices");
    expect_fail("range.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 7\n", "range.obj:5: face index 7 out of range");
    expect_fail("zero.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n", "zero.obj:4: face index 0 out of range");
    expect_fail("nan.obj", "v 0 0 0\nv nan 0 0\nv 1 1 0\nf 1 2 3\n", "nan.obj:2: vertex coordinate is not finite");
    expect_fail("far.obj", "v 0 0 0\nv 1e30 0 0\nv 1 1 0\nf 1 2 3\n",
                "far.obj: vertex 2 (counted from 1) lies 1e+30 m from the origin, beyond 1e+10 m");
    expect_fail("junk.obj", "v 0 0 0 junk\nv 1 0 0\nv 1 1 0\nf 1 2 3\n", "junk.obj:1: vertex: 'junk' after x y z");
    expect_fail("short.obj", "v 0 0\nf 1 1 1\n", "short.obj:1: vertex needs 3 numbers");
    expect_fail("empty.obj", "# nothing here\n", "mesh has no triangles");
    expect_fail("verts.obj", "v 0 0 0\nv 1 0 0\n", "mesh has no triangles");
    expect_fail("garbage.obj", "f x y z\n", "garbage.obj:1: bad face index 'x'");
    expect_fail("idxjunk.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1abc 2 3\n", "idxjunk.obj:4: bad face index '1abc'");
    expect_fail("idxparts.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1/-/+ 2 3\n", "idxparts.obj:4: bad face index '1/-/+'");
    /* corners with parts and a comment right after the last: read as before */
    rc = nc_mesh_load(write_tmp("parts.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1/1/1 2//2 3/3/#tri\nf -3/ -2/-2 -1#c\n"),
                      1.0, &m);
    CHECK(rc == 0 && m.nt == 2 && m.tri[2] == 2 && m.tri[3] == 0, "parts.obj: %s", rc < 0 ? nc_errmsg() : "wrong");
    if (rc == 0)
        nc_mesh_free(&m);
    expect_fail("idxreal.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2.5 3\n", "idxreal.obj:4: bad face index '2.5'");
    expect_fail("relative.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -1 -2 -7\n",
                "relative.obj:4: face index -7 out of range (3 vertices before it)");
    /* a byte-order mark before the first vertex: that vertex is read (every index would move otherwise) */
    rc = nc_mesh_load(write_tmp("bom.obj", "\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n"), 1.0, &m);
    CHECK(rc == 0 && m.nv == 3 && m.v[3] == 1 && m.v[7] == 1, "bom.obj: %s", rc < 0 ? nc_errmsg() : "wrong vertices");
    if (rc == 0)
        nc_mesh_free(&m);
    expect_fail("mesh.stl", "solid\n", "unknown mesh format");
    rc = nc_mesh_load(nc_test_path("missing.obj"), 1.0, &m);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "missing.obj: cannot open mesh"), "missing: %s", nc_errmsg());
    /* a NUL byte in a text format: the rest of its line would be lost unseen */
    static const struct {
        const char *name, *needle;
        char text[128];
        size_t len;
    } nul[] = {
#define NUL_CASE(name, needle, text) {name, needle, text, sizeof text - 1}
        NUL_CASE("nul.obj", "nul.obj:3: a NUL byte at column 8", "v 0 0 0\nv 1 0 0\nv 1 1 0\0 5\nf 1 2 3\n"),
        NUL_CASE("nul.ply", "nul.ply:8: a NUL byte at column 6",
                 "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                 "end_header\n0 0 0\0 7\n1 0 0\n0 1 0\n"),
        NUL_CASE("nulh.ply", "nulh.ply:2: a NUL byte at column 7", "ply\nformat\0ascii 1.0\nend_header\n"),
        NUL_CASE("nul.icq", "nul.icq:2: a NUL byte at column 6", "1\n0 0 1\0 2\n"),
#undef NUL_CASE
    };
    for (size_t i = 0; i < sizeof nul / sizeof nul[0]; i++) {
        nc_test_write_bytes(nc_test_path(nul[i].name), nul[i].text, nul[i].len);
        rc = nc_mesh_load(nc_test_path(nul[i].name), 1.0, &m);
        CHECK(rc < 0 && nc_test_contains(nc_errmsg(), nul[i].needle), "%s: %s", nul[i].name,
              rc < 0 ? nc_errmsg() : "loaded");
        if (rc >= 0)
            nc_mesh_free(&m);
    }

    /* PLY, ASCII with an extra element and property, then binary little and
     * big endian with double vertices and int indices. */
    const char *ply = "ply\nformat ascii 1.0\ncomment made by test_mesh\nelement vertex 4\nproperty float x\n"
                      "property float y\nproperty float z\nproperty uchar red\nelement face 2\n"
                      "property list uchar int vertex_indices\nelement extra 1\nproperty int k\nend_header\n"
                      "0 0 0 255\n1 0 0 0\n0 1 0 0\n0 0 1 0\n3 0 2 1\n3 0 1 3\n42\n";
    rc = nc_mesh_load(write_tmp("a.ply", ply), 1.0, &m);
    CHECK(rc == 0 && m.nv == 4 && m.nt == 2 && m.tri[5] == 3, "ascii ply: %s", nc_errmsg());
    if (rc == 0)
        nc_mesh_free(&m);
    /* le, be; then little-endian data under a big-endian header, and one byte more than the header announces */
    for (int k = 0; k < 4; k++) {
        const int be = k == 1;
        const char *name = k == 3 ? "extra.ply" : k == 2 ? "order.ply" : be ? "be.ply" : "le.ply";
        FILE *f = fopen(nc_test_path(name), "wb");
        fprintf(f, "ply\nformat %s 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
                   "element face 1\nproperty list uchar uint vertex_indices\nend_header\n",
                be || k == 2 ? "binary_big_endian" : "binary_little_endian");
        for (int i = 0; i < 9; i++) {
            double d = i == 4 ? 2.5 : (double)(i % 4 == 0);
            unsigned char b[8];
            memcpy(b, &d, 8);
            if (be)
                for (int j = 0; j < 4; j++) {
                    unsigned char t = b[j];
                    b[j] = b[7 - j];
                    b[7 - j] = t;
                }
            fwrite(b, 1, 8, f);
        }
        unsigned char cnt = 3;
        fwrite(&cnt, 1, 1, f);
        for (unsigned i = 0; i < 3; i++) {
            unsigned char b[4] = {0, 0, 0, 0};
            b[be ? 3 : 0] = (unsigned char)i;
            fwrite(b, 1, 4, f);
        }
        if (k == 3)
            fputs("\r\nx", f); /* a line end after binary data is fine, more is not */
        if (k == 1)
            fputc('\n', f);
        fclose(f);
        rc = nc_mesh_load(nc_test_path(name), 1.0, &m);
        if (k >= 2) {
            CHECK(rc < 0 && nc_test_contains(nc_errmsg(), k == 2 ? "face 0 (counted from 0): vertex index 1.67772e+07 "
                                                                   "out of range (3 vertices, counted from 0); is the "
                                                                   "byte order right?"
                                                                 : "extra.ply: data after the elements the header"),
                  "%s: %s", name, rc < 0 ? nc_errmsg() : "loaded");
            if (rc == 0)
                nc_mesh_free(&m);
            continue;
        }
        CHECK(rc == 0, "%s: %s", name, nc_errmsg());
        if (rc == 0) {
            CHECK(m.nv == 3 && m.nt == 1 && m.v[4] == 2.5 && m.tri[2] == 2, "%s content", name);
            nc_mesh_free(&m);
        }
    }
    expect_fail("quad.ply",
                "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                "4 0 1 2 3\n",
                "quad.ply:14: face 0: a face of 4 vertices");
    expect_fail("range.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n3 0 1 9\n",
                "range.ply:13: face 0: vertex index 9 out of range (3 vertices, counted from 0)");
    expect_fail("trunc.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0\n",
                "the header announces elements of at least 19 bytes, more than the 10 bytes after it hold");
    /* ASCII: an element a line, so a value missing or extra is named at its line, not shifted into the next */
    const char *ply3 = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    char text[512];
    snprintf(text, sizeof text, "%s0 0 0\n1 0\n1 1 0\n3 0 1 2\n", ply3);
    expect_fail("short.ply", text, "short.ply:11: vertex 1: the line ends before its properties do");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0 5\n1 1 0\n3 0 1 2\n", ply3);
    expect_fail("long.ply", text, "long.ply:11: vertex 1: more values on the line than its properties take ('5')");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n1 1 0\n3 0 1 2\n3 0 2 1\n\n", ply3);
    expect_fail("more.ply", text, "more.ply:14: data after the elements the header announces");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n1 x 0\n3 0 1 2\n", ply3);
    expect_fail("word.ply", text, "word.ply:12: vertex 2: 'x' is not a number");
    expect_fail("twice.ply", /* found by fuzz_readers: the first element's vertices were lost (leaked) */
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 1 1\n",
                "twice.ply: the PLY header declares a second vertex element");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n1 1 0\n\n", ply3);
    expect_fail("noface.ply", text, "noface.ply:13: the file ends at face 0 (counted from 0) of the 1 the header");
    expect_fail("nohdr.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "no end_header");
    expect_fail("huge.ply", /* 4e9 vertices announced: said so, not "out of memory" */
                "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n0 0 0\n",
                "the header announces elements of at least 23999999999 bytes, more than the 6 bytes after it hold");
    expect_fail("notply.ply", "hello\n", "not a PLY file");

    /* The procedural asteroid: closed, deterministic, the requested size. */
    struct nc_asteroid_params ap = {.radii_m = nc_v3(300, 250, 200), .subdivisions = 4, .seed = 3, .craters = 50,
                                    .lump_amplitude = 0.08};
    struct nc_mesh a, b;
    CHECK(nc_mesh_asteroid(&ap, &a) == 0 && nc_mesh_asteroid(&ap, &b) == 0, "asteroid");
    CHECK(a.nt == 20u * 256 && a.nv == 10u * 256 + 2, "icosphere counts %zu %zu", a.nt, a.nv);
    CHECK(!memcmp(a.v, b.v, a.nv * 3 * sizeof(double)), "asteroid deterministic");
    double rb = nc_mesh_bounding_radius(&a);
    CHECK(rb > 250 && rb < 420, "asteroid bounding radius %g", rb);
    nc_mesh_free(&a);
    nc_mesh_free(&b);
    return nc_test_end();
}
