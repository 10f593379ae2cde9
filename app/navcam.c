/* navcam.c - the `navcam` program: argument parsing and dispatch only.
 * Physics, scenes and files live in the libraries; keep this file thin. */
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "error.h"
#include "frame_io.h"
#include "image_io.h"
#include "material.h"
#include "camsys.h"
#include "render.h"
#include "scene.h"
#include "version.h"

static const char main_help[] =
    "Usage: navcam COMMAND [OPTIONS]\n"
    "\n"
    "NavCam emulates a spacecraft navigation camera: it ray-traces a planetary\n"
    "body from a camera pose and a Sun direction, in physical units.\n"
    "\n"
    "Commands:\n"
    "  render [SCENE.yaml] -o OUT   render one frame to an image file\n"
    "  expose CAMERA.yaml -o OUT    frames of a uniform radiance field through the camera model\n"
    "  serve [SCENE.yaml]           run the camera emulator (poses in, frames out)\n"
    "  replay TRAJ.csv              stream a trajectory to `navcam serve`\n"
    "  pose send ...                send one pose or trigger to `navcam serve`\n"
    "  scene                        print the built-in default scene (a starting point)\n"
    "  brdf --model NAME ...        evaluate a reflectance model (CSV in, CSV out)\n"
    "\n"
    "Options:\n"
    "  -h, --help      this help; `navcam COMMAND --help` for a command\n"
    "  -V, --version   print the version\n"
    "\n"
    "Examples:\n"
    "  navcam render -o frame.png                       # built-in default scene\n"
    "  navcam scene > my.yaml && navcam render my.yaml -o f.exr --quantity iof\n"
    "  navcam render my.yaml -o f.fits --set camera.position_m=[0,-3000,0]\n"
    "\n"
    "Configuration keys and units: docs/config.md.\n";

static const char render_help[] =
    "Usage: navcam render [SCENE.yaml] -o OUT [--set KEY=VALUE]... [options]\n"
    "\n"
    "Render one frame of SCENE.yaml (or of the built-in default scene) to OUT.\n"
    "\n"
    "  -o, --output FILE      output image; the extension picks the format:\n"
    "                           .exr .tif .fits  float32 physical values\n"
    "                           .png             16-bit linear preview, 65535 = the\n"
    "                                            brightest pixel; the scale is in the\n"
    "                                            file's metadata (navcam:preview_scale)\n"
    "  -q, --quantity Q       radiance   W m^-2 sr^-1 (default)\n"
    "                         iof        I/F = pi * radiance / solar irradiance\n"
    "                         range      distance camera-surface, m (0 = sky)\n"
    "                         electrons  noise-free photo-electrons through the optics\n"
    "                                    and PSF: the ground truth of a DN frame\n"
    "                         dn         the digitised frame: noise, full well, gain,\n"
    "                                    bias, ADC (16-bit files; 8-bit for an 8-bit ADC)\n"
    "  -e, --exposure T       exposure time in seconds (default: exposure.time_s)\n"
    "  -f, --frame N          frame number: keys the noise (default 0)\n"
    "  -s, --set KEY=VALUE    override any configuration key by its dotted path;\n"
    "                         VALUE is YAML. Repeatable. Lists index by number:\n"
    "                           --set camera.position_m=[0,0,-5000]\n"
    "                           --set bodies.0.material.w=0.07\n"
    "                           --set render.samples_per_pixel=16\n"
    "  -j, --threads N        render threads (default: render.threads, else all\n"
    "                         cores); the image does not depend on N\n"
    "  -h, --help             this help\n"
    "\n"
    "Conventions: positions in metres (double precision); quaternions scalar-first\n"
    "[w, x, y, z] rotating camera (or body) frame vectors into the scene frame;\n"
    "camera +Z is the boresight, +X right and +Y down in the image.\n"
    "Pose, Sun, units and the NavCam version are written into the file's metadata.\n";

int cmd_serve(int argc, char **argv);
int cmd_replay(int argc, char **argv);
int cmd_pose(int argc, char **argv);

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int fail(const char *cmd)
{
    fprintf(stderr, "navcam %s: %s\n", cmd, nc_errmsg());
    return 1;
}

/* Electrons (float) or a digitised frame of a rendered radiance image. */
static int write_sensor_frame(const char *out, const struct nc_frame *f, enum nc_quantity q, const struct nc_scene *s,
                              const struct nc_camsys *cs, double exposure, unsigned long long frame_no, double *scale)
{
    size_t n = (size_t)f->width_px * (size_t)f->height_px;
    float *e = malloc(n * sizeof *e);
    uint16_t *dn = malloc(n * sizeof *dn);
    struct nc_image_attr attrs[32];
    char text[32][200];
    int rc = e && dn ? nc_camsys_electrons(cs, f->radiance, exposure, e) : nc_error(-ENOMEM, "out of memory");
    int na = nc_frame_meta(s, q, attrs, text, 32);
    na += nc_camsys_meta(cs, exposure, frame_no, attrs + na, text + na, 32 - na);
    if (rc >= 0 && q == NC_Q_ELECTRONS)
        rc = nc_image_write(out, e, f->width_px, f->height_px, attrs, na, scale);
    else if (rc >= 0 && (rc = nc_camsys_digitise(cs, e, exposure, frame_no, dn)) >= 0)
        rc = nc_image_write_dn(out, dn, f->width_px, f->height_px, cs->sensor.adc_bits, attrs, na);
    free(e);
    free(dn);
    return rc;
}

static int cmd_render(int argc, char **argv)
{
    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"quantity", required_argument, NULL, 'q'},
        {"set", required_argument, NULL, 's'},    {"threads", required_argument, NULL, 'j'},
        {"exposure", required_argument, NULL, 'e'}, {"frame", required_argument, NULL, 'f'},
        {"help", no_argument, NULL, 'h'},         {NULL, 0, NULL, 0},
    };
    const char *out = NULL, *scene_path = NULL;
    double exposure = -1;
    unsigned long long frame_no = 0;
    const char **sets = calloc((size_t)argc, sizeof *sets);
    int nsets = 0, threads = 0, c;
    enum nc_quantity q = NC_Q_RADIANCE;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = getopt_long(argc, argv, "o:q:s:j:e:f:h", opts, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'e':
        case 'f': {
            char *end;
            double v = strtod(optarg, &end);
            if (*end || !(v >= 0) || !isfinite(v) || (c == 'e' && v > 3600) || (c == 'f' && v != floor(v))) {
                fprintf(stderr, "navcam render: --%s expects %s, got '%s'\n", c == 'e' ? "exposure" : "frame",
                        c == 'e' ? "seconds in 0..3600" : "a whole number >= 0", optarg);
                free(sets);
                return 2;
            }
            if (c == 'e')
                exposure = v;
            else
                frame_no = (unsigned long long)v;
            break;
        }
        case 's': sets[nsets++] = optarg; break;
        case 'j': {
            char *end;
            long v = strtol(optarg, &end, 10);
            if (*end || v < 1 || v > 1024) {
                fprintf(stderr, "navcam render: --threads expects 1..1024, got '%s'\n", optarg);
                free(sets);
                return 2;
            }
            threads = (int)v;
            break;
        }
        case 'q':
            if (nc_quantity_parse(optarg, &q) < 0) {
                free(sets);
                fprintf(stderr, "navcam render: %s\n", nc_errmsg());
                return 2;
            }
            break;
        case 'h': fputs(render_help, stdout); free(sets); return 0;
        default: fputs("Try 'navcam render --help'.\n", stderr); free(sets); return 2;
        }
    }
    if (optind < argc)
        scene_path = argv[optind++];
    if (optind < argc || !out) {
        fprintf(stderr, "navcam render: %s\nTry 'navcam render --help'.\n",
                !out ? "missing -o OUT" : "more than one scene file given");
        free(sets);
        return 2;
    }
    if (!nc_image_format_ok(out, NULL)) {
        fprintf(stderr, "navcam render: %s: unsupported output format (use .exr, .tif, .fits or .png)\n", out);
        free(sets);
        return 2;
    }
    /* Fail before rendering, not after, when OUT cannot be written. */
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", out);
    if (access(dirname(dir), W_OK) != 0) {
        fprintf(stderr, "navcam render: %s: cannot write into directory '%s': %s\n", out, dir, strerror(errno));
        free(sets);
        return 1;
    }
    struct nc_scene scene;
    struct nc_camsys cs;
    int rc = nc_setup_load(scene_path, sets, nsets, &scene, &cs);
    free(sets);
    if (rc < 0)
        return fail("render");
    if (exposure < 0)
        exposure = cs.exposure_s;
    struct nc_renderer r;
    struct nc_frame f = {0};
    double t0 = now_ms();
    if ((rc = nc_renderer_init(&r, &scene, threads)) < 0) {
        nc_scene_free(&scene);
        return fail("render");
    }
    double t1 = now_ms();
    rc = nc_frame_alloc(&f, scene.camera.width_px, scene.camera.height_px);
    /* Motion during the exposure (camera and body rates) and a rolling
     * shutter are integrated over the exposure window. */
    struct nc_exposure ex = {.exposure_s = exposure, .rolling = cs.sensor.shutter == NC_SHUTTER_ROLLING,
                             .line_time_s = cs.sensor.line_time_s};
    int tsamples = 1;
    if (rc >= 0)
        rc = nc_render_exposure(&r, &scene, &ex, &f, &tsamples);
    double t2 = now_ms(), scale = 0;
    if (rc >= 0 && q <= NC_Q_RANGE)
        rc = nc_frame_write(out, &f, q, &scene, &scale);
    else if (rc >= 0)
        rc = write_sensor_frame(out, &f, q, &scene, &cs, exposure, frame_no, &scale);
    if (rc >= 0) {
        printf("wrote %s: %dx%d %s [%s], %d samples/pixel, %d time sample%s, %d threads; scene setup %.1f ms, "
               "render %.1f ms\n",
               out, f.width_px, f.height_px, nc_quantity_names[q], nc_quantity_units(q), scene.render.samples_per_pixel,
               tsamples, tsamples == 1 ? "" : "s", r.threads, t1 - t0, t2 - t1);
        if (scale > 0)
            printf("  16-bit preview: 65535 = %.6g %s\n", scale, nc_quantity_units(q));
    }
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_scene_free(&scene);
    nc_camsys_free(&cs);
    return rc < 0 ? fail("render") : 0;
}

static const char brdf_help[] =
    "Usage: navcam brdf (--model NAME | --preset NAME) [--param KEY=VALUE]... [--geometry I,E,G]\n"
    "\n"
    "Evaluate a reflectance model. Angles in degrees: incidence i, emission e,\n"
    "phase g. With --geometry, print one row; otherwise read rows \"i,e,g\" from\n"
    "standard input (an optional header line first) and print one row each.\n"
    "Output columns, full double precision:\n"
    "  i_deg,e_deg,g_deg,r,brdf,radf,reff\n"
    "  r     bidirectional reflectance, 1/sr (radiance = r x solar irradiance)\n"
    "  brdf  r / cos i, 1/sr\n"
    "  radf  radiance factor I/F = pi r\n"
    "  reff  reflectance factor pi r / cos i\n"
    "i >= 90 or e >= 90 gives 0. Impossible geometries and out-of-range\n"
    "parameters are errors naming the input line or the key.\n"
    "\n"
    "  -m, --model NAME       lambert | lommel_seeliger | hapke | mcewen\n"
    "  -P, --preset NAME      a parameter set from the literature (comet_67p, moon)\n"
    "  -p, --param KEY=VALUE  a model parameter (repeatable; overrides the preset)\n"
    "  -g, --geometry I,E,G   one geometry instead of standard input\n"
    "      --no-header        do not print the column header\n"
    "  -l, --list             list models, their parameters and the presets\n"
    "  -h, --help             this help\n"
    "\n"
    "Parameters (defaults in brackets; 'required' has none):\n"
    "%s"
    "\n"
    "Examples:\n"
    "  navcam brdf --model hapke --param w=0.3 --param b=0.25 --param theta_bar=20 --geometry 30,0,30\n"
    "  printf 'i,e,g\\n30,30,0\\n60,0,60\\n' | navcam brdf --preset comet_67p\n";

static void describe_models(char *buf, size_t len)
{
    size_t pos = 0;
    for (int i = 0; nc_brdf_models[i] && pos < len; i++) {
        const struct nc_brdf_model *md = nc_brdf_models[i];
        pos += (size_t)snprintf(buf + pos, len - pos, "  %s: %s\n", md->name, md->description);
        for (int k = 0; k < md->nparams && pos < len; k++) {
            const struct nc_brdf_param *p = &md->params[k];
            char def[32];
            if (isnan(p->def))
                snprintf(def, sizeof def, "required");
            else
                snprintf(def, sizeof def, "%g", p->def);
            pos += (size_t)snprintf(buf + pos, len - pos, "    %-10s [%s] %g..%g %s: %s\n", p->key, def, p->min,
                                    p->max, p->unit, p->doc);
        }
    }
    for (int i = 0; nc_brdf_presets[i].name && pos < len; i++)
        pos += (size_t)snprintf(buf + pos, len - pos, "  preset %s (%s): %s\n    source: %s\n", nc_brdf_presets[i].name,
                                nc_brdf_presets[i].model, nc_brdf_presets[i].keys, nc_brdf_presets[i].source);
}

static int print_brdf_row(const struct nc_material *m, double i, double e, double g, const char *where)
{
    double out[4];
    if (nc_material_eval_deg(m, i, e, g, out) < 0) {
        fprintf(stderr, "navcam brdf: %s: %s\n", where, nc_errmsg());
        return -1;
    }
    printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", i, e, g, out[0], out[1], out[2], out[3]);
    return 0;
}

/* Three comma-separated numbers, nothing else. */
static int parse_geometry(const char *s, double v[3])
{
    const char *p = s;
    for (int k = 0; k < 3; k++) {
        char *end;
        while (*p == ' ' || *p == '\t')
            p++;
        v[k] = strtod(p, &end);
        if (end == p || !isfinite(v[k]))
            return -1;
        p = end;
        while (*p == ' ' || *p == '\t')
            p++;
        if (k < 2) {
            if (*p != ',')
                return -1;
            p++;
        }
    }
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
        p++;
    return *p ? -1 : 0;
}

static int cmd_brdf(int argc, char **argv)
{
    static const struct option opts[] = {
        {"model", required_argument, NULL, 'm'},    {"preset", required_argument, NULL, 'P'},
        {"param", required_argument, NULL, 'p'},    {"geometry", required_argument, NULL, 'g'},
        {"no-header", no_argument, NULL, 'H'},      {"list", no_argument, NULL, 'l'},
        {"help", no_argument, NULL, 'h'},           {NULL, 0, NULL, 0},
    };
    const char *model = NULL, *preset = NULL, *geometry = NULL;
    const char **params = calloc((size_t)argc + 1, sizeof *params);
    int nparams = 0, header = 1, c, rc = 2;
    char models[4096];
    struct nc_material m;
    memset(&m, 0, sizeof m);
    if (!params)
        return 1;
    describe_models(models, sizeof models);
    optind = 1;
    while ((c = getopt_long(argc, argv, "m:P:p:g:lh", opts, NULL)) != -1) {
        switch (c) {
        case 'm': model = optarg; break;
        case 'P': preset = optarg; break;
        case 'p': params[nparams++] = optarg; break;
        case 'g': geometry = optarg; break;
        case 'H': header = 0; break;
        case 'l': fputs(models, stdout); rc = 0; goto out;
        case 'h': printf(brdf_help, models); rc = 0; goto out;
        default: fputs("Try 'navcam brdf --help'.\n", stderr); goto out;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "navcam brdf: unexpected argument '%s'\nTry 'navcam brdf --help'.\n", argv[optind]);
        goto out;
    }
    if (!model && !preset) {
        fprintf(stderr, "navcam brdf: give --model NAME or --preset NAME\nTry 'navcam brdf --help'.\n");
        goto out;
    }
    rc = 1;
    if (preset) {
        if (nc_material_preset(&m, preset) < 0)
            goto fail;
        if (model && strcmp(model, m.model->name) != 0) {
            fprintf(stderr, "navcam brdf: preset '%s' is a %s material, not %s\n", preset, m.model->name, model);
            goto out;
        }
    } else if (nc_material_init(&m, model) < 0) {
        goto fail;
    }
    for (int k = 0; k < nparams; k++) {
        const char *eq = strchr(params[k], '=');
        char key[64], *end;
        if (!eq || eq == params[k] || (size_t)(eq - params[k]) >= sizeof key) {
            fprintf(stderr, "navcam brdf: --param expects KEY=VALUE, got '%s'\n", params[k]);
            goto out;
        }
        snprintf(key, sizeof key, "%.*s", (int)(eq - params[k]), params[k]);
        double v = strtod(eq + 1, &end);
        if (end == eq + 1 || *end || !isfinite(v)) {
            fprintf(stderr, "navcam brdf: --param %s: expected a finite number, got '%s'\n", key, eq + 1);
            goto out;
        }
        if (nc_material_set(&m, key, v) < 0)
            goto fail;
    }
    if (nc_material_finish(&m) < 0)
        goto fail;
    if (header)
        puts("i_deg,e_deg,g_deg,r,brdf,radf,reff");
    if (geometry) {
        double v[3];
        if (parse_geometry(geometry, v) < 0) {
            fprintf(stderr, "navcam brdf: --geometry expects I,E,G in degrees, got '%s'\n", geometry);
            goto out;
        }
        rc = print_brdf_row(&m, v[0], v[1], v[2], "--geometry") < 0 ? 1 : 0;
        goto out;
    }
    char *line = NULL;
    size_t cap = 0;
    long lineno = 0;
    rc = 0;
    while (getline(&line, &cap, stdin) > 0) {
        lineno++;
        double v[3];
        char where[64];
        snprintf(where, sizeof where, "stdin:%ld", lineno);
        if (line[strspn(line, " \t\r\n")] == '\0')
            continue; /* blank */
        if (parse_geometry(line, v) < 0) {
            if (lineno == 1 && !strpbrk(line, "0123456789"))
                continue; /* the optional header */
            line[strcspn(line, "\r\n")] = '\0';
            fprintf(stderr, "navcam brdf: %s: expected \"i,e,g\" in degrees, got \"%s\"\n", where, line);
            rc = 1;
            break;
        }
        if (print_brdf_row(&m, v[0], v[1], v[2], where) < 0) {
            rc = 1;
            break;
        }
    }
    free(line);
    goto out;
fail:
    fprintf(stderr, "navcam brdf: %s\n", nc_errmsg());
out:
    free(params);
    return rc;
}

static const char expose_help[] =
    "Usage: navcam expose CAMERA.yaml --radiance L --exposure T [--frames N] [--dark] -o OUT\n"
    "\n"
    "Apply the camera model (optics, PSF, detector, ADC) to a uniform radiance field\n"
    "and write N digitised frames: how a camera engineer checks a configuration and\n"
    "characterises it (photon transfer, dark current, linearity).\n"
    "\n"
    "  CAMERA.yaml            camera (intrinsics), optics, sensor and exposure sections;\n"
    "                         a whole scene file works too (its pose, bodies and Sun\n"
    "                         are ignored)\n"
    "  -L, --radiance L       uniform scene radiance, W m^-2 sr^-1\n"
    "  -e, --exposure T       exposure time, seconds (default: exposure.time_s)\n"
    "  -n, --frames N         number of frames (default 1), numbered from --first-frame\n"
    "      --first-frame K    frame number of the first frame (keys the noise; default 0)\n"
    "  -d, --dark             dark frames: no light (radiance 0)\n"
    "  -o, --output OUT       .fits: one FITS cube (NAXIS3 = N), 16-bit unsigned;\n"
    "                         .png/.tif/.exr: numbered files OUT_0000.ext, OUT_0001.ext, ...\n"
    "  -s, --set KEY=VALUE    override a configuration key (repeatable)\n"
    "  -h, --help             this help\n"
    "\n"
    "The noise of frame k depends only on the sensor seed and k: rerunning a command\n"
    "reproduces its frames bit for bit.\n"
    "Example:\n"
    "  navcam expose configs/examples/navcam_camera.yaml -L 5 -e 0.002 -n 16 -o flat.fits\n";

static int cmd_expose(int argc, char **argv)
{
    static const struct option opts[] = {
        {"radiance", required_argument, NULL, 'L'}, {"exposure", required_argument, NULL, 'e'},
        {"frames", required_argument, NULL, 'n'},   {"first-frame", required_argument, NULL, 'F'},
        {"dark", no_argument, NULL, 'd'},           {"output", required_argument, NULL, 'o'},
        {"set", required_argument, NULL, 's'},      {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    const char *out = NULL, *cam_path = NULL;
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    double L = -1, T = -1, nframes = 1, first = 0;
    int nsets = 0, dark = 0, c, rc = 2;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = getopt_long(argc, argv, "L:e:n:do:s:h", opts, NULL)) != -1) {
        char *end;
        double v = 0;
        if (c == 'L' || c == 'e' || c == 'n' || c == 'F') {
            v = strtod(optarg, &end);
            if (*end || !isfinite(v) || v < 0 || ((c == 'n' || c == 'F') && v != floor(v)) || (c == 'n' && (v < 1 || v > 100000))) {
                fprintf(stderr, "navcam expose: bad value '%s' for --%s\n", optarg,
                        c == 'L' ? "radiance" : c == 'e' ? "exposure" : c == 'n' ? "frames" : "first-frame");
                goto out;
            }
        }
        switch (c) {
        case 'L': L = v; break;
        case 'e': T = v; break;
        case 'n': nframes = v; break;
        case 'F': first = v; break;
        case 'd': dark = 1; break;
        case 'o': out = optarg; break;
        case 's': sets[nsets++] = optarg; break;
        case 'h': fputs(expose_help, stdout); rc = 0; goto out;
        default: fputs("Try 'navcam expose --help'.\n", stderr); goto out;
        }
    }
    if (optind < argc)
        cam_path = argv[optind++];
    if (!cam_path || optind < argc || !out || (L < 0 && !dark)) {
        fprintf(stderr, "navcam expose: %s\nTry 'navcam expose --help'.\n",
                !cam_path ? "missing CAMERA.yaml" : !out ? "missing -o OUT" : optind < argc ? "more than one camera file"
                                                                                          : "missing --radiance L (or --dark)");
        goto out;
    }
    if (!nc_image_format_ok(out, NULL)) {
        fprintf(stderr, "navcam expose: %s: unsupported output format (use .fits, .png, .tif or .exr)\n", out);
        goto out;
    }
    struct nc_camera geom;
    struct nc_camsys cs;
    rc = 1;
    if (nc_camsys_load(cam_path, sets, nsets, &geom, &cs) < 0) {
        fprintf(stderr, "navcam expose: %s\n", nc_errmsg());
        goto out;
    }
    if (T < 0)
        T = cs.exposure_s;
    if (dark)
        L = 0;
    size_t n = (size_t)geom.width_px * (size_t)geom.height_px, nf = (size_t)nframes;
    float *rad = malloc(n * sizeof *rad), *e = malloc(n * sizeof *e);
    uint16_t *dn = malloc(n * nf * sizeof *dn);
    int ok = rad && e && dn;
    for (size_t i = 0; ok && i < n; i++)
        rad[i] = (float)L;
    ok = ok && nc_camsys_electrons(&cs, rad, T, e) >= 0;
    int is_fits = strstr(out, ".fits") || strstr(out, ".fit") || strstr(out, ".fts");
    struct nc_image_attr attrs[16];
    char text[16][200], ltxt[64], ntxt[32];
    snprintf(ltxt, sizeof ltxt, "%.17g", L);
    snprintf(ntxt, sizeof ntxt, "%zu", nf);
    for (size_t k = 0; ok && k < nf; k++) {
        uint64_t fno = (uint64_t)first + k;
        ok = nc_camsys_digitise(&cs, e, T, fno, dn + k * n) >= 0;
        if (ok && !is_fits) {
            char path[4200];
            const char *dot = strrchr(out, '.');
            snprintf(path, sizeof path, "%.*s_%04llu%s", (int)(dot - out), out, (unsigned long long)fno, dot);
            int na = nc_camsys_meta(&cs, T, fno, attrs, text, 16);
            attrs[na++] = (struct nc_image_attr){"navcam:radiance_w_m2_sr", ltxt};
            ok = nc_image_write_dn(path, dn + k * n, geom.width_px, geom.height_px, cs.sensor.adc_bits, attrs, na) >= 0;
            if (ok)
                printf("wrote %s\n", path);
        }
    }
    if (ok && is_fits) {
        int na = nc_camsys_meta(&cs, T, (uint64_t)first, attrs, text, 16);
        attrs[na++] = (struct nc_image_attr){"navcam:radiance_w_m2_sr", ltxt};
        attrs[na++] = (struct nc_image_attr){"navcam:frames", ntxt};
        ok = nc_image_write_dn_cube(out, dn, geom.width_px, geom.height_px, (int)nf, cs.sensor.adc_bits, attrs, na) >= 0;
        if (ok)
            printf("wrote %s: %zu frames of %dx%d, %d-bit, radiance %g W m^-2 sr^-1, exposure %g s\n", out, nf,
                   geom.width_px, geom.height_px, cs.sensor.adc_bits, L, T);
    }
    if (!ok)
        fprintf(stderr, "navcam expose: %s\n", nc_errmsg()[0] ? nc_errmsg() : "out of memory");
    rc = ok ? 0 : 1;
    free(rad);
    free(e);
    free(dn);
    nc_camsys_free(&cs);
out:
    free(sets);
    return rc;
}

static int cmd_scene(int argc, char **argv)
{
    if (argc > 1 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help"))) {
        puts("Usage: navcam scene\n\nPrint the built-in default scene as YAML, to copy and edit.");
        return 0;
    }
    if (argc > 1) {
        fprintf(stderr, "navcam scene: takes no arguments\n");
        return 2;
    }
    fputs(nc_default_scene_yaml, stdout);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(main_help, stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        fputs(main_help, stdout);
        return 0;
    }
    if (!strcmp(cmd, "-V") || !strcmp(cmd, "--version")) {
        printf("navcam %s\n", NC_VERSION_STRING);
        return 0;
    }
    if (!strcmp(cmd, "render"))
        return cmd_render(argc - 1, argv + 1);
    if (!strcmp(cmd, "scene"))
        return cmd_scene(argc - 1, argv + 1);
    if (!strcmp(cmd, "brdf"))
        return cmd_brdf(argc - 1, argv + 1);
    if (!strcmp(cmd, "expose"))
        return cmd_expose(argc - 1, argv + 1);
    if (!strcmp(cmd, "serve"))
        return cmd_serve(argc - 1, argv + 1);
    if (!strcmp(cmd, "replay"))
        return cmd_replay(argc - 1, argv + 1);
    if (!strcmp(cmd, "pose"))
        return cmd_pose(argc - 1, argv + 1);
    fprintf(stderr, "navcam: unknown command '%s'\n\n%s", cmd, main_help);
    return 2;
}
