/* cmd_compare.c - `navcam compare REAL RENDER`: a real image against a
 * rendered one, the seed paper's procedure (core/imgcmp.h), as JSON and
 * plots. Argument parsing, files and plotting only. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>

#include "app/cli.h"
#include "core/error.h"
#include "core/fs.h"
#include "core/imgcmp.h"
#include "core/texture.h"
#include "render/image_io.h"

static const char compare_help[] =
    "Usage: navcam compare REAL RENDER [-o DIR] [--fit F] [--register R] [--flip-real AXES]\n"
    "                      [--json FILE]\n"
    "\n"
    "Compare a real image with a rendered one of the same size (any format\n"
    "navcam reads: FITS, TIFF, EXR, PNG; the first channel; rows top first, a\n"
    "FITS file with ROWORDER = 'BOTTOM-UP' turned so; --flip-real for a REAL\n"
    "stored otherwise):\n"
    "  1. Otsu's threshold on REAL splits foreground (the body) from background;\n"
    "     only the foreground is compared (the background is not simulated).\n"
    "  2. --register R: RENDER is moved by the shift, found to 1/64 px within\n"
    "     +-R px, that maximises its correlation with REAL (cubic interpolation).\n"
    "  3. --fit: the render's intensities are matched to REAL's foreground:\n"
    "       scale      (default) one factor k, least squares: REAL ~ k RENDER\n"
    "       histogram  the render's foreground values replaced by REAL's, by rank\n"
    "       none       compared as they are (both in the same units)\n"
    "  4. Measured over the foreground: the relative error (RENDER' - REAL)/REAL,\n"
    "     its mean, median, RMS, 95th percentile of |error| and mean (bias);\n"
    "     the correlation (NCC) at full resolution and of 2, 4, 8 and 16 px block\n"
    "     means; the limb IoU: overlap of the two silhouettes, each by its own\n"
    "     Otsu threshold, |A and B| / |A or B|.\n"
    "  5. The texture of REAL and of RENDER (as moved) over the foreground, as\n"
    "     `navcam texture` measures it with its defaults: FAST corners, the\n"
    "     power spectrum's slope, gradient statistics.\n"
    "\n"
    "  -o, --output DIR     also write DIR/relative_error.fits (the signed map,\n"
    "                       float32, 0 off the foreground), DIR/relative_error.png\n"
    "                       (the map), DIR/error_histogram.png and .csv (gnuplot)\n"
    "  -f, --fit F          scale, histogram or none (default scale)\n"
    "  -r, --register R     search shifts within R px, 0 to 256 (default 0: no registration)\n"
    "  -F, --flip-real AXES mirror REAL before anything else: y top to bottom (an\n"
    "                       image stored bottom row first), x left to right, xy\n"
    "                       both (turned by 180 degrees); default none\n"
    "      --json FILE      the results as JSON in FILE (default: standard output; no -j:\n"
    "                       that is --threads in the commands that render)\n"
    "  -h, --help           this help\n"
    "\n"
    "The JSON: real, render, width, height, flip_real, fit, scale, shift_px [dx, dy]\n"
    "(RENDER moved right and down), threshold_real, threshold_render,\n"
    "foreground_px, relative_error {mean, median, rms, p95, bias}, ncc {1, 2, 4,\n"
    "8, 16: NCC of block means, null when undefined}, limb_iou, texture {real,\n"
    "render: {region_px, scale, corners, corners_per_mpx, psd_beta, psd_r2,\n"
    "grad_mean, grad_rms, grad_kurtosis}}.\n";

static int plots(const char *dir, const float *rel, int w, int h, const struct nc_imgcmp_result *res)
{
    char path[4096];
    size_t n = (size_t)w * (size_t)h;
    double hi = fmax(3 * res->rel_p95, 1e-6);
    enum { NB = 100 };
    size_t count[NB];
    nc_imgcmp_histogram(rel, n, -hi, hi, NB, count);
    snprintf(path, sizeof path, "%s/error_histogram.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    fprintf(f, "bin_centre,pixels\n");
    for (int b = 0; b < NB; b++)
        fprintf(f, "%.6g,%zu\n", -hi + (b + 0.5) * 2 * hi / NB, count[b]);
    fclose(f);
    /* The map as raw float32 for gnuplot, rows top first. */
    snprintf(path, sizeof path, "%s/.relative_error.f32", dir);
    if (!(f = fopen(path, "wb")))
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    fwrite(rel, sizeof *rel, n, f);
    fclose(f);
    snprintf(path, sizeof path, "%s/.compare.gp", dir);
    if (!(f = fopen(path, "w")))
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    fprintf(f,
            "set terminal pngcairo size 900,800 font ',10'\nset output 'relative_error.png'\n"
            "set title 'relative error (render - real) / real over the foreground: mean |e| %.4g, p95 %.4g'\n"
            "set size ratio -1\nset yrange [%d:-0.5] reverse\nset xrange [-0.5:%d]\nset xlabel 'x, px'\n"
            "set ylabel 'y, px'\nset palette defined (-1 'blue', 0 'white', 1 'red')\nset cbrange [%g:%g]\n"
            "set datafile missing NaN\nplot '.relative_error.f32' binary array=(%d,%d) format='%%float' "
            "with image notitle\n"
            "set terminal pngcairo size 900,600 font ',10'\nset output 'error_histogram.png'\nset size noratio\n"
            "set autoscale\nset yrange [0:*]\nset title 'foreground pixels by relative error'\n"
            "set xlabel '(render - real) / real'\nset ylabel 'pixels'\nset datafile separator ','\nset grid\n"
            "plot 'error_histogram.csv' using 1:2 skip 1 with boxes fill solid 0.5 notitle\n",
            res->rel_mean, res->rel_p95, h - 1, w - 1, -hi, hi, w, h);
    fclose(f);
    /* without gnuplot the rest stands (the map, the histogram's numbers, the JSON): a warning, as bench's */
    if (nc_cli_gnuplot(dir, ".compare.gp") != 0)
        fprintf(stderr, "navcam compare: %s: no plots: gnuplot failed or is missing (Debian: gnuplot-nox)\n", dir);
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, i ? ".relative_error.f32" : ".compare.gp");
        unlink(path);
    }
    snprintf(path, sizeof path, "%s/relative_error.fits", dir);
    return nc_image_write(path, rel, w, h, NULL, 0, NULL);
}

/* Where word is in the NULL-terminated words, or -1. */
static int word_index(const char *const *words, const char *word)
{
    for (int i = 0; words[i]; i++)
        if (!strcmp(words[i], word))
            return i;
    return -1;
}

int main(int argc, char **argv)
{
    nc_cli_init("compare");
    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"fit", required_argument, NULL, 'f'},
        {"register", required_argument, NULL, 'r'}, {"json", required_argument, NULL, 'j'},
        {"flip-real", required_argument, NULL, 'F'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    static const char *const flips[] = {"none", "x", "y", "xy", NULL}; /* bit 0: x, bit 1: y */
    static const char *const fits[] = {"none", "scale", "histogram", NULL};
    const char *dir = NULL, *json = NULL;
    int fit = NC_FIT_SCALE, radius = 0, flip = 0, c;
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "o:f:r:F:h", opts)) != -1) {
        switch (c) {
        case 'o': dir = optarg; break;
        case 'j': json = optarg; break;
        case 'f':
            if ((fit = word_index(fits, optarg)) < 0) {
                fprintf(stderr, "navcam compare: --fit expects scale, histogram or none, got '%s'\n", optarg);
                return 2;
            }
            break;
        case 'r': {
            long v;
            if (nc_cli_long("register", optarg, 0, 256, &v) < 0)
                return 2;
            radius = (int)v;
            break;
        }
        case 'F':
            if ((flip = word_index(flips, optarg)) < 0) {
                fprintf(stderr, "navcam compare: --flip-real expects none, x, y or xy, got '%s'\n", optarg);
                return 2;
            }
            break;
        case 'h': fputs(compare_help, stdout); return 0;
        default: fputs("Try 'navcam compare --help'.\n", stderr); return 2;
        }
    }
    if (argc - optind != 2) {
        fprintf(stderr, "navcam compare: give two images, REAL and RENDER\nTry 'navcam compare --help'.\n");
        return 2;
    }
    const char *real_path = argv[optind], *render_path = argv[optind + 1];
    float *real = NULL, *render = NULL, *moved = NULL, *rel = NULL;
    uint8_t *fg = NULL;
    struct nc_texture tex[2];
    int w, h, w2, h2, rc;
    double dx = 0, dy = 0;
    struct nc_imgcmp_result res;
    if ((rc = nc_image_read(real_path, &real, &w, &h)) < 0 || (rc = nc_image_read(render_path, &render, &w2, &h2)) < 0)
        goto done;
    if (w != w2 || h != h2) {
        rc = nc_error(NC_ERANGE, "%s is %dx%d but %s is %dx%d: the images must have the same size", real_path, w, h,
                      render_path, w2, h2);
        goto done;
    }
    if (w < 7 || h < 7) { /* the texture's FAST circle needs 7x7 */
        rc = nc_error(NC_ERANGE, "%s and %s are %dx%d: too small to compare (at least 7x7 pixels)", real_path,
                      render_path, w, h);
        goto done;
    }
    nc_image_flip(real, sizeof *real, w, h, flip & 2, flip & 1);
    size_t n = (size_t)w * (size_t)h;
    if (!(rel = malloc(n * sizeof *rel)) || !(moved = malloc(n * sizeof *moved))) {
        rc = nc_error(-ENOMEM, "out of memory");
        goto done;
    }
    memcpy(moved, render, n * sizeof *moved);
    if (radius > 0) {
        if ((rc = nc_imgcmp_register(real, render, w, h, radius, &dx, &dy)) < 0)
            goto done;
        nc_imgcmp_shift(render, w, h, dx, dy, moved);
    }
    if ((rc = nc_imgcmp(real, moved, w, h, (enum nc_imgcmp_fit)fit, &res, rel)) < 0)
        goto done;
    /* the texture of both over the foreground compared */
    if (!(fg = malloc(n))) {
        rc = nc_error(-ENOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; i++) { /* a pixel missing in either is missing in both (their FAST circles too) */
        if (!isfinite(real[i]) || !isfinite(moved[i]))
            real[i] = moved[i] = NAN;
        fg[i] = isfinite(real[i]) && real[i] >= res.threshold_real && real[i] > 0; /* the error's foreground */
    }
    struct nc_texture_opts to;
    nc_texture_defaults(&to);
    to.mask = fg;
    if ((rc = nc_texture_measure(real, w, h, &to, &tex[0])) < 0 ||
        (rc = nc_texture_measure(moved, w, h, &to, &tex[1])) < 0)
        goto done;
    /* made only now: a comparison that fails leaves no empty directory */
    if (dir && ((rc = nc_mkdirs(dir)) < 0 || (rc = plots(dir, rel, w, h, &res)) < 0))
        goto done;
    FILE *out;
    if ((rc = nc_cli_out_open(json, &out)) < 0)
        goto done;
    fprintf(out, "{");
    nc_cli_json_str(out, "real", real_path);
    nc_cli_json_str(out, "render", render_path);
    fprintf(out, "\"width\": %d, \"height\": %d, ", w, h);
    nc_cli_json_str(out, "flip_real", flips[flip]);
    nc_cli_json_str(out, "fit", fits[fit]);
    nc_cli_json_num(out, "scale", res.scale, ", ");
    fprintf(out, "\"shift_px\": [%.6f, %.6f], ", dx, dy);
    nc_cli_json_num(out, "threshold_real", res.threshold_real, ", ");
    nc_cli_json_num(out, "threshold_render", res.threshold_render, ", ");
    fprintf(out, "\"foreground_px\": %zu, \"relative_error\": {", res.foreground_px);
    nc_cli_json_num(out, "mean", res.rel_mean, ", ");
    nc_cli_json_num(out, "median", res.rel_median, ", ");
    nc_cli_json_num(out, "rms", res.rel_rms, ", ");
    nc_cli_json_num(out, "p95", res.rel_p95, ", ");
    nc_cli_json_num(out, "bias", res.rel_bias, "}, \"ncc\": {");
    for (int k = 0; k < 5; k++) {
        char key[8];
        snprintf(key, sizeof key, "%d", nc_imgcmp_blocks[k]);
        nc_cli_json_num(out, key, res.ncc[k], k < 4 ? ", " : "}, ");
    }
    nc_cli_json_num(out, "limb_iou", res.limb_iou, ", \"texture\": {\"real\": {");
    nc_cli_json_texture(out, &tex[0]);
    fprintf(out, "}, \"render\": {");
    nc_cli_json_texture(out, &tex[1]);
    fprintf(out, "}}}\n");
    rc = nc_cli_out_close(out, json);
done:
    free(real);
    free(render);
    free(moved);
    free(rel);
    free(fg);
    return rc < 0 ? nc_cli_fail() : 0;
}
