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
    "  -q, --quantity Q       radiance  W m^-2 sr^-1 (default)\n"
    "                         iof       I/F = pi * radiance / solar irradiance\n"
    "                         range     distance camera-surface, m (0 = sky)\n"
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

static int cmd_render(int argc, char **argv)
{
    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"quantity", required_argument, NULL, 'q'},
        {"set", required_argument, NULL, 's'},    {"threads", required_argument, NULL, 'j'},
        {"help", no_argument, NULL, 'h'},         {NULL, 0, NULL, 0},
    };
    const char *out = NULL, *scene_path = NULL;
    const char **sets = calloc((size_t)argc, sizeof *sets);
    int nsets = 0, threads = 0, c;
    enum nc_quantity q = NC_Q_RADIANCE;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = getopt_long(argc, argv, "o:q:s:j:h", opts, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
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
    int rc = nc_scene_load(scene_path, sets, nsets, &scene);
    free(sets);
    if (rc < 0)
        return fail("render");
    struct nc_renderer r;
    struct nc_frame f = {0};
    double t0 = now_ms();
    if ((rc = nc_renderer_init(&r, &scene, threads)) < 0) {
        nc_scene_free(&scene);
        return fail("render");
    }
    double t1 = now_ms();
    rc = nc_frame_alloc(&f, scene.camera.width_px, scene.camera.height_px);
    if (rc >= 0)
        rc = nc_render_frame(&r, &scene, &f);
    double t2 = now_ms(), scale = 0;
    if (rc >= 0)
        rc = nc_frame_write(out, &f, q, &scene, &scale);
    if (rc >= 0) {
        printf("wrote %s: %dx%d %s [%s], %d samples/pixel, %d threads; scene setup %.1f ms, render %.1f ms\n", out,
               f.width_px, f.height_px, nc_quantity_names[q], nc_quantity_units(q), scene.render.samples_per_pixel,
               r.threads, t1 - t0, t2 - t1);
        if (scale > 0)
            printf("  16-bit preview: 65535 = %.6g %s\n", scale, nc_quantity_units(q));
    }
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_scene_free(&scene);
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
    fprintf(stderr, "navcam: unknown command '%s'\n\n%s", cmd, main_help);
    return 2;
}
