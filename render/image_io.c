/* image_io.c - image files by extension: float32 formats keep values as
 * given, PNG gets a 16-bit linear preview with its scale in the metadata.
 * NaN and Inf never reach a file. Metadata also goes, as one JSON object, into
 * ImageDescription, the one field every format here keeps. */
#include "render/image_io.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/fs.h"
#include "render/image_io_impl.h"

enum fmt { FMT_NONE, FMT_EXR, FMT_TIFF, FMT_FITS, FMT_PNG };

static enum fmt format_of(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return FMT_NONE;
    dot++;
    if (!strcasecmp(dot, "exr"))
        return FMT_EXR;
    if (!strcasecmp(dot, "tif") || !strcasecmp(dot, "tiff"))
        return FMT_TIFF;
    if (!strcasecmp(dot, "fits") || !strcasecmp(dot, "fit") || !strcasecmp(dot, "fts"))
        return FMT_FITS;
    if (!strcasecmp(dot, "png"))
        return FMT_PNG;
    return FMT_NONE;
}

int nc_image_is_fits(const char *path) { return format_of(path) == FMT_FITS; }

int nc_image_fits_row_order_ok(const char *word)
{
    if (!strcmp(word, "top_down") || !strcmp(word, "bottom_up"))
        return 0;
    return nc_error(NC_EUSAGE, "FITS row order '%s': expected top_down (row 1 is the top image row, NavCam's "
                               "default) or bottom_up (row 1 at the bottom, as FITS viewers and archives show it)",
                    word);
}

int nc_image_format_ok(const char *path, int *is_float)
{
    enum fmt f = format_of(path);
    if (is_float)
        *is_float = f == FMT_EXR || f == FMT_TIFF || f == FMT_FITS;
    return f != FMT_NONE;
}

int nc_image_prepare(const char *path)
{
    enum fmt f = format_of(path);
    return f == FMT_NONE || f == FMT_FITS ? 0 : nc__oiio_load();
}

/* Every image is written under a temporary name beside path and renamed
 * into place once whole: a reader never sees a partial file, a failed write
 * leaves none, and what was at path (a file; a directory, which the rename
 * refuses) stays until the new file is complete. The name keeps path's
 * extension, which picks the format. */
static int tmp_path(const char *path, char *tmp, size_t len)
{
    const char *slash = strrchr(path, '/'), *base = slash ? slash + 1 : path, *dot = strrchr(base, '.');
    int n = snprintf(tmp, len, "%.*s.%.*s.%ld.tmp%s", (int)(base - path), path, (int)(dot - base), base,
                     (long)getpid(), dot);
    return n < 0 || (size_t)n >= len ? nc_error(NC_EIMAGE, "%s: path too long", path) : 0;
}

/* px (w x h x depth of type t) to path, by its extension (FITS through
 * cfitsio, the rest through OpenImageIO, one plane), as above. */
static int write_file(const char *path, const void *px, enum nc__pixel t, int w, int h, int depth,
                      const struct nc_image_attr *attrs, int nattrs, const char *desc)
{
    char tmp[4200];
    int rc = tmp_path(path, tmp, sizeof tmp);
    if (rc < 0 || (rc = nc_fs_replaceable(path)) < 0)
        return rc;
    rc = format_of(path) == FMT_FITS ? nc__fits_write(tmp, px, t, w, h, depth, attrs, nattrs)
                                     : nc__oiio_write(tmp, px, w, h, t, attrs, nattrs, desc);
    if (rc >= 0 && rename(tmp, path) < 0)
        rc = nc_error(-errno, "%s: %s", path, strerror(errno));
    if (rc < 0) {
        const size_t n = strlen(tmp);
        if (!strncmp(nc_errmsg(), tmp, n)) { /* the writer's message names the file the user named */
            char msg[1024];
            snprintf(msg, sizeof msg, "%s", nc_errmsg() + n);
            nc_error(rc, "%s%s", path, msg);
        }
        unlink(tmp);
    }
    return rc;
}

/* {"name": "value", ...} with JSON string escapes. */
static char *describe(const struct nc_image_attr *attrs, int nattrs)
{
    size_t cap = 64;
    for (int i = 0; i < nattrs; i++)
        cap += 2 * (strlen(attrs[i].name) + strlen(attrs[i].value)) + 16;
    char *s = malloc(cap), *p = s;
    if (!s)
        return NULL;
    *p++ = '{';
    for (int i = 0, n = 0; i < nattrs; i++) {
        if (!strncmp(attrs[i].name, "fits:", 5))
            continue; /* FITS keywords of their own (the WCS): FITS files only */
        const char *parts[2] = {attrs[i].name, attrs[i].value};
        if (n++)
            *p++ = ',', *p++ = ' ';
        for (int k = 0; k < 2; k++) {
            *p++ = '"';
            for (const char *c = parts[k]; *c; c++) {
                if (*c == '"' || *c == '\\')
                    *p++ = '\\';
                *p++ = (unsigned char)*c < 0x20 ? ' ' : *c;
            }
            *p++ = '"';
            if (k == 0)
                *p++ = ':', *p++ = ' ';
        }
    }
    *p++ = '}';
    *p = '\0';
    return s;
}

int nc_image_write(const char *path, const float *px, int w, int h, const struct nc_image_attr *attrs, int nattrs,
                   double *preview_scale)
{
    enum fmt f = format_of(path);
    if (f == FMT_NONE)
        return nc_error(NC_EIMAGE,
                        "%s: unsupported output format (use .exr, .tif or .fits for float32 values, .png for a 16-bit preview)",
                        path);
    size_t n = (size_t)w * (size_t)h;
    float *clean = malloc((n ? n : 1) * sizeof *clean);
    uint16_t *dn = NULL;
    struct nc_image_attr *all = malloc((size_t)(nattrs + 2) * sizeof *all);
    char *desc = NULL, scale_txt[64];
    int rc;
    if (!clean || !all) {
        rc = nc_error(-ENOMEM, "%s: out of memory", path);
        goto out;
    }
    double vmax = 0;
    for (size_t i = 0; i < n; i++) {
        clean[i] = isfinite(px[i]) ? px[i] : 0.0f;
        if (clean[i] > vmax)
            vmax = clean[i];
    }
    if (nattrs > 0)
        memcpy(all, attrs, (size_t)nattrs * sizeof *all);
    int nall = nattrs;
    if (preview_scale)
        *preview_scale = 0;
    if (f == FMT_PNG) {
        double scale = vmax > 0 ? vmax : 1.0;
        snprintf(scale_txt, sizeof scale_txt, "%.17g", scale);
        all[nall++] = (struct nc_image_attr){"navcam:preview_scale", scale_txt};
        all[nall++] = (struct nc_image_attr){"navcam:preview_rule",
                                             "value = DN / 65535 * navcam:preview_scale (linear, in navcam:units)"};
        if (preview_scale)
            *preview_scale = scale;
        if (!(dn = malloc((n ? n : 1) * sizeof *dn))) {
            rc = nc_error(-ENOMEM, "%s: out of memory", path);
            goto out;
        }
        for (size_t i = 0; i < n; i++) {
            double v = clean[i] / scale * 65535.0;
            dn[i] = (uint16_t)(v <= 0 ? 0 : v >= 65535 ? 65535 : lround(v));
        }
    }
    if (!(desc = describe(all, nall))) {
        rc = nc_error(-ENOMEM, "%s: out of memory", path);
        goto out;
    }
    rc = write_file(path, f == FMT_PNG ? (const void *)dn : clean, f == FMT_PNG ? NC__PX_U16 : NC__PX_FLOAT, w, h, 1,
                    all, nall, desc);
out:
    free(clean);
    free(dn);
    free(all);
    free(desc);
    return rc;
}

int nc_image_write_dn(const char *path, const uint16_t *dn, int w, int h, int bits, const struct nc_image_attr *attrs,
                      int nattrs)
{
    enum fmt f = format_of(path);
    if (f == FMT_NONE)
        return nc_error(NC_EIMAGE, "%s: unsupported output format (use .png, .tif, .fits or .exr)", path);
    size_t n = (size_t)w * (size_t)h;
    char *desc = describe(attrs, nattrs);
    void *buf = NULL;
    int rc;
    if (!desc)
        return nc_error(-ENOMEM, "out of memory");
    if (f == FMT_EXR) {
        float *v = malloc((n ? n : 1) * sizeof *v);
        if (v)
            for (size_t i = 0; i < n; i++)
                v[i] = dn[i];
        buf = v;
    } else if (bits <= 8) {
        uint8_t *v = malloc(n ? n : 1);
        if (v)
            for (size_t i = 0; i < n; i++)
                v[i] = (uint8_t)(dn[i] > 255 ? 255 : dn[i]);
        buf = v;
    }
    if (!buf && (f == FMT_EXR || bits <= 8)) {
        free(desc);
        return nc_error(-ENOMEM, "out of memory");
    }
    enum nc__pixel t = f == FMT_EXR ? NC__PX_FLOAT : bits <= 8 ? NC__PX_U8 : NC__PX_U16;
    const void *px = buf ? buf : (const void *)dn;
    rc = write_file(path, px, t, w, h, 1, attrs, nattrs, desc);
    free(buf);
    free(desc);
    return rc;
}

int nc_image_write_dn_cube(const char *path, const uint16_t *dn, int w, int h, int nframes, int bits,
                           const struct nc_image_attr *attrs, int nattrs)
{
    if (format_of(path) != FMT_FITS)
        return nc_error(NC_EIMAGE, "%s: a cube of frames needs .fits (or write numbered files)", path);
    size_t n = (size_t)w * (size_t)h * (size_t)nframes;
    if (bits > 8)
        return write_file(path, dn, NC__PX_U16, w, h, nframes, attrs, nattrs, NULL);
    uint8_t *v = malloc(n ? n : 1);
    if (!v)
        return nc_error(-ENOMEM, "out of memory");
    for (size_t i = 0; i < n; i++)
        v[i] = (uint8_t)(dn[i] > 255 ? 255 : dn[i]);
    int rc = write_file(path, v, NC__PX_U8, w, h, nframes, attrs, nattrs, NULL);
    free(v);
    return rc;
}

int nc_image_write_planes(const char *path, const float *planes, int w, int h, int nplanes, const char *const *names,
                          const struct nc_image_attr *attrs, int nattrs)
{
    if (format_of(path) != FMT_FITS)
        return nc_error(NC_EIMAGE, "%s: planes are written to FITS files (.fits) only", path);
    size_t n = (size_t)w * (size_t)h * (size_t)nplanes;
    float *clean = malloc((n ? n : 1) * sizeof *clean);
    struct nc_image_attr *all = malloc((size_t)(nattrs + nplanes) * sizeof *all);
    char (*key)[24] = malloc((size_t)nplanes * sizeof *key);
    int rc;
    if (!clean || !all || !key) {
        rc = nc_error(-ENOMEM, "%s: out of memory", path);
        goto out;
    }
    for (size_t i = 0; i < n; i++)
        clean[i] = isfinite(planes[i]) ? planes[i] : 0.0f;
    if (nattrs > 0)
        memcpy(all, attrs, (size_t)nattrs * sizeof *all);
    for (int k = 0; k < nplanes; k++) {
        snprintf(key[k], sizeof key[k], "PLANE%d", k + 1);
        all[nattrs + k] = (struct nc_image_attr){key[k], names[k]};
    }
    rc = write_file(path, clean, NC__PX_FLOAT, w, h, nplanes, all, nattrs + nplanes, NULL);
out:
    free(clean);
    free(all);
    free(key);
    return rc;
}

void nc_image_flip(void *px, size_t elem, int w, int h, int rows, int cols)
{
    unsigned char *p = px, tmp[8];
    const size_t W = (size_t)w, H = (size_t)h;
    if (rows)
        for (size_t y = 0; y < H / 2; y++)
            for (size_t x = 0; x < W; x++) {
                unsigned char *a = p + (y * W + x) * elem, *b = p + ((H - 1 - y) * W + x) * elem;
                memcpy(tmp, a, elem);
                memcpy(a, b, elem);
                memcpy(b, tmp, elem);
            }
    if (cols)
        for (size_t y = 0; y < H; y++)
            for (size_t x = 0; x < W / 2; x++) {
                unsigned char *a = p + (y * W + x) * elem, *b = p + (y * W + W - 1 - x) * elem;
                memcpy(tmp, a, elem);
                memcpy(a, b, elem);
                memcpy(b, tmp, elem);
            }
}

/* After a failed read: why, where the path itself says it (cfitsio and
 * OpenImageIO say "could not open the named file" for a missing,
 * unreadable or looping path alike, and a directory is "error reading from
 * FITS file"); the readers' own message otherwise. Asked only after the
 * read, so that cfitsio's extended names (file.fits[1]) still reach it. */
static int why_unread(const char *path, int rc)
{
    struct stat st;
    if (stat(path, &st) < 0) /* a missing "x.fits[1]" is cfitsio's to explain */
        return errno == ENOENT && strchr(path, '[') ? rc : nc_error(-errno, "%s: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode))
        return nc_error(NC_EIMAGE, "%s: is a directory, not an image", path);
    if (access(path, R_OK) < 0)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    return rc;
}

int nc_image_read(const char *path, float **px, int *w, int *h)
{
    const int rc = format_of(path) == FMT_FITS ? nc__fits_read(path, px, w, h) : nc__oiio_read(path, px, w, h);
    return rc < 0 ? why_unread(path, rc) : rc;
}

/* Value of "name" in the JSON object written by describe(). */
static int json_get(const char *json, const char *name, char *buf, size_t len)
{
    char pat[256];
    snprintf(pat, sizeof pat, "\"%s\": \"", name);
    const char *p = strstr(json, pat);
    if (!p)
        return -1;
    p += strlen(pat);
    size_t k = 0;
    for (; *p && *p != '"' && k + 1 < len; p++) {
        if (*p == '\\' && p[1])
            p++;
        buf[k++] = *p;
    }
    buf[k] = '\0';
    return 0;
}

static int read_attr(const char *path, const char *name, char *buf, size_t len)
{
    int rc;
    enum fmt f = format_of(path);
    if (f == FMT_FITS)
        return nc__fits_read_attr(path, name, buf, len);
    if (f != FMT_TIFF)
        return nc__oiio_read_attr(path, name, buf, len);
    /* TIFF keeps only ImageDescription. */
    char *desc = malloc(65536);
    if (!desc)
        return nc_error(-ENOMEM, "out of memory");
    rc = nc__oiio_read_attr(path, "ImageDescription", desc, 65536);
    if (rc == 0 && json_get(desc, name, buf, len) < 0)
        rc = nc_error(NC_EIMAGE, "%s: no attribute '%s' in ImageDescription", path, name);
    free(desc);
    return rc;
}

int nc_image_read_attr(const char *path, const char *name, char *buf, size_t len)
{
    const int rc = read_attr(path, name, buf, len);
    return rc < 0 ? why_unread(path, rc) : rc;
}
