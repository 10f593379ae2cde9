/* image_fits.c - the FITS back-end of image_io, with cfitsio.
 *
 * OpenImageIO's FITS writer leaves string values unquoted and cuts them at
 * 72 characters, which standard FITS readers reject; cfitsio writes conforming
 * headers. NavCam's attributes get 8-character keywords from the table below
 * (long values continue with the CONTINUE convention), with the attribute
 * name as the card's comment; any other attribute becomes HIERARCH NAVCAM
 * NAME (cfitsio 4.2 drops the continuation of long HIERARCH values, so those
 * must stay short).
 * Row order: by default the top image row first (FITS row 1 is image row
 * y = 0, as NavCam's pixel coordinates run); with the attribute
 * navcam:fits_row_order = bottom_up, the archive convention of FITS
 * viewers and mission archives (row 1 at the bottom, +Y up). Either way the
 * keyword ROWORDER says which ('TOP-DOWN' or 'BOTTOM-UP'), and reading turns
 * a BOTTOM-UP file back into top-down rows.
 */
#include <ctype.h>
#include <errno.h>
#include <fitsio.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/lines.h"
#include "render/image_io_impl.h"

static const char *const fits_keys[][2] = {
    {"Software", "CREATOR"},
    {"navcam:version", "NCVERSN"},
    {"navcam:quantity", "QUANTITY"},
    {"navcam:units", "NCUNITS"}, /* and BUNIT, in FITS units (fits_unit) */
    {"navcam:camera_position_m", "CAMPOS"},
    {"navcam:camera_attitude_q", "CAMQUAT"},
    {"navcam:quaternion_convention", "QCONVENT"},
    {"navcam:camera_frame", "CAMFRAME"},
    {"navcam:sun_direction_scene", "SUNDIR"},
    {"navcam:sun_irradiance_w_m2", "SUNIRR"},
    {"navcam:intrinsics_fx_fy_cx_cy_px", "INTRINS"},
    {"navcam:samples_per_pixel", "SPP"},
    {"navcam:light", "LIGHT"},
    {"navcam:body0_position_m", "BODYPOS"},
    {"navcam:body0_attitude_q", "BODYQUAT"},
    {"navcam:preview_scale", "PRVSCALE"},
    {"navcam:distortion_k1_k2_k3_p1_p2", "DISTORT"},
    {"navcam:adc_bits", "ADCBITS"},
    {"navcam:gain_e_per_dn", "GAINEDN"},
    {"navcam:analog_gain_db", "AGAINDB"},
    {"navcam:bias_dn", "BIASDN"},
    {"navcam:exposure_s", "EXPTIME"},
    {"navcam:frame", "FRAME"},
    {"navcam:frames", "NFRAMES"},
    {"navcam:radiance_w_m2_sr", "RADIANCE"},
    {"navcam:frame_record", "FRAMEREC"},
    {"navcam:preview_rule", "PRVRULE"},
    {"navcam:fits_row_order", "ROWORDER"},
    {"navcam:lod_error_m", "LODERR"},
    {"navcam:boulder_min_m", "ROCKMIN"},
    {"navcam:boulder_mesh_px", "ROCKMESH"},
    {"navcam:normals", "NORMALS"},
    {"navcam:rock_fold_theta_bar_deg", "ROCKFOLD"},
    {"navcam:stars", "STARS"},
    {"navcam:sun_view", "SUNVIEW"},
};

/* NavCam's units (nc_quantity_units) as FITS units (FITS 4.0, 4.3) that
 * unit parsers take: electrons and DN by the names astropy reads, the
 * dimensionless quantities (I/F, a rock's index) as none. */
static const char *fits_unit(const char *u)
{
    return !strcmp(u, "e-") ? "electron" : !strcmp(u, "DN") ? "adu" : !strncmp(u, "1 (", 3) ? "" : u;
}

/* 1 when attrs ask for the archive row order (row 1 at the bottom). */
static int bottom_up(const struct nc_image_attr *attrs, int nattrs)
{
    for (int i = 0; i < nattrs; i++)
        if (!strcmp(attrs[i].name, "navcam:fits_row_order"))
            return !strcmp(attrs[i].value, "bottom_up");
    return 0;
}

/* Rows of every plane in reverse order (a copy; caller frees). */
static void *flip_rows(const void *px, size_t elem, int w, int h, int depth)
{
    size_t row = elem * (size_t)w;
    unsigned char *out = malloc(row * (size_t)h * (size_t)depth);
    const unsigned char *in = px;
    for (int d = 0; out && d < depth; d++)
        for (int y = 0; y < h; y++)
            memcpy(out + ((size_t)d * h + (size_t)(h - 1 - y)) * row, in + ((size_t)d * h + (size_t)y) * row, row);
    return out;
}

static void fits_key(const char *attr, char *key, size_t len)
{
    if (!strncmp(attr, "fits:", 5)) { /* a FITS keyword of its own (the WCS) */
        snprintf(key, len, "%s", attr + 5);
        return;
    }
    for (size_t i = 0; i < sizeof fits_keys / sizeof fits_keys[0]; i++)
        if (!strcmp(attr, fits_keys[i][0])) {
            snprintf(key, len, "%s", fits_keys[i][1]);
            return;
        }
    const char *colon = strchr(attr, ':');
    snprintf(key, len, "%s%s", colon ? "NAVCAM " : "", colon ? colon + 1 : attr);
    for (char *k = key; *k; k++)
        *k = (char)toupper((unsigned char)*k);
}

static int fits_fail(const char *path, const char *op, int status)
{
    char msg[FLEN_STATUS];
    fits_get_errstatus(status, msg);
    return nc_error(NC_EIMAGE, "%s: cfitsio %s: %s", path, op, msg);
}

int nc__fits_write(const char *path, const void *px, enum nc__pixel type, int w, int h, int depth,
                   const struct nc_image_attr *attrs, int nattrs)
{
    fitsfile *f = NULL;
    int status = 0;
    char fname[4200];
    snprintf(fname, sizeof fname, "!%s", path); /* '!' = overwrite */
    long naxes[3] = {w, h, depth};
    /* Unsigned 16-bit is BITPIX 16 with BZERO 32768 (cfitsio's USHORT_IMG). */
    int bitpix = type == NC__PX_FLOAT ? FLOAT_IMG : type == NC__PX_U16 ? USHORT_IMG : BYTE_IMG;
    int dtype = type == NC__PX_FLOAT ? TFLOAT : type == NC__PX_U16 ? TUSHORT : TBYTE;
    const int up = bottom_up(attrs, nattrs);
    size_t elem = type == NC__PX_FLOAT ? 4 : type == NC__PX_U16 ? 2 : 1;
    void *flipped = up ? flip_rows(px, elem, w, h, depth) : NULL;
    if (up && !flipped)
        return nc_error(-ENOMEM, "%s: out of memory", path);
    if (fits_create_file(&f, fname, &status) || fits_create_img(f, bitpix, depth > 1 ? 3 : 2, naxes, &status))
        goto fail;
    fits_write_key_longwarn(f, &status);
    for (int i = 0; i < nattrs && !status; i++) {
        char key[80], *end;
        fits_key(attrs[i].name, key, sizeof key);
        if (!strcmp(attrs[i].name, "navcam:fits_row_order"))
            continue; /* written below, in the keyword's own spelling */
        if (!strcmp(attrs[i].name, "navcam:units"))
            fits_write_key_str(f, "BUNIT", fits_unit(attrs[i].value), "physical unit of the data (NCUNITS: NavCam's)",
                               &status);
        /* Numbers as FITS numbers (EXPTIME, ADCBITS, ...), the rest as strings. */
        double v = strtod(attrs[i].value, &end);
        const int turned = up && (!strcmp(key, "CRPIX2") || !strcmp(key, "CD1_2") || !strcmp(key, "CD2_2"));
        if (turned) /* the WCS of top-down rows, turned: FITS row p2 becomes h + 1 - p2 */
            v = !strcmp(key, "CRPIX2") ? h + 1 - v : -v;
        /* a number in digits alone (a frame number past 2^53 too) keeps every digit */
        const char *digits = attrs[i].value + (attrs[i].value[0] == '-');
        const int whole = !turned && digits[0] && strspn(digits, "0123456789") == strlen(digits);
        long long sv = 0;
        unsigned long long uv = 0;
        int exact = 0;
        if (whole) {
            errno = 0;
            sv = strtoll(attrs[i].value, NULL, 10);
            exact = errno == 0 ? 1 : 0;
            if (!exact && digits == attrs[i].value) {
                errno = 0;
                uv = strtoull(attrs[i].value, NULL, 10);
                exact = errno == 0 ? 2 : 0;
            }
        }
        if (end != attrs[i].value && !*end && isfinite(v)) {
            if (exact == 1)
                fits_write_key_lng(f, key, sv, attrs[i].name, &status);
            else if (exact == 2)
                fits_write_key_ulng(f, key, uv, attrs[i].name, &status);
            else if (v == floor(v) && fabs(v) < 1e15 && !strpbrk(attrs[i].value, ".eE"))
                fits_write_key_lng(f, key, (LONGLONG)v, attrs[i].name, &status);
            else
                fits_write_key_dbl(f, key, v, -17, attrs[i].name, &status);
        } else {
            fits_write_key_longstr(f, key, attrs[i].value, attrs[i].name, &status);
        }
    }
    fits_write_key_str(f, "ROWORDER", up ? "BOTTOM-UP" : "TOP-DOWN", "order of the image rows in the data", &status);
    fits_write_comment(f, up ? "Row 1 is the bottom image row (y = height - 1): +Y up, as FITS viewers show it."
                             : "Row 1 is the top image row (y = 0, +Y down).",
                       &status);
    for (int i = 0; i < nattrs; i++)
        if (!strcmp(attrs[i].name, "navcam:intrinsics_fx_fy_cx_cy_px")) {
            fits_write_comment(f, "Pixel coordinates in INTRINS run from the top row down.", &status);
            break;
        }
    fits_write_comment(f, "Each NavCam metadata card carries its attribute name as its comment.", &status);
    if (status || fits_write_img(f, dtype, 1, (LONGLONG)w * h * depth, flipped ? flipped : (void *)px, &status))
        goto fail;
    free(flipped);
    if (fits_close_file(f, &status))
        return fits_fail(path, "close", status);
    return 0;
fail:;
    int rc = fits_fail(path, "write", status);
    free(flipped);
    status = 0;
    if (f)
        fits_close_file(f, &status);
    return rc;
}

/* BSCALE and BZERO, where given, are numbers (cfitsio would take a bad one as 1 and 0 unseen). */
static int scale_ok(fitsfile *f, const char *path)
{
    static const char *const keys[] = {"BSCALE", "BZERO"};
    for (int i = 0; i < 2; i++) {
        char raw[FLEN_VALUE], *end;
        int status = 0;
        if (fits_read_keyword(f, keys[i], raw, NULL, &status))
            continue; /* not given */
        const double v = nc_strtod_fortran(raw, &end); /* FITS allows Fortran's D exponent */
        if (end == raw || end[strspn(end, " ")] || !isfinite(v))
            return nc_error(NC_EIMAGE, "%s: %s = %s is not a finite number", path, keys[i], raw);
    }
    return 0;
}

int nc__fits_read(const char *path, float **px, int *w, int *h)
{
    fitsfile *f = NULL;
    int status = 0, naxis = 0;
    long naxes[3] = {0, 0, 1};
    if (fits_open_image(&f, path, READONLY, &status) || fits_get_img_dim(f, &naxis, &status) ||
        fits_get_img_size(f, naxis > 3 ? 3 : naxis, naxes, &status)) {
        int rc = fits_fail(path, "open", status);
        status = 0;
        if (f)
            fits_close_file(f, &status);
        return rc;
    }
    long planes = naxes[2];
    for (int k = 4; k <= naxis; k++) { /* the sizes of axes past the third */
        char key[16];
        long len = 1;
        snprintf(key, sizeof key, "NAXIS%d", k);
        if (!fits_read_key_lng(f, key, &len, NULL, &status))
            planes *= len;
        status = 0;
    }
    char order[FLEN_VALUE] = "";
    if (fits_read_key_str(f, "ROWORDER", order, NULL, &status))
        status = 0, order[0] = '\0'; /* files from elsewhere: top-down, as NavCam wrote them before */
    if (naxis < 2 || planes != 1 || (order[0] && strcmp(order, "TOP-DOWN") && strcmp(order, "BOTTOM-UP"))) {
        fits_close_file(f, &status);
        if (naxis < 2 || planes != 1)
            return nc_error(NC_EIMAGE, "%s: %d axes%s: an image here is one plane of 2 axes", path, naxis,
                            planes != 1 ? ", more than one plane" : "");
        return nc_error(NC_EIMAGE, "%s: ROWORDER '%s': expected 'TOP-DOWN' or 'BOTTOM-UP'", path, order);
    }
    if (naxes[0] < 1 || naxes[1] < 1) {
        fits_close_file(f, &status);
        return nc_error(NC_EIMAGE, "%s: %ldx%ld pixels: an empty image", path, naxes[0], naxes[1]);
    }
    size_t n = (size_t)naxes[0] * (size_t)naxes[1];
    float *buf = malloc((n ? n : 1) * sizeof *buf);
    double *row = malloc((naxes[0] ? (size_t)naxes[0] : 1) * sizeof *row);
    if (!buf || !row) {
        free(buf);
        free(row);
        fits_close_file(f, &status);
        return nc_error(-ENOMEM, "%s: out of memory", path);
    }
    int rc = scale_ok(f, path);
    /* Row by row in double: a pixel the BLANK keyword (or IEEE NaN) marks undefined becomes NaN, and so does a
     * value beyond a float's range (a float64 file's fill value, such as -DBL_MAX), as a float TIFF's would. */
    const double nul = NAN;
    for (long y = 0; rc == 0 && y < naxes[1]; y++) {
        int anynul = 0;
        if (fits_read_img(f, TDOUBLE, 1 + y * naxes[0], naxes[0], (void *)&nul, row, &anynul, &status)) {
            rc = fits_fail(path, "read", status);
            break;
        }
        for (long x = 0; x < naxes[0]; x++)
            buf[(size_t)y * (size_t)naxes[0] + (size_t)x] = fabs(row[x]) <= FLT_MAX ? (float)row[x] : NAN;
    }
    free(row);
    if (rc < 0) {
        free(buf);
        status = 0;
        fits_close_file(f, &status);
        return rc;
    }
    fits_close_file(f, &status);
    *w = (int)naxes[0];
    *h = (int)naxes[1];
    if (!strcmp(order, "BOTTOM-UP"))
        nc_image_flip(buf, sizeof *buf, *w, *h, 1, 0);
    *px = buf;
    return 0;
}

int nc__fits_read_attr(const char *path, const char *name, char *buf, size_t len)
{
    fitsfile *f = NULL;
    int status = 0;
    char key[80], *val = NULL;
    fits_key(name, key, sizeof key);
    if (fits_open_image(&f, path, READONLY, &status))
        return fits_fail(path, "open", status);
    char raw[FLEN_VALUE];
    int rc = 0;
    if (fits_read_keyword(f, key, raw, NULL, &status)) {
        rc = nc_error(NC_EIMAGE, "%s: no keyword %s (%s)", path, key, name);
    } else if (raw[0] == '\'') {
        fits_read_key_longstr(f, key, &val, NULL, &status);
        snprintf(buf, len, "%s", status ? "" : val);
    } else {
        snprintf(buf, len, "%s", raw); /* a number, as written */
    }
    if (val)
        fits_free_memory(val, &status);
    status = 0;
    fits_close_file(f, &status);
    return rc;
}
