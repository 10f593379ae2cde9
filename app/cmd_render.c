/* cmd_render.c - `navcam render`: one frame of a scene to an image file
 * (radiance, I/F, range, electrons or DN). Argument parsing only; links the
 * renderer and the camera model, never the emulator. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/cli.h"
#include "camera/camsys.h"
#include "camera/load.h"
#include "camera/shot.h"
#include "core/clock.h"
#include "core/error.h"
#include "render/frame_io.h"
#include "render/image_io.h"
#include "render/render.h"
#include "render/scene.h"

static const char render_help[] =
    "Usage: navcam render [SCENE.yaml] -o OUT [--set KEY=VALUE]... [options]\n"
    "\n"
    "Render one frame of SCENE.yaml (or of the built-in default scene) to OUT.\n"
    "\n"
    "  -o, --output FILE      output image; the extension (any case) picks the format:\n"
    "                           .exr .tif/.tiff .fits/.fit/.fts  float32 physical values\n"
    "                           .png             16-bit linear preview, 65535 = the\n"
    "                                            brightest pixel; the scale is in the\n"
    "                                            file's metadata (navcam:preview_scale)\n"
    "  -q, --quantity Q       radiance   W m^-2 sr^-1 (default)\n"
    "                         iof        I/F = pi * radiance / solar irradiance\n"
    "                         range      distance camera-surface, m (0 = sky)\n"
    "                         rock_id    the boulder each pixel shows: its index in\n"
    "                                    its body's list (exact in float32 files up\n"
    "                                    to 2^24), -1 for ground or sky; FITS, TIFF\n"
    "                                    or EXR (not PNG)\n"
    "                         electrons  noise-free photo-electrons through the optics\n"
    "                                    and PSF: the ground truth of a DN frame\n"
    "                         dn         the digitised frame: noise, full well, gain,\n"
    "                                    bias, ADC (16-bit PNG, TIFF and FITS, 8-bit\n"
    "                                    for an 8-bit ADC; float32 EXR)\n"
    "  -e, --exposure T       exposure time in seconds, 0 to 3600 (default:\n"
    "                         exposure.time_s)\n"
    "  -f, --frame N          frame number: keys the noise (default 0)\n"
    "  -s, --set KEY=VALUE    override any configuration key by its dotted path;\n"
    "                         VALUE is YAML. Repeatable. Lists index by number;\n"
    "                         KEY=null takes a key out:\n"
    "                           --set camera.position_m=[0,-3000,0]\n"
    "                           --set bodies.0.material.w=0.07\n"
    "                           --set render.samples_per_pixel=16\n"
    "                           --set optics.f_number=null --set optics.aperture_diameter_m=0.01\n"
    "  -j, --threads N        render threads, 0 to 1024 (default: render.threads, else\n"
    "                         all cores; 0: all cores); the image does not depend on N\n"
    "      --sumfile X.SUM    the camera and pose of an SPC SUM file: replaces the\n"
    "                         camera section with {sumfile: X.SUM} and takes\n"
    "                         sun.direction out (the Sun's direction comes from it\n"
    "                         too); give its distance with --set sun.distance_au=D\n"
    "                         (docs/sumfiles.md)\n"
    "      --fits-rows ORDER  .fits only: top_down (default: row 1 is the top image\n"
    "                         row, y = 0) or bottom_up (row 1 at the bottom, as FITS\n"
    "                         viewers and mission archives show it); the keyword\n"
    "                         ROWORDER records which\n"
    "  -h, --help             this help\n"
    "\n"
    "Conventions: positions in metres (double precision); quaternions scalar-first\n"
    "[w, x, y, z] rotating camera (or body) frame vectors into the scene frame;\n"
    "camera +Z is the boresight, +X right and +Y down in the image.\n"
    "Pose, Sun, units and the NavCam version are written into the file's metadata.\n";

static double now_ms(void) { return (double)nc_mono_ns() * 1e-6; }

int main(int argc, char **argv)
{
    nc_cli_init("render");
    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"quantity", required_argument, NULL, 'q'},
        {"set", required_argument, NULL, 's'},    {"threads", required_argument, NULL, 'j'},
        {"exposure", required_argument, NULL, 'e'}, {"frame", required_argument, NULL, 'f'},
        {"fits-rows", required_argument, NULL, 'R'}, {"sumfile", required_argument, NULL, 'S'},
        {"help", no_argument, NULL, 'h'},         {NULL, 0, NULL, 0},
    };
    const char *out = NULL, *scene_path = NULL, *rows = NULL;
    double exposure = -1;
    unsigned long long frame_no = 0;
    const char **sets = calloc(2 * (size_t)argc + 2, sizeof *sets); /* --sumfile=X adds two */
    char sumset[4200];
    int nsets = 0, threads = 0, c;
    enum nc_quantity q = NC_Q_RADIANCE;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "o:q:s:j:e:f:h", opts)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'R': rows = optarg; break;
        case 'S': /* first, so that --set camera.X=... can still add to it */
            nc_cli_sumfile(sets, &nsets, sumset, sizeof sumset, optarg);
            break;
        case 'e':
            if (nc_cli_double("exposure", optarg, 0, 3600, &exposure) < 0) {
                free(sets);
                return 2;
            }
            break;
        case 'f':
            if (nc_cli_whole(optarg, &frame_no) < 0) {
                fprintf(stderr, "navcam render: --frame expects a whole number 0..18446744073709551615, got '%s'\n",
                        optarg);
                free(sets);
                return 2;
            }
            break;
        case 's': sets[nsets++] = optarg; break;
        case 'j':
            if (nc_cli_threads(optarg, &threads) < 0) {
                free(sets);
                return 2;
            }
            break;
        case 'q':
            if (nc_quantity_parse(optarg, &q) < 0) {
                free(sets);
                fprintf(stderr, "navcam render: --quantity: %s\n", nc_errmsg());
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
        fprintf(stderr, "navcam render: %s: unsupported output format (use .exr, .tif or .tiff, .fits, .fit or .fts, "
                        "or .png, in any case)\n", out);
        free(sets);
        return 2;
    }
    if (nc_quantity_format_check(q, out) < 0) {
        fprintf(stderr, "navcam render: %s: %s\n", out, nc_errmsg());
        free(sets);
        return 2;
    }
    if (rows && (!nc_image_is_fits(out) || nc_image_fits_row_order_ok(rows) < 0)) {
        fprintf(stderr, "navcam render: --fits-rows: %s\n",
                !nc_image_is_fits(out) ? "applies to .fits output only" : nc_errmsg());
        free(sets);
        return 2;
    }
    const struct nc_image_attr row_attr = {"navcam:fits_row_order", rows ? rows : "top_down"};
    if (nc_cli_dir_writable(out) < 0) { /* fail before rendering, not after */
        free(sets);
        return 1;
    }
    struct nc_scene scene;
    struct nc_camsys cs;
    struct nc_sky sky;
    const double tl = now_ms();
    int rc = nc_shot_setup(scene_path, sets, nsets, &scene, &cs, &sky);
    free(sets);
    if (rc < 0)
        return nc_cli_fail();
    if (exposure < 0)
        exposure = cs.exposure_s;
    struct nc_renderer r;
    const double t0 = now_ms();
    if ((rc = nc_renderer_init(&r, &scene, threads)) < 0) {
        nc_scene_free(&scene);
        nc_sky_free(&sky);
        return nc_cli_fail();
    }
    double t1 = now_ms();
    /* The image library now (OpenImageIO for EXR, TIFF, PNG), not after the
     * render; after the configuration, whose mistakes need none of it. */
    if ((rc = nc_image_prepare(out)) < 0) {
        nc_renderer_free(&r);
        nc_scene_free(&scene);
        nc_sky_free(&sky);
        return nc_cli_fail();
    }
    struct nc_shot_info info;
    const struct nc_image_attr *extra = rows ? &row_attr : NULL;
    rc = nc_shot(&r, &scene, &cs, &sky, q, exposure, 0, frame_no, out, extra, rows ? 1 : 0, &info);
    double t2 = t1 + info.render_ms + info.stars_ms, scale = info.preview_scale;
    const int tsamples = info.time_samples;
    const char *chosen = info.quality, *sunwarn = info.sun_warning;
    const struct nc_sky_stats sst = info.stars;
    const struct nc_sun_view sv = info.sun;
    if (rc >= 0) {
        printf("wrote %s: %dx%d %s [%s], %d samples/pixel, %d time sample%s, %d threads; scene built in %.1f ms, "
               "renderer set up in %.1f ms, render %.1f ms\n",
               out, scene.camera.width_px, scene.camera.height_px, nc_quantity_names[q], nc_quantity_units(q), scene.render.samples_per_pixel,
               tsamples, tsamples == 1 ? "" : "s", r.threads, t0 - tl, t1 - t0, t2 - t1);
        if (chosen[0])
            printf("  render.quality auto: %s; the pilots took %.1f ms\n", chosen, info.quality_ms);
        if (sunwarn[0])
            printf("  WARNING: %s (its centre %.2f deg off axis)\n", sunwarn, sv.off_axis_deg);
        if (info.inside_warning[0])
            printf("  WARNING: %s\n", info.inside_warning);
        if (sky.on)
            printf("  stars: to V %.2f, %ld in the frame, %ld hidden by bodies (%.1f ms)\n", sst.limit_mag, sst.drawn,
                   sst.hidden, info.stars_ms);
        if (scene.render.lod_error_px > 0)
            printf("  levels of detail: surface error bound %.3g m (render.lod_error_px %g)\n", nc_rt_lod_error_m(r.rt),
                   scene.render.lod_error_px);
        struct nc_rt_stats st;
        nc_rt_get_stats(r.rt, &st);
        for (int i = 0; i < scene.nbodies; i++)
            if (scene.body[i].boulders.n) {
                if (st.boulder_min_m[i] > 0)
                    printf("  boulders of '%s': %zu of %zu traced, %.3g m and larger (%g px)", scene.body[i].name,
                           st.boulders_traced[i], scene.body[i].boulders.n, st.boulder_min_m[i],
                           nc_scene_boulder_min_px(&scene, i));
                else
                    printf("  boulders of '%s': all %zu traced (%g px)", scene.body[i].name, scene.body[i].boulders.n,
                           nc_scene_boulder_min_px(&scene, i));
                int k = nc_material_roughness_param(&scene.body[i].material);
                if (r.fold_theta_bar_deg[i] >= 0)
                    printf("; the rest (cover %.3g) folded into the reflectance: theta_bar %.3g -> %.3g deg\n",
                           st.boulder_cut_cover[i], scene.body[i].material.p[k], r.fold_theta_bar_deg[i]);
                else if (st.boulder_cut_cover[i] > 0)
                    printf("; the rest (cover %.3g) NOT folded in (%s)\n", st.boulder_cut_cover[i],
                           k < 0 ? "the material has no roughness parameter" : "render.boulder_fold is false");
                else
                    printf("\n");
                if (st.boulder_mesh_px[i] > 0)
                    printf("  rough rocks spanning %g px or more traced as detailed surfaces (%zu triangles a "
                           "shape, %.3g effective)\n", st.boulder_mesh_px[i], nc_rt_rock_mesh_triangles(r.rt, i),
                           (double)nc_rt_rock_mesh_triangles(r.rt, i) * (double)st.boulders_traced[i]);
            }
        if (scale > 0)
            printf("  16-bit preview: 65535 = %.6g %s\n", scale, nc_quantity_units(q));
    }
    nc_renderer_free(&r);
    nc_scene_free(&scene);
    nc_camsys_free(&cs);
    nc_sky_free(&sky);
    return rc < 0 ? nc_cli_fail() : 0;
}
