/* cmd_texture.c - `navcam texture IMAGE...`: the texture statistics of
 * images (core/texture.h) as JSON, to set a render beside a real image.
 * Argument parsing and files only. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/cli.h"
#include "core/error.h"
#include "core/texture.h"
#include "render/image_io.h"

static const char texture_help[] =
    "Usage: navcam texture IMAGE... [--threshold T] [--range LO,HI] [--region R]\n"
    "                       [--band FLO,FHI] [--crop X,Y,W,H] [--gsd M] [--json FILE]\n"
    "\n"
    "The texture of images (any format navcam reads: FITS, TIFF, EXR, PNG; the\n"
    "first channel) as feature trackers see it, the same way for a render and a\n"
    "real image:\n"
    "  corners    FAST corners (Rosten and Drummond 2006): a pixel whose circle of\n"
    "             16 pixels at radius 3 holds 9 contiguous ones all brighter than it\n"
    "             by more than T, or all darker; each kept only when its score (the\n"
    "             largest T for which it still is a corner) beats its 8 neighbours'.\n"
    "             As OpenCV's FastFeatureDetector (TYPE_9_16, non-maximum\n"
    "             suppression) finds them on the image scaled to 8 bits: value LO\n"
    "             -> 0, HI -> 255, rounded, clipped. Counted on region pixels (none\n"
    "             within 3 px of the border, none missing or with a missing pixel\n"
    "             on its circle), per million region pixels and, with --gsd, per\n"
    "             square metre.\n"
    "  psd_beta   the slope of the power spectrum, P(f) ~ f^-beta: the region's\n"
    "             mean removed (pixels off the region set to it), a 2-D Hann\n"
    "             window, |FFT|^2 averaged in bins of 1/8 octave of f = |(fx, fy)|,\n"
    "             a least-squares line through log P against log f over FLO..FHI\n"
    "             cycles per pixel (psd_r2: its R^2).\n"
    "  gradient   the central-difference gradient over the region's mean value,\n"
    "             per pixel, where a pixel and its 4 neighbours are in the region:\n"
    "             grad_mean and grad_rms of its magnitude, and grad_kurtosis of its\n"
    "             components dI/dx and dI/dy together (3 for Gaussian gradients).\n"
    "\n"
    "  -t, --threshold T   FAST threshold, 8-bit units, 0..254 (default 10, OpenCV's)\n"
    "  -r, --range LO,HI   the values scaled to 0 and 255 (default: the region's\n"
    "                      0.5th and 99.5th percentiles)\n"
    "  -R, --region R      all: every finite pixel (default); otsu: those at or\n"
    "                      above Otsu's threshold (a body against the sky)\n"
    "  -b, --band FLO,FHI  the spectrum's band, cycles per pixel, 0 < FLO < FHI <= 0.5,\n"
    "                      at most 32 octaves (FHI / FLO <= 2^32)\n"
    "                      (default 0.015625,0.25: wavelengths of 4 to 64 px)\n"
    "  -c, --crop X,Y,W,H  measure only W x H pixels of each image from column X,\n"
    "                      row Y (0-based; row 0 is the top row: FITS files are\n"
    "                      read top-down whatever their ROWORDER)\n"
    "  -g, --gsd M         ground sample distance, m per pixel: also corners per m^2\n"
    "      --json FILE     the results in FILE (default: standard output; no -j: that is\n"
    "                      --threads in the commands that render)\n"
    "  -h, --help          this help\n"
    "\n"
    "The JSON: an array, one object per image: image, width, height (the crop's\n"
    "with --crop), crop [X, Y, W, H] (null without --crop), region, region_px,\n"
    "scale [LO, HI], threshold, corners, corners_per_mpx,\n"
    "corners_per_m2 (null without --gsd), band_cpp [FLO, FHI], psd_beta, psd_r2,\n"
    "grad_mean, grad_rms, grad_kurtosis (null where undefined).\n"
    "\n"
    "Examples (the first from a NavCam checkout; real.fits stands for your own\n"
    "image of the same ground; the last anywhere):\n"
    "  navcam render configs/examples/bennu_rubble.yaml -o r.fits --quantity radiance\n"
    "  navcam texture r.fits real.fits --gsd 0.2\n"
    "  navcam render -o frame.tif && navcam texture frame.tif --crop 256,128,256,256 \\\n"
    "      --band 0.03125,0.25\n";

/* "A,B" into two numbers; 0, or -1 if it is not that. */
static int pair(const char *s, double *a, double *b)
{
    char *end;
    *a = strtod(s, &end);
    if (end == s || *end != ',')
        return -1;
    const char *t = end + 1;
    *b = strtod(t, &end);
    return end == t || *end ? -1 : 0;
}

/* "X,Y,W,H": four integers, X and Y >= 0, W and H > 0; 0, or -1. */
static int crop4(const char *s, int c[4])
{
    for (int k = 0; k < 4; k++) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || *end != (k < 3 ? ',' : '\0') || v < (k < 2 ? 0 : 1) || v > 1000000)
            return -1;
        c[k] = (int)v;
        s = end + 1;
    }
    return 0;
}

/* px (w x h) cut to crop c in place (*w, *h become its size), or an error
 * naming path if it does not fit. */
static int cut(const char *path, float *px, int *w, int *h, const int c[4])
{
    if (c[0] + c[2] > *w || c[1] + c[3] > *h)
        return nc_error(NC_ECONFIG, "%s: --crop %d,%d,%d,%d reaches beyond its %dx%d pixels", path, c[0], c[1], c[2],
                        c[3], *w, *h);
    for (int y = 0; y < c[3]; y++)
        memmove(px + (size_t)y * (size_t)c[2], px + (size_t)(c[1] + y) * (size_t)*w + (size_t)c[0],
                (size_t)c[2] * sizeof *px);
    *w = c[2];
    *h = c[3];
    return 0;
}

static int usage(const char *msg, const char *arg)
{
    fprintf(stderr, "navcam texture: %s, got '%s'\nTry 'navcam texture --help'.\n", msg, arg);
    return 2;
}

int main(int argc, char **argv)
{
    nc_cli_init("texture");
    static const struct option opts[] = {
        {"threshold", required_argument, NULL, 't'}, {"range", required_argument, NULL, 'r'},
        {"region", required_argument, NULL, 'R'},    {"band", required_argument, NULL, 'b'},
        {"gsd", required_argument, NULL, 'g'},       {"json", required_argument, NULL, 'j'},
        {"crop", required_argument, NULL, 'c'},      {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    struct nc_texture_opts o;
    nc_texture_defaults(&o);
    const char *json = NULL;
    double gsd = 0;
    int c, crop[4] = {0, 0, 0, 0};
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "t:r:R:b:g:c:h", opts)) != -1) {
        char *end;
        switch (c) {
        case 't': {
            long v = strtol(optarg, &end, 10);
            if (end == optarg || *end || v < 0 || v > 254)
                return usage("--threshold expects an integer 0..254", optarg);
            o.threshold = (int)v;
            break;
        }
        case 'r':
            if (pair(optarg, &o.lo, &o.hi) < 0 || !isfinite(o.lo) || !isfinite(o.hi) || !(o.hi > o.lo))
                return usage("--range expects LO,HI with LO < HI", optarg);
            break;
        case 'R':
            if (strcmp(optarg, "all") && strcmp(optarg, "otsu"))
                return usage("--region expects all or otsu", optarg);
            o.otsu = !strcmp(optarg, "otsu");
            break;
        case 'b':
            if (pair(optarg, &o.f_lo, &o.f_hi) < 0 || !(o.f_lo > 0) || !(o.f_hi > o.f_lo) || !(o.f_hi <= 0.5) ||
                !(o.f_hi <= 4294967296.0 * o.f_lo)) /* the spectrum's 8 bins an octave, at most 256 */
                return usage("--band expects FLO,FHI cycles per pixel with 0 < FLO < FHI <= 0.5 and FHI / FLO at most "
                             "2^32 (32 octaves)", optarg);
            break;
        case 'g':
            gsd = strtod(optarg, &end);
            if (end == optarg || *end || !(gsd > 0) || !isfinite(gsd))
                return usage("--gsd expects metres per pixel, > 0", optarg);
            break;
        case 'c':
            if (crop4(optarg, crop) < 0)
                return usage("--crop expects X,Y,W,H in pixels: X, Y >= 0, W, H > 0", optarg);
            break;
        case 'j': json = optarg; break;
        case 'h': fputs(texture_help, stdout); return 0;
        default: fputs("Try 'navcam texture --help'.\n", stderr); return 2;
        }
    }
    if (optind >= argc) {
        fputs("navcam texture: give at least one image\nTry 'navcam texture --help'.\n", stderr);
        return 2;
    }
    const int nimg = argc - optind;
    struct nc_texture *res = calloc((size_t)nimg, sizeof *res);
    int *wh = calloc(2 * (size_t)nimg, sizeof *wh), rc = 0;
    if (!res || !wh) {
        rc = nc_error(-ENOMEM, "out of memory");
        goto done;
    }
    for (int k = 0; k < nimg && rc == 0; k++) {
        float *px = NULL;
        if ((rc = nc_image_read(argv[optind + k], &px, &wh[2 * k], &wh[2 * k + 1])) == 0 && crop[2] > 0)
            rc = cut(argv[optind + k], px, &wh[2 * k], &wh[2 * k + 1], crop);
        if (rc == 0 && (rc = nc_texture_measure(px, wh[2 * k], wh[2 * k + 1], &o, &res[k])) < 0) {
            char msg[512];
            snprintf(msg, sizeof msg, "%s", nc_errmsg());
            nc_error(rc, "%s: %s", argv[optind + k], msg);
        }
        free(px);
    }
    if (rc < 0)
        goto done;
    FILE *out;
    if ((rc = nc_cli_out_open(json, &out)) < 0)
        goto done;
    fprintf(out, "[");
    for (int k = 0; k < nimg; k++) {
        const struct nc_texture *t = &res[k];
        fprintf(out, "%s{", k ? ",\n " : "");
        nc_cli_json_str(out, "image", argv[optind + k]);
        fprintf(out, "\"width\": %d, \"height\": %d, ", wh[2 * k], wh[2 * k + 1]);
        if (crop[2] > 0)
            fprintf(out, "\"crop\": [%d, %d, %d, %d], ", crop[0], crop[1], crop[2], crop[3]);
        else
            fprintf(out, "\"crop\": null, ");
        nc_cli_json_str(out, "region", o.otsu ? "otsu" : "all");
        fprintf(out, "\"threshold\": %d, \"band_cpp\": [%.9g, %.9g], ", o.threshold, o.f_lo, o.f_hi);
        nc_cli_json_num(out, "corners_per_m2", gsd > 0 ? (double)t->corners / ((double)t->region_px * gsd * gsd) : NAN,
                        ", ");
        nc_cli_json_texture(out, t);
        fprintf(out, "}");
    }
    fprintf(out, "]\n");
    rc = nc_cli_out_close(out, json);
done:
    free(res);
    free(wh);
    return rc < 0 ? nc_cli_fail() : 0;
}
