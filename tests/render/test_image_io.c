/* test_image_io.c - frames written through OpenImageIO read back exactly
 * (float formats), within one DN of the stated scale (16-bit preview), with
 * the metadata a user needs, and with NaN/Inf never reaching the file. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fitsio.h>
#include <float.h>

#include "core/error.h"
#include "core/le.h"
#include "render/frame_io.h"
#include "render/image_io.h"
#include "testutil.h"

static const char yaml[] =
    "bodies:\n"
    "  - shape: {type: sphere, radius_m: 800}\n"
    "    material: {model: lambert, A: 0.2}\n"
    "sun: {direction: [0.3, 0, -1]}\n"
    "camera: {width_px: 48, height_px: 36, fx_px: 60, fy_px: 60, position_m: [0, 0, -3000.123456789012],\n"
    "         attitude_q: [1, 0, 0, 0]}\n";

/* FITS row order, read back with cfitsio's own API (the reader FITS users
 * have; OpenImageIO 2.4 cannot read float FITS at all): by default row 1 is
 * image row 0 (ROWORDER 'TOP-DOWN'); with navcam:fits_row_order bottom_up,
 * row 1 is the bottom image row (ROWORDER 'BOTTOM-UP', the archive
 * convention); nc_image_read returns top-down rows either way, bit exact. */
static void fits_rows(void)
{
    enum { FW = 3, FH = 4 };
    float img[FW * FH];
    uint16_t dn[2 * FW * FH];
    for (int i = 0; i < FW * FH; i++)
        img[i] = 10.0f * (i / FW) + (i % FW) + 0.25f, dn[i] = (uint16_t)i, dn[FW * FH + i] = (uint16_t)(100 + i);
    const char *order[] = {"top_down", "bottom_up"};
    for (int up = 0; up < 2; up++) {
        char name[64];
        snprintf(name, sizeof name, "rows_%s.fits", order[up]);
        const char *path = nc_test_path(name);
        const struct nc_image_attr a = {"navcam:fits_row_order", order[up]};
        CHECK(nc_image_write(path, img, FW, FH, &a, 1, NULL) == 0, "%s: %s", name, nc_errmsg());
        fitsfile *ff = NULL;
        int status = 0, anynul = 0;
        float raw[FW * FH];
        char rowkey[FLEN_VALUE] = "";
        fits_open_image(&ff, path, READONLY, &status);
        fits_read_key_str(ff, "ROWORDER", rowkey, NULL, &status);
        fits_read_img(ff, TFLOAT, 1, FW * FH, NULL, raw, &anynul, &status);
        fits_close_file(ff, &status);
        CHECK(status == 0 && !strcmp(rowkey, up ? "BOTTOM-UP" : "TOP-DOWN"), "%s: cfitsio status %d, ROWORDER '%s'",
              name, status, rowkey);
        int same = 1;
        for (int y = 0; y < FH; y++)
            for (int x = 0; x < FW; x++)
                same &= raw[y * FW + x] == img[(up ? FH - 1 - y : y) * FW + x];
        CHECK(same, "%s: FITS row 1 is not image row %d", name, up ? FH - 1 : 0);
        float *back = NULL;
        int w = 0, h = 0;
        CHECK(nc_image_read(path, &back, &w, &h) == 0 && w == FW && h == FH && !memcmp(back, img, sizeof img),
              "%s: read back is not the image, top-down", name);
        free(back);
        /* A DN cube: every plane in the same order. */
        snprintf(name, sizeof name, "cube_%s.fits", order[up]);
        path = nc_test_path(name);
        CHECK(nc_image_write_dn_cube(path, dn, FW, FH, 2, 12, &a, 1) == 0, "%s: %s", name, nc_errmsg());
        unsigned short rawdn[2 * FW * FH];
        status = 0;
        fits_open_image(&ff, path, READONLY, &status);
        fits_read_img(ff, TUSHORT, 1, 2 * FW * FH, NULL, rawdn, &anynul, &status);
        fits_close_file(ff, &status);
        same = status == 0;
        for (int k = 0; k < 2; k++)
            for (int y = 0; y < FH; y++)
                for (int x = 0; x < FW; x++)
                    same &= rawdn[(k * FH + y) * FW + x] == dn[(k * FH + (up ? FH - 1 - y : y)) * FW + x];
        CHECK(same, "%s: a plane's rows are not in %s order", name, order[up]);
        /* An image here is one plane; a row order NavCam cannot tell is an
         * error, not a guess. */
        back = NULL;
        CHECK(nc_image_read(path, &back, &w, &h) < 0 && nc_test_contains(nc_errmsg(), "more than one plane"),
              "%s: read as an image: %s", name, nc_errmsg());
        free(back);
        if (up) {
            snprintf(name, sizeof name, "sideways.fits");
            const char *side = nc_test_path(name);
            CHECK(nc_image_write(side, img, FW, FH, NULL, 0, NULL) == 0, "%s: %s", name, nc_errmsg());
            status = 0;
            fits_open_image(&ff, side, READWRITE, &status);
            fits_update_key_str(ff, "ROWORDER", "SIDEWAYS", NULL, &status);
            fits_close_file(ff, &status);
            back = NULL;
            CHECK(status == 0 && nc_image_read(side, &back, &w, &h) < 0 &&
                      nc_test_contains(nc_errmsg(), "ROWORDER 'SIDEWAYS': expected 'TOP-DOWN' or 'BOTTOM-UP'"),
                  "%s: %s", name, nc_errmsg());
            free(back);
        }
    }
}

/* FITS from elsewhere: a pixel the BLANK keyword marks is undefined (NaN:
 * a DEM's hole, not a height of -32768), as is a float64 value no float
 * holds (a fill value); a BSCALE that is no number is an error, not 1. */
static void fits_foreign(void)
{
    static const struct {
        const char *name, *key, *value, *error;
        double big;
    } cases[] = {
        {"blank.fits", "BLANK", "-32768", NULL, 0},
        {"dscale.fits", "BSCALE", "2.0D0", NULL, 0},
        {"badscale.fits", "BSCALE", "'abc'", "badscale.fits: BSCALE = 'abc' is not a finite number", 0},
        {"noscale.fits", "BSCALE", "", "noscale.fits: BSCALE =  is not a finite number", 0}, /* blank */
        {"big.fits", NULL, NULL, NULL, -DBL_MAX}, /* a float64 file's fill value: no data, as NaN */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *path = nc_test_path(cases[i].name);
        fitsfile *ff = NULL;
        int status = 0;
        long ax[2] = {4, 3};
        short v[12];
        double d[12];
        for (int k = 0; k < 12; k++)
            v[k] = (short)k, d[k] = k;
        v[5] = -32768;
        d[5] = cases[i].big;
        remove(path);
        fits_create_file(&ff, path, &status);
        fits_create_img(ff, cases[i].big ? DOUBLE_IMG : SHORT_IMG, 2, ax, &status);
        if (cases[i].key) {
            char card[81];
            snprintf(card, sizeof card, "%-8s= %20s", cases[i].key, cases[i].value);
            fits_write_record(ff, card, &status);
            fits_set_bscale(ff, 1.0, 0.0, &status); /* the values below written raw */
        }
        if (cases[i].big)
            fits_write_img(ff, TDOUBLE, 1, 12, d, &status);
        else
            fits_write_img(ff, TSHORT, 1, 12, v, &status);
        fits_close_file(ff, &status);
        float *px = NULL;
        int w, h;
        const int rc = nc_image_read(path, &px, &w, &h);
        if (cases[i].error)
            CHECK(status == 0 && rc < 0 && nc_test_contains(nc_errmsg(), cases[i].error), "%s: %s", cases[i].name,
                  rc < 0 ? nc_errmsg() : "read");
        else
            CHECK(status == 0 && rc == 0 && w == 4 && h == 3 && px[4] == (i == 1 ? 8 : 4) &&
                      (i == 1 ? px[5] < 0 : isnan(px[5])),
                  "%s: status %d, %s, pixel 5 %g", cases[i].name, status, rc < 0 ? nc_errmsg() : "read",
                  rc == 0 ? px[5] : 0);
        free(px);
    }
}

/* A file is written whole or not at all, and one cut short is not read. */
static void whole_or_nothing(void)
{
    enum { W = 256 };
    static float img[W * W];
    for (int i = 0; i < W * W; i++)
        img[i] = (float)((i * 7919) % 1000);
    const char *exts[] = {"png", "exr", "tif", "fits"};
    struct rlimit old;
    getrlimit(RLIMIT_FSIZE, &old);
    signal(SIGXFSZ, SIG_IGN);
    for (int e = 0; e < 4; e++) {
        char name[32];
        snprintf(name, sizeof name, "limit.%s", exts[e]);
        const char *path = nc_test_path(name);
        CHECK(nc_image_write(path, img, 2, 2, NULL, 0, NULL) == 0, "%s: %s", name, nc_errmsg());
        size_t before = 0, after = 0;
        char *was = nc_test_read(path, &before);
        struct rlimit lim = {1024, old.rlim_max}; /* as a full disk: write() fails past 1 KiB */
        setrlimit(RLIMIT_FSIZE, &lim);
        int rc = nc_image_write(path, img, W, W, NULL, 0, NULL);
        setrlimit(RLIMIT_FSIZE, &old);
        char *now = nc_test_read(path, &after);
        CHECK(rc < 0 && nc_test_contains(nc_errmsg(), name) && was && now && after == before &&
                  !memcmp(was, now, after),
              "%s over the file size limit: rc %d '%s', the file before it %s", name, rc, nc_errmsg(),
              now && after == before ? "kept" : "lost");
        free(was), free(now);
    }
    signal(SIGXFSZ, SIG_DFL);
    DIR *d = opendir(nc_test_path("."));
    int tmps = 0;
    for (struct dirent *de; d && (de = readdir(d));)
        tmps += strstr(de->d_name, ".tmp") != NULL;
    if (d)
        closedir(d);
    CHECK(tmps == 0, "%d temporary files left behind", tmps);
    /* A directory of the name stays (cfitsio's overwrite removed an empty one). */
    const char *dir = nc_test_path("adir.fits");
    mkdir(dir, 0755);
    struct stat st;
    CHECK(nc_image_write(dir, img, 2, 2, NULL, 0, NULL) < 0 && stat(dir, &st) == 0 && S_ISDIR(st.st_mode),
          "a directory named like the output: %s", nc_errmsg());
    rmdir(dir);
    /* Nor is a pipe (or, as root, a device such as /dev/null) replaced by the rename. */
    const char *fifo = nc_test_path("apipe.fits");
    unlink(fifo);
    CHECK(mkfifo(fifo, 0600) == 0 && nc_image_write(fifo, img, 2, 2, NULL, 0, NULL) < 0 &&
              nc_test_contains(nc_errmsg(), "apipe.fits: exists and is not a regular file (a device, pipe") &&
              stat(fifo, &st) == 0 && S_ISFIFO(st.st_mode),
          "a pipe named like the output: %s", nc_errmsg());
    unlink(fifo);
    /* A TIFF cut short (OpenImageIO reads it "successfully", the missing rows left as they were). */
    const char *tif = nc_test_path("cut.tif");
    float *px = NULL;
    int w, h;
    size_t len = 0;
    char *bytes = NULL;
    CHECK(nc_image_write(tif, img, W, W, NULL, 0, NULL) == 0 && (bytes = nc_test_read(tif, &len)), "cut.tif: %s",
          nc_errmsg());
    if (bytes) {
        FILE *fp = fopen(tif, "wb");
        if (fp)
            fwrite(bytes, 1, len / 2, fp), fclose(fp);
        CHECK(nc_image_read(tif, &px, &w, &h) < 0 && nc_test_contains(nc_errmsg(), "cut.tif: read:"),
              "a TIFF cut short: %s", nc_errmsg());
    }
    free(bytes);
}

/* Whether a little-endian classic TIFF's first directory has an entry of
 * this tag: 1, 0, or -1 when the file is not one. */
static int tiff_tag(const char *path, unsigned tag)
{
    size_t len = 0;
    uint8_t *b = (uint8_t *)nc_test_read(path, &len);
    int found = -1;
    if (b && len >= 8 && !memcmp(b, "II", 2) && nc_le_get_u16(b + 2) == 42 && nc_le_get_u32(b + 4) + 2 <= len) {
        const size_t ifd = nc_le_get_u32(b + 4), n = nc_le_get_u16(b + ifd);
        found = ifd + 2 + 12 * n + 4 <= len ? 0 : -1;
        for (size_t i = 0; i < n && found == 0; i++)
            found = nc_le_get_u16(b + ifd + 2 + 12 * i) == tag;
    }
    free(b);
    return found;
}

/* A whole number keeps every digit as a FITS integer: frame numbers past 2^53 were written as doubles
 * (18446744073709551615 as 1.8446744073709552E+19). */
static void fits_whole_numbers(void)
{
    const char *values[] = {"18446744073709551615", "9007199254740993", "-9007199254740993", "42"};
    for (int i = 0; i < 4; i++) {
        const char *path = nc_test_path("whole.fits");
        const struct nc_image_attr a = {"navcam:frame", values[i]};
        float img[4] = {0};
        char card[FLEN_VALUE] = "";
        int status = 0;
        fitsfile *ff = NULL;
        CHECK(nc_image_write(path, img, 2, 2, &a, 1, NULL) == 0, "FRAME %s: %s", values[i], nc_errmsg());
        fits_open_image(&ff, path, READONLY, &status);
        fits_read_keyword(ff, "FRAME", card, NULL, &status);
        fits_close_file(ff, &status);
        CHECK(status == 0 && !strcmp(card, values[i]), "FRAME %s written as '%s' (status %d)", values[i], card, status);
    }
}

int main(void)
{
    fits_whole_numbers();
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    struct nc_frame f;
    nc_test_render(&s, 1, &f);
    const size_t n = (size_t)f.width_px * f.height_px;
    const char *exts[] = {"exr", "tif", "fits", "png"};
    for (int q = 0; q < 3; q++)
        for (int e = 0; e < 4; e++) {
            char name[64];
            snprintf(name, sizeof name, "frame_%s.%s", nc_quantity_names[q], exts[e]);
            const char *path = nc_test_path(name);
            double scale = -1;
            int rc = nc_frame_write(path, &f, (enum nc_quantity)q, &s, NULL, 0, &scale);
            CHECK(rc == 0, "%s: %s", name, nc_errmsg());
            float *px = NULL;
            int w = 0, h = 0;
            rc = nc_image_read(path, &px, &w, &h);
            CHECK(rc == 0 && w == f.width_px && h == f.height_px, "%s read back: %s", name, nc_errmsg());
            if (rc < 0)
                continue;
            const float *src = q == 0 ? f.radiance : q == 1 ? f.iof : f.range_m;
            double worst = 0, vmax = 0;
            for (size_t i = 0; i < n; i++) {
                double want = e == 3 ? src[i] / scale : src[i];
                worst = fmax(worst, fabs(px[i] - want));
                vmax = fmax(vmax, src[i]);
            }
            if (e < 3)
                CHECK(worst == 0, "%s: float values changed by up to %g", name, worst);
            else
                /* half a DN of rounding, plus the float32 of the read-back normalisation */
                CHECK(worst <= 0.51 / 65535 && scale == vmax, "%s: preview error %g DN (scale %g, max %g)", name,
                      worst * 65535, scale, vmax);
            free(px);
            char buf[512];
            const char *want_q = nc_quantity_names[q];
            CHECK(nc_image_read_attr(path, "navcam:quantity", buf, sizeof buf) == 0 && !strcmp(buf, want_q),
                  "%s: navcam:quantity '%s' (%s)", name, buf, nc_errmsg());
            CHECK(nc_image_read_attr(path, "navcam:units", buf, sizeof buf) == 0 &&
                      !strcmp(buf, nc_quantity_units((enum nc_quantity)q)),
                  "%s: navcam:units", name);
            CHECK(nc_image_read_attr(path, "navcam:camera_position_m", buf, sizeof buf) == 0 &&
                      nc_test_contains(buf, "-3000.1234567890"),
                  "%s: camera position in full precision: '%s'", name, buf);
            CHECK(nc_image_read_attr(path, "navcam:version", buf, sizeof buf) == 0, "%s: version", name);
            CHECK(nc_image_read_attr(path, "navcam:quaternion_convention", buf, sizeof buf) == 0 &&
                      nc_test_contains(buf, "Hamilton; rotates camera-frame vectors into the scene frame"),
                  "%s: long value intact: '%s'", name, buf);
            CHECK(nc_image_read_attr(path, "navcam:sun_direction_scene", buf, sizeof buf) == 0, "%s: sun", name);
            if (e == 1) /* no DateTime tag at all: an empty one is malformed TIFF, a time breaks reproducibility */
                CHECK(tiff_tag(path, 306) == 0 && tiff_tag(path, 305) == 1, "%s: DateTime %d, Software %d", name,
                      tiff_tag(path, 306), tiff_tag(path, 305));
            if (e == 3)
                CHECK(nc_image_read_attr(path, "navcam:preview_scale", buf, sizeof buf) == 0 &&
                          fabs(atof(buf) - scale) <= 1e-8 * scale,
                      "%s: preview scale in metadata '%s' vs %g", name, buf, scale);
        }

    /* Written again more than a second later, every format holds the same
     * bytes: no time of writing (OpenImageIO stamps one unless told). */
    nanosleep(&(struct timespec){1, 100000000}, NULL);
    for (int e = 0; e < 4; e++) {
        char name[64], again[64];
        snprintf(name, sizeof name, "frame_radiance.%s", exts[e]);
        snprintf(again, sizeof again, "again.%s", exts[e]);
        CHECK(nc_frame_write(nc_test_path(again), &f, NC_Q_RADIANCE, &s, NULL, 0, NULL) == 0, "%s", again);
        size_t la = 0, lb = 0;
        char *a = nc_test_read(nc_test_path(name), &la), *b = nc_test_read(nc_test_path(again), &lb);
        CHECK(a && b && la == lb && !memcmp(a, b, la), "%s written 1.1 s later: not the same bytes", exts[e]);
        free(a);
        free(b);
    }

    /* NaN and Inf never reach a file. */
    float bad[4] = {NAN, INFINITY, -INFINITY, 2.0f};
    const char *p = nc_test_path("bad.exr");
    CHECK(nc_image_write(p, bad, 2, 2, NULL, 0, NULL) == 0, "bad.exr");
    float *px;
    int w, h;
    if (nc_image_read(p, &px, &w, &h) == 0) {
        CHECK(px[0] == 0 && px[1] == 0 && px[2] == 0 && px[3] == 2.0f, "non-finite values replaced by 0");
        free(px);
    }
    CHECK(nc_image_write(nc_test_path("x.bmp"), bad, 2, 2, NULL, 0, NULL) < 0 &&
              nc_test_contains(nc_errmsg(), "unsupported output format"),
          "unsupported extension: %s", nc_errmsg());
    CHECK(nc_image_write("/nonexistent-dir/x.exr", bad, 2, 2, NULL, 0, NULL) < 0 &&
              nc_test_contains(nc_errmsg(), "/nonexistent-dir/x.exr"),
          "unwritable path names the file: %s", nc_errmsg());
    fits_rows();
    fits_foreign();
    whole_or_nothing();
    nc_frame_free(&f);
    nc_scene_free(&s);
    return nc_test_end();
}
