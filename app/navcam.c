/* navcam.c - the `navcam` program: argument parsing and dispatch only.
 * Physics, scenes and files live in the libraries; keep this file thin. */
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "error.h"
#include "frame_io.h"
#include "image_io.h"
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
    "                           --set bodies.0.material.A=0.12\n"
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
    fprintf(stderr, "navcam: unknown command '%s'\n\n%s", cmd, main_help);
    return 2;
}
