/* cmd_expose.c - `navcam expose`: frames of a uniform radiance field
 * through the camera model (flats, darks, photon transfer). Links the
 * camera model, never the renderer's ray tracing or the emulator. */
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "app/cli.h"
#include "camera/camsys.h"
#include "camera/load.h"
#include "camera/shot.h"
#include "core/error.h"
#include "core/version.h"
#include "render/image_io.h"

static const char expose_help[] =
    "Usage: navcam expose CAMERA.yaml --radiance L [--exposure T] [--frames N] [--dark] -o OUT\n"
    "\n"
    "Apply the camera model (optics, PSF, detector, ADC) to a uniform radiance field\n"
    "and write N digitised frames: how a camera engineer checks a configuration and\n"
    "characterises it (photon transfer, dark current, linearity).\n"
    "\n"
    "  CAMERA.yaml            camera (intrinsics), optics, sensor and exposure sections;\n"
    "                         a whole scene file works too, read as render reads it\n"
    "                         (base: builtin:default; its pose, camera rates, bodies\n"
    "                         and Sun are ignored); a mirrored SUM camera's frames are\n"
    "                         stored as render stores them\n"
    "  -L, --radiance L       uniform scene radiance, W m^-2 sr^-1 (0 or more)\n"
    "  -e, --exposure T       exposure time, seconds, 0 to 3600 (default: exposure.time_s)\n"
    "  -n, --frames N         number of frames, 1 to 100000 (default 1), numbered from\n"
    "                         --first-frame\n"
    "      --first-frame K    frame number of the first frame (keys the noise; default 0)\n"
    "  -d, --dark             dark frames: no light (radiance 0)\n"
    "  -o, --output OUT       .fits: one FITS cube (NAXIS3 = N; one frame: a 2-D image),\n"
    "                         16-bit unsigned (8-bit for an 8-bit ADC);\n"
    "                         .png/.tif/.exr: numbered files OUT_0000.ext, OUT_0001.ext, ...\n"
    "      --fits-rows ORDER  .fits only: top_down (default: row 1 is the top image\n"
    "                         row) or bottom_up (row 1 at the bottom, as FITS viewers\n"
    "                         and mission archives show it); keyword ROWORDER\n"
    "  -s, --set KEY=VALUE    override a configuration key (repeatable)\n"
    "  -h, --help             this help\n"
    "\n"
    "The noise of frame k depends only on the sensor seed and k: rerunning a command\n"
    "reproduces its frames bit for bit.\n"
    "Examples (the first from a NavCam checkout; the second anywhere, with the\n"
    "built-in default scene's camera):\n"
    "  navcam expose configs/examples/navcam_camera.yaml -L 5 -e 0.002 -n 16 -o flat.fits\n"
    "  navcam scene > cam.yaml && navcam expose cam.yaml -L 5 -n 16 -o flat.fits\n";

int main(int argc, char **argv)
{
    nc_cli_init("expose");
    static const struct option opts[] = {
        {"radiance", required_argument, NULL, 'L'}, {"exposure", required_argument, NULL, 'e'},
        {"frames", required_argument, NULL, 'n'},   {"first-frame", required_argument, NULL, 'F'},
        {"dark", no_argument, NULL, 'd'},           {"output", required_argument, NULL, 'o'},
        {"set", required_argument, NULL, 's'},      {"help", no_argument, NULL, 'h'},
        {"fits-rows", required_argument, NULL, 'R'}, {NULL, 0, NULL, 0},
    };
    const char *out = NULL, *cam_path = NULL, *rows = NULL;
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    double L = -1, T = -1, nframes = 1;
    uint64_t first = 0;
    int nsets = 0, dark = 0, c, rc = 2;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "L:e:n:do:s:h", opts)) != -1) {
        const char *end = "";
        double v = 0;
        unsigned long long whole = 0;
        if (c == 'L' || c == 'e' || c == 'n' || c == 'F') {
            const int bad = c == 'n' || c == 'F' ? nc_cli_whole(optarg, &whole) : nc_cli_decimal(optarg, &end, &v);
            if (c == 'n' || c == 'F')
                v = (double)whole;
            if (bad || *end || v < 0 || (c == 'n' && (whole < 1 || whole > 100000)) || (c == 'e' && v > 3600)) {
                fprintf(stderr, "navcam expose: bad value '%s' for --%s (%s)\n", optarg,
                        c == 'L' ? "radiance" : c == 'e' ? "exposure" : c == 'n' ? "frames" : "first-frame",
                        c == 'L'   ? "W m^-2 sr^-1, 0 or more"
                        : c == 'e' ? "seconds, 0 to 3600, as exposure.time_s"
                        : c == 'n' ? "a whole number, 1 to 100000"
                                   : "a whole number, 0 or more");
                goto out;
            }
        }
        switch (c) {
        case 'L': L = v; break;
        case 'e': T = v; break;
        case 'n': nframes = v; break;
        case 'F': first = whole; break;
        case 'd': dark = 1; break;
        case 'o': out = optarg; break;
        case 'R': rows = optarg; break;
        case 's': sets[nsets++] = optarg; break;
        case 'h': fputs(expose_help, stdout); rc = 0; goto out;
        default: fputs("Try 'navcam expose --help'.\n", stderr); goto out;
        }
    }
    if ((uint64_t)nframes - 1 > UINT64_MAX - first) { /* the numbers key the noise: none may wrap to 0 */
        fprintf(stderr, "navcam expose: --first-frame %llu with %.0f frames goes past frame 2^64 - 1\n",
                (unsigned long long)first, nframes);
        goto out;
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
    if (rows && (!nc_image_is_fits(out) || nc_image_fits_row_order_ok(rows) < 0)) {
        fprintf(stderr, "navcam expose: --fits-rows: %s\n",
                !nc_image_is_fits(out) ? "applies to .fits output only" : nc_errmsg());
        goto out;
    }
    struct nc_camera geom;
    struct nc_camsys cs;
    rc = 1;
    if (nc_camsys_load(cam_path, sets, nsets, &geom, &cs) < 0) {
        fprintf(stderr, "navcam expose: %s\n", nc_errmsg());
        goto out;
    }
    if (nc_image_prepare(out) < 0) { /* the image library now, after the configuration */
        fprintf(stderr, "navcam expose: %s\n", nc_errmsg());
        nc_camsys_free(&cs);
        goto out;
    }
    if (T < 0)
        T = cs.exposure_s;
    if (dark)
        L = 0;
    /* The uniform field fills the PSF's margin too, as a lens sees it. */
    size_t n = (size_t)geom.width_px * (size_t)geom.height_px, nf = (size_t)nframes;
    size_t nr = (size_t)cs.render_width_px * (size_t)cs.render_height_px;
    float *rad = malloc(nr * sizeof *rad), *e = malloc(n * sizeof *e);
    uint16_t *dn = malloc(n * nf * sizeof *dn);
    int ok = rad && e && dn;
    for (size_t i = 0; ok && i < nr; i++)
        rad[i] = (float)L;
    ok = ok && nc_shot_electrons(&cs, &geom, rad, T, e) >= 0; /* stored as `navcam render` stores its frames */
    int is_fits = nc_image_is_fits(out);
    struct nc_image_attr attrs[32];
    char text[16][200], ltxt[64], ntxt[32], sw[64], intr[160];
    snprintf(ltxt, sizeof ltxt, "%.17g", L);
    snprintf(ntxt, sizeof ntxt, "%zu", nf);
    snprintf(sw, sizeof sw, "NavCam %s", NC_VERSION_STRING);
    snprintf(intr, sizeof intr, "[%.17g, %.17g, %.17g, %.17g]", geom.fx_px, geom.fy_px, geom.cx_px, geom.cy_px);
    /* what every image NavCam writes carries (docs/config.md): the maker, the quantity and its units (FITS BUNIT
     * adu), the camera's intrinsics */
    const struct nc_image_attr common[] = {{"Software", sw},          {"navcam:version", NC_VERSION_STRING},
                                           {"navcam:quantity", "dn"}, {"navcam:units", "DN"},
                                           {"navcam:intrinsics_fx_fy_cx_cy_px", intr}};
    const int ncommon = (int)(sizeof common / sizeof common[0]);
    char flip[32]; /* as `navcam render` records a mirrored camera (FITS IMAGE_MIRRORED) */
    for (size_t k = 0; ok && k < nf; k++) {
        uint64_t fno = first + (uint64_t)k;
        ok = nc_camsys_digitise(&cs, e, T, fno, dn + k * n) >= 0;
        if (ok && !is_fits) {
            char path[4200];
            const char *dot = strrchr(out, '.');
            snprintf(path, sizeof path, "%.*s_%04llu%s", (int)(dot - out), out, (unsigned long long)fno, dot);
            int na = nc_camsys_meta(&cs, T, fno, attrs, text, 16);
            for (int i = 0; i < ncommon; i++)
                attrs[na++] = common[i];
            attrs[na++] = (struct nc_image_attr){"navcam:radiance_w_m2_sr", ltxt};
            na += nc_shot_mirrored_attr(&geom, flip, attrs + na);
            ok = nc_image_write_dn(path, dn + k * n, geom.width_px, geom.height_px, cs.sensor.adc_bits, attrs, na) >= 0;
            if (ok)
                printf("wrote %s\n", path);
        }
    }
    if (ok && is_fits) {
        int na = nc_camsys_meta(&cs, T, first, attrs, text, 16);
        for (int i = 0; i < ncommon; i++)
            attrs[na++] = common[i];
        attrs[na++] = (struct nc_image_attr){"navcam:radiance_w_m2_sr", ltxt};
        attrs[na++] = (struct nc_image_attr){"navcam:frames", ntxt};
        na += nc_shot_mirrored_attr(&geom, flip, attrs + na);
        if (rows)
            attrs[na++] = (struct nc_image_attr){"navcam:fits_row_order", rows};
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
