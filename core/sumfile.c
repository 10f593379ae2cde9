/* sumfile.c - reading and writing SPC SUM files (sumfile.h). */
#include "core/sumfile.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/lines.h"
#include "core/pose.h"

enum { IT_SIZE, IT_MMFL, IT_SCOBJ, IT_CX, IT_CY, IT_CZ, IT_SZ, IT_K, IT_DIST, IT_SIGMA_VSO, IT_SIGMA_PTG, IT_N };
static const struct {
    const char *label; /* how the line's label starts */
    int count;         /* numbers before it (-1: not read) */
} items[IT_N] = {{"NPX", 4},   {"MMFL", 3},     {"SCOBJ", 3},     {"CX", 3},        {"CY", 3},       {"CZ", 3},
                 {"SZ", 3},    {"K-MATRIX", 6}, {"DISTORTION", 4}, {"SIGMA_VSO", -1}, {"SIGMA_PTG", -1}};

/* Skew the pixel grid may have (K12, K21) and still be taken as none: the
 * most it moves a pixel over the image, px. */
#define SKEW_MAX_PX 0.05

static void trim(char *s)
{
    size_t n = strlen(s);
    while (n && isspace((unsigned char)s[n - 1]))
        s[--n] = 0;
}

/* Where label starts as a word of line (at its start or after a blank, a
 * comma or a digit: a label glued to the line's last number, `0.5D+00CX`,
 * as fixed-width Fortran output can print it; and followed by neither a
 * letter, a digit nor '_'), or NULL. */
static const char *label_at(const char *line, const char *label)
{
    const size_t n = strlen(label);
    for (const char *p = strstr(line, label); p; p = strstr(p + 1, label))
        if ((p == line || isspace((unsigned char)p[-1]) || p[-1] == ',' || isdigit((unsigned char)p[-1])) &&
            !isalnum((unsigned char)p[n]) && p[n] != '_')
            return p;
    return NULL;
}

/* The item whose label the line carries after its numbers, and where: -1
 * if none; *other another item the line names too (-1: none). */
static int find_label(const char *line, const char **at, int *other)
{
    int found = -1;
    *other = -1;
    for (int it = 0; it < IT_N; it++) {
        const char *p = label_at(line, items[it].label);
        if (!p)
            continue;
        if (found < 0)
            found = it, *at = p;
        else if (p < *at)
            *other = found, found = it, *at = p;
        else
            *other = it;
    }
    return found;
}

/* The numbers of text (blank- or comma-separated; Fortran D exponents read
 * as E) into v[0..max); how many, or -1 with *bad the token that is not a
 * number (NUL-terminated in place). */
static int numbers(char *text, double *v, int max, char **bad)
{
    int n = 0;
    for (char *s = text;;) {
        s += strspn(s, " \t,");
        if (!*s)
            return n;
        char *tok = s, *end;
        s += strcspn(s, " \t,");
        if (*s)
            *s++ = 0;
        const double x = nc_strtod_fortran(tok, &end);
        if (*end || end == tok) {
            *bad = tok;
            return -1;
        }
        if (n < max)
            v[n] = x;
        n++;
    }
}

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

int nc_sumfile_rotation(const double *const ax[3], struct nc_quat *q, int *item)
{
    static const char *const names[3] = {"CX", "CY", "CZ"};
    for (int a = 0; a < 3; a++) {
        *item = a;
        const double len = sqrt(dot(ax[a], ax[a]));
        if (!(fabs(len - 1) <= NC_SUMFILE_AXES_TOL))
            return nc_error(NC_ECONFIG, "%s: not a unit vector (length %.9g; within %g of 1 is taken)", names[a],
                            len, NC_SUMFILE_AXES_TOL);
        for (int b = 0; b < a; b++)
            if (!(fabs(dot(ax[a], ax[b])) <= NC_SUMFILE_AXES_TOL))
                return nc_error(NC_ECONFIG, "%s and %s are not perpendicular (dot product %.6g; up to %g is taken)",
                                names[b], names[a], dot(ax[a], ax[b]), NC_SUMFILE_AXES_TOL);
    }
    const double *x0 = ax[0], *y0 = ax[1], *z0 = ax[2];
    const double c[3] = {x0[1] * y0[2] - x0[2] * y0[1], x0[2] * y0[0] - x0[0] * y0[2], x0[0] * y0[1] - x0[1] * y0[0]};
    if (dot(c, z0) < 0)
        return nc_error(NC_ECONFIG, "CX, CY, CZ are left-handed (CX x CY = -CZ): not a rotation");
    /* Exactly orthonormal: CZ kept (a point on the boresight stays at CTR,
     * as SPC projects it), CX made perpendicular to it, CY = CZ x CX. */
    double z[3], x[3], y[3];
    const double lz = sqrt(dot(z0, z0)), xz = dot(x0, z0) / (lz * lz);
    for (int i = 0; i < 3; i++) {
        z[i] = z0[i] / lz;
        x[i] = x0[i] - xz * z0[i];
    }
    const double lx = sqrt(dot(x, x));
    for (int i = 0; i < 3; i++)
        x[i] /= lx;
    y[0] = z[1] * x[2] - z[2] * x[1];
    y[1] = z[2] * x[0] - z[0] * x[2];
    y[2] = z[0] * x[1] - z[1] * x[0];
    struct nc_mat3 r; /* columns: the camera axes in the body frame */
    for (int i = 0; i < 3; i++) {
        r.m[i][0] = x[i];
        r.m[i][1] = y[i];
        r.m[i][2] = z[i];
    }
    *q = nc_quat_from_mat(&r);
    return 0;
}

/* The K-MATRIX terms NavCam's camera does not model: K13 and K23 must be
 * 0, and K12, K21 (a skewed grid) may move no pixel by more than
 * SKEW_MAX_PX over the image; the DISTORTION terms must be 0. */
static int unmodelled(const char *path, const int *seen, const struct nc_sumfile *s, const double *dist)
{
    const double *k = s->k;
    if (k[2] != 0 || k[5] != 0)
        return nc_error(NC_ECONFIG, "%s:%d: K-MATRIX: K13 = %g, K23 = %g: NavCam's camera has no such terms (it "
                                    "needs both 0)",
                        path, seen[IT_K], k[2], k[5]);
    const double ex = fmax(fabs(1 - s->ctr[0]), fabs(s->npx - s->ctr[0])) / fabs(k[0]), /* mm from CTR */
        ey = fmax(fabs(1 - s->ctr[1]), fabs(s->nln - s->ctr[1])) / fabs(k[4]);
    const double skew = fmax(fabs(k[1]) * ey, fabs(k[3]) * ex);
    if (!(skew <= SKEW_MAX_PX))
        return nc_error(NC_ECONFIG, "%s:%d: K-MATRIX: K12 = %g, K21 = %g skew the pixel grid, moving pixels by up "
                                    "to %.3g px; NavCam's camera has no skew and takes it as none only up to %g px",
                        path, seen[IT_K], k[1], k[3], skew, SKEW_MAX_PX);
    if (seen[IT_DIST] && (dist[0] != 0 || dist[1] != 0 || dist[2] != 0 || dist[3] != 0))
        return nc_error(NC_ECONFIG, "%s:%d: DISTORTION: %g %g %g %g: NavCam does not model SPC's distortion terms "
                                    "(it needs all four 0)",
                        path, seen[IT_DIST], dist[0], dist[1], dist[2], dist[3]);
    return 0;
}

int nc_sumfile_read(const char *path, struct nc_sumfile *out)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    struct nc_lines ln;
    nc_lines_init(&ln, f, path, NC_ECONFIG);
    int lineno = 0, seen[IT_N] = {0}, rc;
    double dist[4] = {0};
    while ((rc = nc_lines_next(&ln)) > 0) {
        rc = 0; /* a line read; an error below sets it */
        char *line = ln.line;
        lineno = (int)ln.no;
        if (strcspn(line, "\r\n") > 1024) { /* the line's text; its end not counted */
            rc = nc_error(NC_ECONFIG, "%s:%d: line longer than 1024 bytes: not a SUM file", path, lineno);
            break;
        }
        trim(line);
        if (lineno == 1) {
            snprintf(out->picture, sizeof out->picture, "%s", line + strspn(line, " \t"));
            continue;
        }
        if (lineno == 2) {
            snprintf(out->utc, sizeof out->utc, "%s", line + strspn(line, " \t"));
            continue;
        }
        const char *start = line + strspn(line, " \t");
        if (!strncmp(start, "LANDMARKS", 9) || !strncmp(start, "END FILE", 8))
            break;
        const char *at;
        int other;
        const int it = find_label(line, &at, &other);
        if (other >= 0) {
            rc = nc_error(NC_ECONFIG, "%s:%d: the line is labelled both %s and %s: one label a line", path, lineno,
                          items[it].label, items[other].label);
            break;
        }
        if (it < 0 || items[it].count < 0)
            continue; /* SIGMA_VSO, SIGMA_PTG, lines NavCam does not know */
        if (seen[it]) {
            rc = nc_error(NC_ECONFIG, "%s:%d: %s: given twice (lines %d and %d)", path, lineno, items[it].label,
                          seen[it], lineno);
            break;
        }
        line[at - line] = 0;
        double v[8];
        char *bad;
        const int n = numbers(line, v, 8, &bad);
        if (n < 0) {
            rc = nc_error(NC_ECONFIG, "%s:%d: %s: '%s' is not a number", path, lineno, items[it].label, bad);
            break;
        }
        if (n != items[it].count) {
            rc = nc_error(NC_ECONFIG, "%s:%d: %s: expected %d numbers before the label, found %d", path, lineno,
                          items[it].label, items[it].count, n);
            break;
        }
        for (int k = 0; k < n && !rc; k++)
            if (!isfinite(v[k]))
                rc = nc_error(NC_ECONFIG, "%s:%d: %s: number %d is not finite", path, lineno, items[it].label, k + 1);
        if (rc)
            break;
        seen[it] = lineno;
        double *dst[IT_N] = {NULL, NULL, out->scobj_km, out->cx, out->cy, out->cz, out->sz, out->k, dist};
        if (it == IT_SIZE) {
            if (v[0] != floor(v[0]) || v[1] != floor(v[1]) || v[0] < 1 || v[0] > 16384 || v[1] < 1 || v[1] > 16384) {
                rc = nc_error(NC_ECONFIG, "%s:%d: NPX, NLN: expected image sizes of 1..16384 pixels, got %g x %g",
                              path, lineno, v[0], v[1]);
                break;
            }
            out->npx = (int)v[0];
            out->nln = (int)v[1];
        } else if (it == IT_MMFL) {
            out->mmfl_mm = v[0];
            out->ctr[0] = v[1];
            out->ctr[1] = v[2];
        } else {
            memcpy(dst[it], v, (size_t)items[it].count * sizeof *v);
        }
    }
    nc_lines_free(&ln);
    fclose(f);
    if (rc < 0)
        return rc;
    if (lineno < 2)
        return nc_error(NC_ECONFIG, "%s: %d lines: not a SUM file (picture name, UTC, then the geometry)", path,
                        lineno);
    for (int it = 0; it <= IT_K; it++)
        if (!seen[it])
            return nc_error(NC_ECONFIG, "%s: no %s line (expected %d numbers followed by the label '%s')", path,
                            items[it].label, items[it].count, items[it].label);
    if (!(out->mmfl_mm > 0))
        return nc_error(NC_ECONFIG, "%s:%d: MMFL: the focal length must be > 0 mm, got %g", path, seen[IT_MMFL],
                        out->mmfl_mm);
    const double *ax[3] = {out->cx, out->cy, out->cz};
    int item;
    if (nc_sumfile_rotation(ax, &out->q, &item) < 0) {
        char why[256];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_error(NC_ECONFIG, "%s:%d: %s", path, seen[IT_CX + item], why);
    }
    if (!(dot(out->sz, out->sz) > 0))
        return nc_error(NC_ECONFIG, "%s:%d: SZ: the Sun direction is zero", path, seen[IT_SZ]);
    if (out->k[0] == 0 || out->k[4] == 0)
        return nc_error(NC_ECONFIG, "%s:%d: K-MATRIX: K11 and K22 (pixels/mm) must not be zero", path, seen[IT_K]);
    const double fx = out->mmfl_mm * fabs(out->k[0]), fy = out->mmfl_mm * fabs(out->k[4]);
    if (!(fx >= NC_FOCAL_MIN_PX && fx <= NC_FOCAL_MAX_PX && fy >= NC_FOCAL_MIN_PX && fy <= NC_FOCAL_MAX_PX))
        return nc_error(NC_ECONFIG, "%s:%d: K-MATRIX: MMFL x K11, K22 give focal lengths of %g x %g pixels, expected "
                        "%g to %g", path, seen[IT_K], fx, fy, NC_FOCAL_MIN_PX, NC_FOCAL_MAX_PX);
    if (!(fabs(out->ctr[0]) <= NC_PRINCIPAL_MAX_PX && fabs(out->ctr[1]) <= NC_PRINCIPAL_MAX_PX))
        return nc_error(NC_ECONFIG, "%s:%d: CTR: the principal point (%g, %g) lies beyond %g pixels", path,
                        seen[IT_MMFL], out->ctr[0], out->ctr[1], NC_PRINCIPAL_MAX_PX);
    return unmodelled(path, seen, out, dist);
}

int nc_sumfile_write(const char *path, const struct nc_sumfile *s)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    fprintf(f, "%s\n%s\n", s->picture, s->utc);
    fprintf(f, "%6d%6d%6d%6d%52s\n", s->npx, s->nln, 0, 65535, "NPX, NLN, THRSH");
    fprintf(f, "%20.10E%20.10E%20.10E  MMFL, CTR\n", s->mmfl_mm, s->ctr[0], s->ctr[1]);
    const double *v[5] = {s->scobj_km, s->cx, s->cy, s->cz, s->sz};
    static const char *const lab[5] = {"SCOBJ", "CX", "CY", "CZ", "SZ"};
    for (int i = 0; i < 5; i++)
        fprintf(f, "%20.10E%20.10E%20.10E  %s\n", v[i][0], v[i][1], v[i][2], lab[i]);
    for (int i = 0; i < 6; i++)
        fprintf(f, "%18.10E", s->k[i]);
    fprintf(f, "  K-MATRIX\n");
    fprintf(f, "%15.5E%15.5E%15.5E%15.5E  DISTORTION\n", 0.0, 0.0, 0.0, 0.0);
    fprintf(f, "%20.10E%20.10E%20.10E  SIGMA_VSO\n%20.10E%20.10E%20.10E  SIGMA_PTG\n", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    fprintf(f, "LANDMARKS\nLIMB FITS\nEND FILE\n");
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return nc_error(NC_EIMAGE, "%s: write failed", path);
    return 0;
}
