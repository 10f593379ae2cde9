/* sumfile.c - reading and writing SPC SUM files (sumfile.h). */
#include "core/sumfile.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

enum { IT_SIZE, IT_MMFL, IT_SCOBJ, IT_CX, IT_CY, IT_CZ, IT_SZ, IT_K, IT_N };
static const struct {
    const char *label; /* how the line's label starts */
    int count;         /* numbers before it */
} items[IT_N] = {{"NPX", 4}, {"MMFL", 3}, {"SCOBJ", 3}, {"CX", 3}, {"CY", 3}, {"CZ", 3}, {"SZ", 3}, {"K-MATRIX", 6}};

static void trim(char *s)
{
    size_t n = strlen(s);
    while (n && isspace((unsigned char)s[n - 1]))
        s[--n] = 0;
}

/* Numbers at the start of line (D exponents read as E), then the label. */
static int split(char *line, double *v, int max, char **label)
{
    for (char *c = line; *c; c++)
        if ((*c == 'D' || *c == 'd') && c > line && (isdigit((unsigned char)c[-1]) || c[-1] == '.') &&
            (c[1] == '+' || c[1] == '-' || isdigit((unsigned char)c[1])))
            *c = 'E';
    int n = 0;
    char *s = line, *end;
    for (;;) {
        s += strspn(s, " \t,");
        double x = strtod(s, &end);
        if (end == s || (*end && !isspace((unsigned char)*end) && *end != ','))
            break;
        if (n < max)
            v[n] = x;
        n++;
        s = end;
    }
    *label = s;
    trim(s);
    return n;
}

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

int nc_sumfile_read(const char *path, struct nc_sumfile *out)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    char line[1024];
    int lineno = 0, seen[IT_N] = {0}, rc = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        if (!strchr(line, '\n') && !feof(f)) {
            rc = nc_error(NC_ECONFIG, "%s:%d: line longer than %zu characters: not a SUM file", path, lineno,
                          sizeof line - 2);
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
        double v[8];
        char *label;
        int n = split(line, v, 8, &label);
        if (!strncmp(label, "LANDMARKS", 9) || !strncmp(label, "END FILE", 8))
            break;
        int it = 0;
        for (; it < IT_N; it++)
            if (!strncmp(label, items[it].label, strlen(items[it].label)) &&
                !isalnum((unsigned char)label[strlen(items[it].label)]))
                break;
        if (it == IT_N)
            continue; /* DISTORTION, SIGMA_VSO, SIGMA_PTG: not used */
        if (n != items[it].count) {
            rc = nc_error(NC_ECONFIG, "%s:%d: %s: expected %d numbers before the label, found %d", path, lineno,
                          items[it].label, items[it].count, n);
            break;
        }
        seen[it] = lineno;
        double *dst[IT_N] = {NULL, NULL, out->scobj_km, out->cx, out->cy, out->cz, out->sz, out->k};
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
        for (int k = 0; k < items[it].count; k++)
            if (!isfinite(v[k])) {
                rc = nc_error(NC_ECONFIG, "%s:%d: %s: number %d is not finite", path, lineno, items[it].label, k + 1);
                break;
            }
        if (rc)
            break;
    }
    fclose(f);
    if (rc < 0)
        return rc;
    if (lineno < 2)
        return nc_error(NC_ECONFIG, "%s: %d lines: not a SUM file (picture name, UTC, then the geometry)", path,
                        lineno);
    for (int it = 0; it < IT_N; it++)
        if (!seen[it])
            return nc_error(NC_ECONFIG, "%s: no %s line (expected %d numbers followed by the label '%s')", path,
                            items[it].label, items[it].count, items[it].label);
    if (!(out->mmfl_mm > 0))
        return nc_error(NC_ECONFIG, "%s:%d: MMFL: the focal length must be > 0 mm, got %g", path, seen[IT_MMFL],
                        out->mmfl_mm);
    const double *ax[3] = {out->cx, out->cy, out->cz};
    static const char *const names[3] = {"CX", "CY", "CZ"};
    for (int a = 0; a < 3; a++) {
        if (fabs(dot(ax[a], ax[a]) - 1) > 2e-3)
            return nc_error(NC_ECONFIG, "%s:%d: %s: not a unit vector (length %.6g)", path, seen[IT_CX + a],
                            names[a], sqrt(dot(ax[a], ax[a])));
        for (int b = a + 1; b < 3; b++)
            if (fabs(dot(ax[a], ax[b])) > 1e-3)
                return nc_error(NC_ECONFIG, "%s:%d: %s and %s are not perpendicular (dot product %.6g)", path,
                                seen[IT_CX + b], names[a], names[b], dot(ax[a], ax[b]));
    }
    double cross[3] = {out->cx[1] * out->cy[2] - out->cx[2] * out->cy[1], out->cx[2] * out->cy[0] - out->cx[0] * out->cy[2],
                       out->cx[0] * out->cy[1] - out->cx[1] * out->cy[0]};
    if (dot(cross, out->cz) < 0)
        return nc_error(NC_ECONFIG, "%s:%d: CX, CY, CZ are left-handed (CX x CY = -CZ): not a rotation", path,
                        seen[IT_CZ]);
    if (!(dot(out->sz, out->sz) > 0))
        return nc_error(NC_ECONFIG, "%s:%d: SZ: the Sun direction is zero", path, seen[IT_SZ]);
    if (out->k[0] == 0 || out->k[4] == 0)
        return nc_error(NC_ECONFIG, "%s:%d: K-MATRIX: K11 and K22 (pixels/mm) must not be zero", path, seen[IT_K]);
    return 0;
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
