/* test_config.c - configuration errors name file, line, key and what was
 * expected; unknown keys are errors; --set overrides any key. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "testutil.h"

static const char base[] =
    "bodies:\n"
    "  - shape: {type: sphere, radius_m: 500}\n"
    "    material: {model: lambert, A: 0.1}\n"
    "sun:\n"
    "  direction: [1, 0, 0]\n"
    "camera:\n"
    "  width_px: 64\n"
    "  height_px: 48\n"
    "  focal_length_m: 0.05\n"
    "  pixel_pitch_m: 1e-5\n"
    "  position_m: [0, 0, -5000]\n"
    "  attitude_q: [1, 0, 0, 0]\n";

/* Load base with one line replaced (or appended), expect an error containing
 * every needle. */
static void expect_error(const char *what, const char *find, const char *repl, const char *const *sets, int nsets,
                         const char *n1, const char *n2)
{
    char yaml[4096];
    const char *at = find ? strstr(base, find) : NULL;
    if (find && !at) {
        CHECK(0, "%s: test setup, '%s' not in base", what, find);
        return;
    }
    if (at)
        snprintf(yaml, sizeof yaml, "%.*s%s%s", (int)(at - base), base, repl, at + strlen(find));
    else
        snprintf(yaml, sizeof yaml, "%s%s", base, repl ? repl : "");
    struct nc_scene s;
    int rc = nc_test_scene_rc(yaml, sets, nsets, &s);
    const char *msg = nc_errmsg();
    CHECK(rc < 0, "%s: expected an error", what);
    if (rc >= 0) {
        nc_scene_free(&s);
        return;
    }
    CHECK(nc_test_contains(msg, n1), "%s: message '%s' lacks '%s'", what, msg, n1);
    if (n2)
        CHECK(nc_test_contains(msg, n2), "%s: message '%s' lacks '%s'", what, msg, n2);
    printf("ok  %-28s -> %s\n", what, msg);
}

int main(void)
{
    struct nc_scene s;
    CHECK(nc_test_scene_rc(base, NULL, 0, &s) == 0, "base scene: %s", nc_errmsg());
    CHECK(s.camera.fx_px == 5000.0, "fx from focal length / pitch = %g", s.camera.fx_px);
    CHECK(s.camera.cx_px == 31.5 && s.camera.cy_px == 23.5, "centred principal point (%g, %g)", s.camera.cx_px,
          s.camera.cy_px);
    CHECK(s.sun.irradiance_w_m2 == 1361.0, "1 au irradiance %g", s.sun.irradiance_w_m2);
    { /* a whole number written as a decimal that is whole is taken; one that is not, refused */
        const char *sci[] = {"camera.width_px=6.4e1", "camera.height_px=48.0"};
        struct nc_scene w;
        const int rc = nc_test_scene_rc(base, sci, 2, &w);
        CHECK(rc == 0 && w.camera.width_px == 64 && w.camera.height_px == 48, "width 6.4e1, height 48.0: %s",
              rc ? nc_errmsg() : "other values");
        if (rc == 0)
            nc_scene_free(&w);
        const char *half[] = {"camera.width_px=64.5"}, *huge[] = {"camera.width_px=1e400"};
        expect_error("a whole number 64.5", NULL, NULL, half, 1,
                     "camera.width_px: expected a whole number, got \"64.5\"", NULL);
        expect_error("a whole number 1e400", NULL, NULL, huge, 1, "expected a whole number, got \"1e400\"", NULL);
    }
    { /* an 'up' along the line of sight is blamed on up, where it was given */
        const char *up[] = {"camera.attitude_q=null", "camera.look_at_m=[0, 0, 0]", "camera.up=[0, 0, 1]"};
        expect_error("up along the line of sight", NULL, NULL, up, 3, "--set camera.up=[0, 0, 1]: camera.up: look-at",
                     "parallel to the line of sight");
    }
    nc_scene_free(&s);

    expect_error("unknown key", "  width_px: 64\n", "  width_px: 64\n  exposure: 3\n", NULL, 0,
                 "test.yaml:8: camera.exposure", "unknown key");
    expect_error("unknown top-level key", NULL, "lights: 1\n", NULL, 0, "test.yaml:13: lights", "unknown key");
    expect_error("wrong type", "  position_m: [0, 0, -5000]\n", "  position_m: [0, zero, -5000]\n", NULL, 0,
                 "test.yaml:11: camera.position_m", "expected a number, got \"zero\"");
    expect_error("wrong length", "  position_m: [0, 0, -5000]\n", "  position_m: [0, -5000]\n", NULL, 0,
                 "camera.position_m", "expected a list of 3 numbers");
    expect_error("missing key", "  width_px: 64\n", "", NULL, 0, "camera.width_px", "missing required key");
    expect_error("null in a plain file", "  width_px: 64\n", "  width_px: ~\n", NULL, 0, "test.yaml:7: camera.width_px",
                 "got \"~\" (YAML's null: give a value, or leave the key out for its default)");
    expect_error("no value in a plain file", "  focal_length_m: 0.05\n", "  focal_length_m:\n", NULL, 0,
                 "test.yaml:9: camera.focal_length_m", "got \"\" (no value: give a value, or leave the key out");
    expect_error("missing key, misspelt", "  width_px: 64\n", "  widht_px: 64\n", NULL, 0,
                 "camera.width_px: missing required key", "'widht_px' (line 7) is not a key here: a misspelling");
    { /* KEY=null takes the key out: the file's f_number makes way for an aperture */
        const char *sets[] = {"optics.f_number=null", "optics.aperture_diameter_m=0.01"};
        struct nc_cfg cfg;
        nc_cfg_init(&cfg);
        CHECK(nc_cfg_load_scene(&cfg, NULL, sets, 2) == 0 && nc_cfg_get(nc_cfg_get(cfg.root, "optics"), "f_number") ==
                  NULL && nc_cfg_get(nc_cfg_get(cfg.root, "optics"), "aperture_diameter_m") != NULL,
              "--set optics.f_number=null: %s", nc_errmsg());
        nc_cfg_free(&cfg);
        const char *item[] = {"camera.width_px=~"};
        expect_error("a required key set to null", NULL, NULL, item, 1, "camera.width_px", "missing required key");
        const char *quoted[] = {"camera.width_px=\"null\""}; /* a word, not a null: the key stays */
        expect_error("a key set to \"null\" quoted", NULL, NULL, quoted, 1, "camera.width_px: expected a whole number, "
                     "got \"null\"", NULL);
    }
    expect_error("hexadecimal", "  pixel_pitch_m: 1e-5\n", "  pixel_pitch_m: 0x1p-17\n", NULL, 0,
                 "test.yaml:10: camera.pixel_pitch_m", "got \"0x1p-17\" (decimal digits: no hexadecimal)");
    /* One YAML document a file: a second one was dropped unseen, its keys neither read nor refused. */
    expect_error("a second YAML document", NULL, "---\ncamera:\n  width_px: 16\n", NULL, 0, "test.yaml:14",
                 "a second YAML document ('---'): one document a file");
    expect_error("a second document after '...'", NULL, "...\n---\nrender: {samples_per_pixel: 3}\n", NULL, 0,
                 "test.yaml:15", "a second YAML document");
    /* ... nor text that does not parse after the first: it was dropped unseen too */
    expect_error("keys after '...'", NULL, "...\ncamera: {width_px: 8}\n", NULL, 0, "test.yaml:14",
                 "YAML syntax error: did not find expected <document start> (text after the end of the value");
    {
        const char *two[] = {"camera.position_m=[0, -6000, 0] [0, -9000, 0]"}, *br[] = {"render={seed: 2}]"};
        expect_error("a --set with a second list", NULL, NULL, two, 1, "--set camera.position_m=[0, -6000, 0] [0, "
                     "-9000, 0]: YAML syntax error", "(text after the end of the value: one value, one document)");
        expect_error("a --set with a stray bracket", NULL, NULL, br, 1, "--set render={seed: 2}]: YAML syntax error",
                     NULL);
    }
    {
        struct nc_cfg cfg;
        nc_cfg_init(&cfg);
        CHECK(nc_cfg_load_string(&cfg, "---\n---\ncamera: {width_px: 8}\n", "two.yaml") < 0 &&
                  nc_test_contains(nc_errmsg(), "two.yaml:3: a second YAML document"),
              "a second document after an empty first: %s", nc_errmsg());
        nc_cfg_free(&cfg);
    }
    { /* KEY=null where nothing is: nothing to take out, and no parents made for it (an empty `stars:` was made,
       * and a second body: "bodies[1].shape: missing required key") */
        const char *sets[] = {"stars.magnitude_limit=null", "bodies.1.name=null", "optics.psf.sigma_px=null"};
        struct nc_scene t;
        const int rc = nc_test_scene_rc(base, sets, 3, &t);
        CHECK(rc == 0 && t.nbodies == 1, "null where nothing is: %s", rc < 0 ? nc_errmsg() : "a body more");
        if (rc == 0)
            nc_scene_free(&t);
    }
    { /* CR CR LF line ends (CR LF converted twice): errors name the line, not twice its number */
        char crcr[4096];
        size_t n = 0;
        for (const char *c = base; *c && n + 4 < sizeof crcr; c++)
            n += (size_t)snprintf(crcr + n, sizeof crcr - n, "%s", *c == '\n' ? "\r\r\n" : (char[2]){*c, 0});
        char *w = strstr(crcr, "width_px: 64");
        if (w)
            memcpy(w + 10, "6x", 2);
        const char *path = nc_test_path("crcr.yaml");
        nc_test_write(path, crcr);
        struct nc_cfg cfg;
        struct nc_scene t;
        nc_cfg_init(&cfg);
        CHECK(w && nc_cfg_load_file(&cfg, path) == 0 && nc_scene_read(&cfg, &t) < 0 &&
                  nc_test_contains(nc_errmsg(), "crcr.yaml:7: camera.width_px"),
              "CR CR LF: '%s'", nc_errmsg());
        nc_cfg_free(&cfg);
    }
    { /* an albedo map's image is read with the body's build: a mistake in a
       * later body's keys is reported first */
        const char *sets[] = {"bodies.0.material.albedo_map={file: missing.fits}",
                              "bodies.1={shape: {type: sphere, radius_m: 5}, material: {model: lambert, A: 0.1}, zz: 1}"};
        expect_error("albedo map read after every body's keys", NULL, NULL, sets, 2, "bodies[1].zz: unknown key",
                     NULL);
    }
    { /* a required key one level too high: named where it is */
        const char *sets[] = {"bodies.1={shape: {type: sphere}, radius_m: 200, material: {model: lambert, A: 0.1}}"};
        expect_error("required key one level up", NULL, NULL, sets, 1, "bodies[1].shape.radius_m: missing required key",
                     "'radius_m' is given in bodies[1] instead: move it into bodies[1].shape");
    }
    expect_error("missing key, cut short", "  width_px: 64\n", "  wid: 64\n", NULL, 0,
                 "camera.width_px: missing required key", "'wid' (line 7) is not a key here: a misspelling");
    { /* the key cut short, not a valid key one edit further away */
        const char *sets[] = {"bodies.0.shape={type: dem, file: x.fits, pixel_m: 1, on_sphere: {radius_m: 1e6, "
                              "lat: 0, lon_deg: 0}}"};
        expect_error("missing key beside a valid one", NULL, NULL, sets, 1, "on_sphere.lat_deg: missing required key",
                     "'lat' is not a key here: a misspelling of it?");
        const char *one_of[] = {
            "bodies.0.shape={type: asteroid, radii_m: [280, 230, 200], craters: {saturaton: 0.05}}"};
        expect_error("none of several keys, one misspelt", NULL, NULL, one_of, 1,
                     "bodies[0].shape.craters: give one of",
                     "'saturaton' is not a key here: a misspelling of 'saturation'?");
    }
    expect_error("out of range", "A: 0.1}", "A: 1.5}", NULL, 0, "test.yaml:3: bodies[0].material.A",
                 "expected a number in [0, 1]");
    expect_error("unknown model", "model: lambert", "model: phong", NULL, 0, "bodies[0].material.model",
                 "expected one of: lambert");
    expect_error("non-unit quaternion", "[1, 0, 0, 0]", "[1, 1, 0, 0]", NULL, 0, "camera.attitude_q",
                 "unit quaternion");
    expect_error("NaN", "radius_m: 500", "radius_m: .nan", NULL, 0, "bodies[0].shape.radius_m", "finite");
    expect_error("both intrinsics", "  pixel_pitch_m: 1e-5\n", "  pixel_pitch_m: 1e-5\n  fx_px: 100\n  fy_px: 100\n",
                 NULL, 0, "camera.", "not both");
    expect_error("duplicate key", "  height_px: 48\n", "  height_px: 48\n  height_px: 49\n", NULL, 0,
                 "test.yaml:9", "appears twice");
    expect_error("YAML syntax", "  height_px: 48\n", "  height_px: [48\n", NULL, 0, "test.yaml:", "YAML syntax error");
    expect_error("sun both ways", "  direction: [1, 0, 0]\n", "  direction: [1, 0, 0]\n  position_m: [1e11, 0, 0]\n",
                 NULL, 0, "sun.position_m", "not both");
    expect_error("Sun inside its radius", "  direction: [1, 0, 0]\n", "  position_m: [5000, -3000, 0]\n", NULL, 0,
                 "sun.position_m", "within its own radius");
    expect_error("missing mesh file", "{type: sphere, radius_m: 500}", "{type: mesh, file: nowhere.obj, unit: km}",
                 NULL, 0, "test.yaml:2: bodies[0].shape.file", "nowhere.obj: cannot open mesh");
    expect_error("mesh without unit", "{type: sphere, radius_m: 500}", "{type: mesh, file: x.obj}", NULL, 0,
                 "bodies[0].shape.unit", "m or km");
    expect_error("not a square spp", NULL, "render: {samples_per_pixel: 5}\n", NULL, 0, "render.samples_per_pixel",
                 "square number");
    {
        const char *sets[] = {"camera.exposure_s=0.1"};
        expect_error("--set unknown key", NULL, NULL, sets, 1, "--set camera.exposure_s=0.1", "unknown key");
    }
    { /* what the unknown-key message suggests: the nearest key, a key's place, the section's keys */
        const char *sets[] = {"camera.widht_px=64"};
        expect_error("typo", NULL, NULL, sets, 1, "camera.widht_px: unknown key; did you mean 'width_px'?",
                     "(this section takes: ");
        const char *cut[] = {"render.samples=4"};
        expect_error("key without its unit", NULL, NULL, cut, 1, "did you mean 'samples_per_pixel'?", "docs/config.md");
        const char *moved[] = {"bodies.0.radius_m=5"};
        expect_error("key in another section", NULL, NULL, moved, 1, "bodies[0].radius_m: unknown key; 'radius_m' is "
                     "read in bodies[0].shape", "(this section takes: name, shape,");
        const char *two[] = {"bodies.1={shape: {type: sphere, radius_m: 5}, material: {model: lambert, A: 0.1}, "
                             "position_m: [0, 0, 900]}", "bodies.0.radius_m=5"};
        expect_error("key in another section, two bodies", NULL, NULL, two, 2,
                     "bodies[0].radius_m: unknown key; 'radius_m' is read in bodies[0].shape", NULL);
        /* the Sun's and render settings are read and checked before any body is built */
        expect_error("render key before the bodies", "{type: sphere, radius_m: 500}",
                     "{type: mesh, file: nowhere.obj, unit: km}", cut, 1, "render.samples: unknown key", NULL);
        const char *cam[] = {"camera.widht_px=64"};
        expect_error("camera key before the bodies", "{type: sphere, radius_m: 500}",
                     "{type: mesh, file: nowhere.obj, unit: km}", cam, 1, "camera.widht_px: unknown key", NULL);
        /* and every body's keys before any body is built: a mistake in its
         * detail or material comes before its mesh is even opened */
        const char *rocks[] = {"bodies.0.boulders={preset: bennu, min_diameterm: 1}"};
        expect_error("boulder key before the mesh", "{type: sphere, radius_m: 500}",
                     "{type: mesh, file: nowhere.obj, unit: km}", rocks, 1,
                     "bodies[0].boulders.min_diameterm: unknown key; did you mean 'min_diameter_m'?", NULL);
        const char *swap[] = {"bodies.0.shape.relief={edge_m: 1, hurts: 0.5}"};
        expect_error("two letters swapped", "{type: sphere, radius_m: 500}",
                     "{type: mesh, file: nowhere.obj, unit: km}", swap, 1,
                     "bodies[0].shape.relief.hurts: unknown key; did you mean 'hurst'?", NULL);
        const char *mat[] = {"bodies.0.material.A=2"};
        expect_error("material before the mesh", "{type: sphere, radius_m: 500}",
                     "{type: mesh, file: nowhere.obj, unit: km}", mat, 1, "bodies[0].material.A", "[0, 1]");
        const char *second[] = {"bodies.1={shape: {type: sphere, radius_m: 5}, material: {model: lambert, A: 0.1}, "
                                "position_m: [0, 0, 900], colour: red}"};
        expect_error("second body before the first is built", "{type: sphere, radius_m: 500}",
                     "{type: mesh, file: nowhere.obj, unit: km}", second, 1, "bodies[1].colour: unknown key", NULL);
        const char *globe[] = {"bodies.0.shape={type: globe, radius_m: 1000, elevation_map: {file: nowhere.tif, "
                               "scael: 1}}"};
        expect_error("elevation map key before its image", NULL, NULL, globe, 1,
                     "bodies[0].shape.elevation_map.scael: unknown key; did you mean 'scale'?", NULL);
        const char *top[] = {"lights=1"};
        expect_error("unknown top-level key", NULL, NULL, top, 1, "lights: unknown key (the top level takes: camera, sun, render, bodies,",
                     NULL);
    }
    {
        const char *sets[] = {"camera.position_m=[0,0"};
        expect_error("--set bad YAML", NULL, NULL, sets, 1, "--set camera.position_m", "YAML syntax error");
    }
    {
        const char *sets[] = {"bodies.3.material.A=0.5"};
        expect_error("--set bad index", NULL, NULL, sets, 1, "--set bodies.3", "not an index");
    }

    /* Materials: presets, overrides of a preset, and their errors. */
    {
        const char *sets[] = {"bodies.0.material={preset: comet_67p, theta_bar: 20}"};
        CHECK(nc_test_scene_rc(base, sets, 1, &s) == 0, "preset: %s", nc_errmsg());
        CHECK(!strcmp(s.body[0].material.model->name, "hapke") && s.body[0].material.p[0] == 0.055 &&
                  s.body[0].material.p[7] == 20,
              "preset comet_67p with theta_bar override");
        nc_scene_free(&s);
    }
    {
        const char *sets[] = {"bodies.0.material={preset: vesta}"};
        expect_error("unknown preset", NULL, NULL, sets, 1, "bodies[0].material.preset", "unknown preset 'vesta'");
    }
    {
        const char *sets[] = {"bodies.0.material={preset: moon, model: lambert}"};
        expect_error("preset vs model", NULL, NULL, sets, 1, "bodies[0].material.model", "is a hapke material");
    }
    {
        const char *sets[] = {"bodies.0.material={model: hapke, b: 0.2}"};
        expect_error("hapke without w", NULL, NULL, sets, 1, "bodies[0].material", "parameter w is required");
    }
    {
        const char *sets[] = {"bodies.0.material={model: hapke, w: 0.2, B_C0: 1, h_C: 0}"};
        expect_error("h_C used but 0", NULL, NULL, sets, 1, "bodies[0].material", "h_C must be > 0 when B_C0 > 0");
    }
    {
        const char *sets[] = {"bodies.0.material={model: lommel_seeliger, w: 0.2, A: 0.1}"};
        expect_error("key of another model", NULL, NULL, sets, 1, "bodies[0].material.A", "unknown key");
    }

    /* Overrides: dotted paths into maps and lists; new keys; whole subtrees. */
    const char *sets[] = {"camera.position_m=[0,0,-7000]", "bodies.0.material.A=0.25", "bodies[0].position_m=[1,2,3]",
                          "sun={direction: [0, 1, 0], distance_au: 2}", "render.samples_per_pixel=9"};
    CHECK(nc_test_scene_rc(base, sets, 5, &s) == 0, "overrides: %s", nc_errmsg());
    CHECK(s.camera.position_m.z == -7000.0, "camera.position_m override");
    CHECK(s.body[0].material.p[0] == 0.25, "material override");
    CHECK(s.body[0].position_m.y == 2.0, "bodies[0] index syntax");
    CHECK(s.sun.direction.y == 1.0 && s.sun.irradiance_w_m2 == 1361.0 / 4, "sun subtree override, 1/d^2: %g",
          s.sun.irradiance_w_m2);
    CHECK(s.render.samples_per_pixel == 9, "new section created by --set");
    nc_scene_free(&s);
    /* a direction of any length: squares beyond a double's range are not a zero vector */
    for (int k = 0; k < 2; k++) {
        const char *dir[] = {k ? "sun.direction=[3e-200, -4e-200, 0]" : "sun.direction=[3e200, -4e200, 0]"};
        CHECK(nc_test_scene_rc(base, dir, 1, &s) == 0 && fabs(s.sun.direction.x - 0.6) < 1e-15 &&
                  fabs(s.sun.direction.y + 0.8) < 1e-15,
              "sun.direction %s: %s -> [%g, %g]", dir[0], nc_errmsg(), s.sun.direction.x, s.sun.direction.y);
        nc_scene_free(&s);
    }

    /* look_at: the target lands on the principal point. */
    const char *look[] = {"camera.attitude_q=null", "camera.look_at_m=[300, 200, 100]", "camera.up=[0, 1, 0]"};
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    nc_cfg_load_string(&cfg, base, "test.yaml");
    /* attitude_q=null takes the file's attitude out: the pose is the
     * look_at one, as in a file written without it (below). */
    for (int i = 0; i < 3; i++)
        nc_cfg_set(&cfg, look[i]);
    int rc = nc_scene_from_config(&cfg, &s);
    CHECK(rc == 0, "attitude_q=null with look_at_m: %s", nc_errmsg());
    struct nc_quat q_set = s.camera.attitude_q;
    if (rc == 0)
        nc_scene_free(&s);
    nc_cfg_free(&cfg);
    char yaml[4096];
    const char *at = strstr(base, "  attitude_q");
    snprintf(yaml, sizeof yaml, "%.*s  look_at_m: [300, 200, 100]\n  up: [0, 1, 0]\n", (int)(at - base), base);
    CHECK(nc_test_scene_rc(yaml, NULL, 0, &s) == 0, "look_at scene: %s", nc_errmsg());
    struct nc_vec3 boresight = nc_quat_rotate(s.camera.attitude_q, nc_v3(0, 0, 1));
    struct nc_vec3 want = nc_v3_unit(nc_v3_sub(nc_v3(300, 200, 100), s.camera.position_m));
    CHECK(nc_v3_norm(nc_v3_sub(boresight, want)) < 1e-12, "look_at boresight");
    CHECK(q_set.w == s.camera.attitude_q.w && q_set.x == s.camera.attitude_q.x && q_set.y == s.camera.attitude_q.y &&
              q_set.z == s.camera.attitude_q.z,
          "attitude_q=null and look_at_m on the command line: not the file's look_at pose");
    struct nc_vec3 img_up = nc_quat_rotate(s.camera.attitude_q, nc_v3(0, -1, 0));
    CHECK(nc_v3_dot(img_up, nc_v3(0, 1, 0)) > 0.9, "look_at 'up' appears up in the image");
    nc_scene_free(&s);

    /* base: builtin:default - a file laid over the built-in scene; errors
     * still name the file and line they come from. */
    char path[4096];
    snprintf(path, sizeof path, "%s", nc_test_path("over.yaml"));
    nc_test_write(path, "base: builtin:default\ncamera:\n  width_px: 64\n  height_px: 40\n");
    /* Read like `navcam render` does: the scene, then the camera model's
     * sections (optics, sensor, exposure) are the camera model's to check. */
    nc_cfg_init(&cfg);
    rc = nc_cfg_load_scene(&cfg, path, NULL, 0);
    if (rc >= 0)
        rc = nc_scene_read(&cfg, &s);
    CHECK(rc == 0, "overlay: %s", nc_errmsg());
    if (rc == 0) {
        CHECK(s.camera.width_px == 64 && s.camera.height_px == 40, "overlay: camera size %dx%d", s.camera.width_px,
              s.camera.height_px);
        CHECK(s.nbodies == 1 && s.camera.position_m.y == -6000, "overlay: the default scene's body and camera kept");
        CHECK(nc_cfg_get(cfg.root, "optics") != NULL, "overlay: the default camera model kept");
        nc_scene_free(&s);
    }
    nc_cfg_free(&cfg);
    nc_test_write(path, "base: builtin:default\ncamera:\n  width_px: 64\n  height_px: forty\n");
    rc = nc_scene_load(path, NULL, 0, &s);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "over.yaml:4: camera.height_px"), "overlay error: %s", nc_errmsg());
    /* key: null in the file laid over takes the base's key out (~, and a
     * key with nothing after it: an error before): the look-at camera of
     * the default scene becomes one given by its attitude */
    nc_test_write(path, "base: builtin:default\ncamera:\n  look_at_m: ~\n  up:\n  attitude_q: [1, 0, 0, 0]\n");
    nc_cfg_init(&cfg);
    rc = nc_cfg_load_scene(&cfg, path, NULL, 0);
    if (rc >= 0)
        rc = nc_scene_read(&cfg, &s);
    CHECK(rc == 0 && s.camera.attitude_q.w == 1 && s.camera.attitude_q.x == 0, "overlay with null: %s", nc_errmsg());
    if (rc == 0)
        nc_scene_free(&s);
    nc_cfg_free(&cfg);
    nc_test_write(path, "base: builtin:nothing\n");
    rc = nc_scene_load(path, NULL, 0, &s);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "over.yaml:1: base: unknown base"), "bad base: %s", nc_errmsg());
    static const char nul[] = "base: builtin:default\ncamera:\n  width_px: 64\0 # and the rest\n";
    nc_test_write_bytes(path, nul, sizeof nul - 1);
    rc = nc_scene_load(path, NULL, 0, &s);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "over.yaml:3: a NUL byte at column 15"), "NUL: %s", nc_errmsg());

    /* YAML aliases of aliases (nine times a level: a few lines, billions of values) are refused once the
     * tree passes the limit; nesting too deep is refused before libyaml's scanner, slow at depth, goes on. */
    char *bomb = malloc(4096), *deep = malloc(200010);
    if (bomb && deep) {
        int n = snprintf(bomb, 4096, "a: &l0 [x, x, x, x, x, x, x, x, x]\n");
        for (int i = 1; i < 10; i++)
            n += snprintf(bomb + n, 4096 - (size_t)n,
                          "l%d: &l%d [*l%d, *l%d, *l%d, *l%d, *l%d, *l%d, *l%d, *l%d, *l%d]\n", i, i, i - 1, i - 1,
                          i - 1, i - 1, i - 1, i - 1, i - 1, i - 1, i - 1);
        nc_cfg_init(&cfg);
        CHECK(nc_cfg_load_string(&cfg, bomb, "bomb.yaml") < 0 &&
                  nc_test_contains(nc_errmsg(), "the configuration expands to more than 200000 values"),
              "alias bomb: %s", nc_errmsg());
        nc_cfg_free(&cfg);
        memset(deep, '[', 100000), memset(deep + 100000, ']', 100000), deep[200000] = '\0';
        nc_cfg_init(&cfg);
        CHECK(nc_cfg_load_string(&cfg, deep, "deep.yaml") < 0 &&
                  nc_test_contains(nc_errmsg(), "deep.yaml:1: nesting deeper than 32 levels"),
              "deep nesting: %s", nc_errmsg());
        nc_cfg_free(&cfg);
        /* a --set value has no lines: its errors name the --set alone */
        const char *set[] = {"camera={a: [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]}",
                             "camera={a: 1, a: 2}"};
        const char *needle[] = {"]}: nesting deeper than 32 levels", "2}: key 'a' appears twice in the same map"};
        for (int i = 0; i < 2; i++) {
            nc_cfg_init(&cfg);
            CHECK(nc_cfg_set(&cfg, set[i]) < 0 && nc_test_contains(nc_errmsg(), needle[i]), "--set %s: %s", set[i],
                  nc_errmsg());
            nc_cfg_free(&cfg);
        }
    }
    free(bomb), free(deep);

    /* A --set key path is names joined by '.' with list items as [N] or .N; anything else is refused (an empty
     * name or a stray bracket was dropped: camera..width_px set camera.width_px, bodies[[0].material.A the
     * material's A) */
    const char *bad_keys[] = {"camera..width_px=3", ".camera.width_px=3", "camera.width_px.=3", "camera.width]_px=3",
                              "bodies[0.material.A=0.2", "bodies[[0].material.A=0.2", "bodies[]=1", "a[0]b=1"};
    for (size_t i = 0; i < sizeof bad_keys / sizeof bad_keys[0]; i++) {
        nc_cfg_init(&cfg);
        CHECK(nc_cfg_set(&cfg, bad_keys[i]) < 0 && nc_test_contains(nc_errmsg(), "is no key path"), "--set %s: %s",
              bad_keys[i], nc_errmsg());
        nc_cfg_free(&cfg);
    }
    nc_cfg_init(&cfg);
    CHECK(nc_cfg_set(&cfg, "bodies[0.material.A=0.2") < 0 &&
              nc_test_contains(nc_errmsg(), "--set bodies[0.material.A=0.2: 'bodies[0.material.A' is no key path (at "
                                            "its character 9, '.')"),
          "the error says where: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    nc_cfg_init(&cfg);
    CHECK(nc_cfg_set(&cfg, "a=[[1, 2]]") == 0 && nc_cfg_set(&cfg, "a[0][1]=5") == 0 && nc_cfg_set(&cfg, "a.0.0=4") == 0,
          "a[0][1] and a.0.0: %s", nc_errmsg());
    struct nc_cfg_node *a0 = nc_cfg_get(cfg.root, "a")->child[0];
    CHECK(!strcmp(a0->child[0]->value, "4") && !strcmp(a0->child[1]->value, "5"), "a[0] = [%s, %s]",
          a0->child[0]->value, a0->child[1]->value);
    nc_cfg_free(&cfg);

    /* An error about a key names it at its line, or at its map's when it is absent (a default that failed);
     * one about no node at all (nc_cfg_get of an absent key) still gives the message. */
    nc_cfg_init(&cfg);
    nc_cfg_load_string(&cfg, "outputs:\n  - driver: hello\n    path: /x\n", "drv.yaml");
    struct nc_cfg_node *out0 = nc_cfg_get(cfg.root, "outputs")->child[0];
    CHECK(nc_cfg_key_error(out0, "path", "cannot open") < 0 &&
              !strcmp(nc_errmsg(), "drv.yaml:3: outputs[0].path: cannot open"), "present key: %s", nc_errmsg());
    CHECK(nc_cfg_key_error(out0, "every", "bad default %d", 3) < 0 &&
              !strcmp(nc_errmsg(), "drv.yaml:2: outputs[0].every: bad default 3"), "absent key: %s", nc_errmsg());
    CHECK(nc_cfg_error(nc_cfg_get(out0, "every"), "no node") < 0 && !strcmp(nc_errmsg(), "config: no node"),
          "no node: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    return nc_test_end();
}
