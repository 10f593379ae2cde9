/* star_cat.c - the star catalogue (stars.h): KStars' stars.dat read, the
 * index file written and loaded, and a star's direction at a date (proper
 * motion) as an observer in motion sees it (aberration). No renderer: the
 * file readers' fuzz target links this file alone. */
#include "render/stars.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/fs.h"
#include "core/le.h"
#include "core/lines.h"

#define MAS_RAD (M_PI / 180.0 / 3600.0 / 1000.0)
#define LIGHT_M_S 299792458.0

/* ---- KStars stars.dat ------------------------------------------------------ */

/* stars.dat's numbers: columns [a, b) (0-based) and the range each takes. */
static const struct {
    const char *name;
    int a, b;
    double lo, hi;
} cols[] = {
    {"RA hours", 0, 2, 0, 23},          {"RA minutes", 2, 4, 0, 59},      {"RA seconds", 4, 9, 0, 60},
    {"Dec degrees", 11, 13, 0, 90},     {"Dec minutes", 13, 15, 0, 59},   {"Dec seconds", 15, 19, 0, 60},
    {"pmRA (mas/yr)", 20, 29, -1e5, 1e5}, {"pmDec (mas/yr)", 29, 38, -1e5, 1e5}, {"V", 45, 51, -30, 30},
    {"B-V", 51, 56, -5, 10},
};
enum { NCOLS = sizeof cols / sizeof cols[0] };

/* The numbers of a row into v[NCOLS]: 0, or -1 with why[] saying which
 * column is not a decimal number in its range. */
static int row_fields(const char *line, double *v, char *why, size_t whylen)
{
    for (int i = 0; i < NCOLS; i++) {
        char buf[16], *end;
        const int a = cols[i].a, b = cols[i].b;
        if ((size_t)b > strcspn(line, "\r\n")) {
            snprintf(why, whylen, "the row ends before %s (columns %d-%d)", cols[i].name, a + 1, b);
            return -1;
        }
        memcpy(buf, line + a, (size_t)(b - a));
        buf[b - a] = 0;
        v[i] = strtod(buf, &end);
        const int decimal = strspn(buf, " +-.0123456789") == (size_t)(b - a);
        if (!decimal || end == buf || end[strspn(end, " ")] || !(v[i] >= cols[i].lo && v[i] <= cols[i].hi)) {
            snprintf(why, whylen, "%s (columns %d-%d) '%s' is not a number in %g..%g", cols[i].name, a + 1, b, buf,
                     cols[i].lo, cols[i].hi);
            return -1;
        }
    }
    return 0;
}

static int by_mag(const void *a, const void *b)
{
    const struct nc_star *x = a, *y = b;
    return (x->v_mag > y->v_mag) - (x->v_mag < y->v_mag);
}

int nc_star_cat_read_kstars(const char *path, struct nc_star_cat *c)
{
    memset(c, 0, sizeof *c);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    size_t cap = 0;
    struct nc_lines ln;
    nc_lines_init(&ln, f, path, NC_ECONFIG);
    int rc;
    while ((rc = nc_lines_next(&ln)) > 0) {
        const char *line = ln.line;
        const long no = (long)ln.no;
        if (line[0] == '#' || !line[strspn(line, " \t\r\n")])
            continue;
        /* RA hhmmss.ss (cols 1-9), Dec sddmmss.s (11-19), pmRA cos(dec)
         * (21-29) and pmDec (30-38) in mas/yr, V (46-51), B-V (52-56) */
        double v[NCOLS];
        char why[160];
        int bad = row_fields(line, v, why, sizeof why) < 0;
        if (!bad && line[10] != '+' && line[10] != '-')
            bad = snprintf(why, sizeof why, "the Dec's sign (column 11) is not + or -");
        else if (!bad && v[3] + v[4] / 60 + v[5] / 3600 > 90)
            bad = snprintf(why, sizeof why, "the Dec lies beyond 90 deg");
        if (bad) {
            rc = nc_error(NC_ECONFIG, "%s:%ld: %s: not a stars.dat row (RA hhmmss.ss, Dec sddmmss.s, pmRA, pmDec, "
                                     "parallax, V, B-V in fixed columns)",
                          path, no, why);
            break;
        }
        if (c->n == cap) {
            cap = cap ? 2 * cap : 1 << 17;
            struct nc_star *s = realloc(c->star, cap * sizeof *s);
            if (!s) {
                rc = nc_error(-ENOMEM, "out of memory");
                break;
            }
            c->star = s;
        }
        /* Seconds written as 60.00 (rounding) are converted, not refused. */
        double dec = (v[3] + v[4] / 60 + v[5] / 3600) * (line[10] == '-' ? -1 : 1);
        c->star[c->n++] = (struct nc_star){.ra_rad = (v[0] + v[1] / 60 + v[2] / 3600) * 15 * M_PI / 180,
                                           .dec_rad = dec * M_PI / 180, .pm_ra_mas_yr = (float)v[6],
                                           .pm_dec_mas_yr = (float)v[7], .v_mag = (float)v[8], .b_v = (float)v[9]};
    }
    nc_lines_free(&ln);
    fclose(f);
    if (rc == 0 && c->n == 0)
        rc = nc_error(NC_ECONFIG, "%s: no stars", path);
    if (rc < 0) {
        nc_star_cat_free(c);
        return rc;
    }
    qsort(c->star, c->n, sizeof *c->star, by_mag);
    c->epoch_jyear = 2000.0;
    return 0;
}

/* ---- NavCam's index: "NCSTARS1", u64 count, f64 epoch (Julian year), then
 * per star f64 ra, f64 dec (rad), f32 pm_ra cos(dec), f32 pm_dec (mas/yr),
 * f32 V, f32 B-V; little-endian, brightest first. ------------------------------ */

#define MAGIC "NCSTARS1"
#define RECORD 32
#define HEADER 24 /* magic, star count, epoch */

int nc_star_cat_write(const struct nc_star_cat *c, const char *path)
{
    size_t size = HEADER + c->n * RECORD;
    uint8_t *b = malloc(size);
    if (!b)
        return nc_error(-ENOMEM, "out of memory");
    memcpy(b, MAGIC, 8);
    nc_le_put_u64(b + 8, c->n);
    nc_le_put_f64(b + 16, c->epoch_jyear);
    for (size_t i = 0; i < c->n; i++) {
        uint8_t *p = b + HEADER + i * RECORD;
        const struct nc_star *s = &c->star[i];
        nc_le_put_f64(p, s->ra_rad);
        nc_le_put_f64(p + 8, s->dec_rad);
        nc_le_put_f32(p + 16, s->pm_ra_mas_yr);
        nc_le_put_f32(p + 20, s->pm_dec_mas_yr);
        nc_le_put_f32(p + 24, s->v_mag);
        nc_le_put_f32(p + 28, s->b_v);
    }
    /* under a temporary name, put in place once whole: a failed write leaves no partial index */
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%.4000s.%ld.tmp", path, (long)getpid());
    int rc = nc_fs_replaceable(path);
    FILE *f = rc < 0 ? NULL : fopen(tmp, "wb");
    if (rc == 0 && !f)
        rc = nc_error(-errno, "%s: cannot write the star index: %s", path, strerror(errno));
    if (f) {
        errno = 0;
        const int err = fwrite(b, 1, size, f) != size ? (errno ? errno : EIO) : 0;
        if (fclose(f) != 0 || err)
            rc = nc_error(-(err ? err : errno), "%s: cannot write the star index: %s", path,
                          strerror(err ? err : errno));
        if (rc == 0)
            rc = nc_commit_file(tmp, path);
        if (rc < 0)
            remove(tmp);
    }
    free(b);
    return rc;
}

int nc_star_cat_load(const char *path, struct nc_star_cat *c)
{
    memset(c, 0, sizeof *c);
    FILE *f = fopen(path, "rb");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    uint8_t h[HEADER];
    int rc = 0;
    if (fread(h, 1, HEADER, f) != HEADER || memcmp(h, MAGIC, 8))
        rc = nc_error(NC_ECONFIG, "%s: not a NavCam star index (write one with `navcam stars`)", path);
    uint64_t n = rc ? 0 : nc_le_get_u64(h + 8);
    if (rc == 0 && (n == 0 || n > 100000000))
        rc = nc_error(NC_ECONFIG, "%s: %llu stars", path, (unsigned long long)n);
    struct stat st; /* the size before the memory: a damaged count must not allocate gigabytes */
    if (rc == 0 && fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && (uint64_t)st.st_size < HEADER + n * RECORD)
        rc = nc_error(NC_ECONFIG, "%s: truncated (%llu stars announced, %llu bytes of them)", path,
                      (unsigned long long)n, (unsigned long long)(st.st_size - HEADER));
    uint8_t *b = rc ? NULL : malloc(n * RECORD);
    if (rc == 0 && (!b || !(c->star = malloc(n * sizeof *c->star))))
        rc = nc_error(-ENOMEM, "out of memory");
    if (rc == 0 && fread(b, RECORD, n, f) != n)
        rc = nc_error(NC_ECONFIG, "%s: truncated (%llu stars announced)", path, (unsigned long long)n);
    if (rc == 0 && fgetc(f) != EOF)
        rc = nc_error(NC_ECONFIG, "%s: bytes after the %llu stars the header announces", path, (unsigned long long)n);
    fclose(f);
    for (uint64_t i = 0; rc == 0 && i < n; i++) {
        const uint8_t *p = b + i * RECORD;
        struct nc_star *s = &c->star[i];
        *s = (struct nc_star){nc_le_get_f64(p), nc_le_get_f64(p + 8), nc_le_get_f32(p + 16), nc_le_get_f32(p + 20), nc_le_get_f32(p + 24), nc_le_get_f32(p + 28)};
        const char *bad = !isfinite(s->ra_rad)                ? "right ascension (rad) is not finite"
                          : !(fabs(s->dec_rad) <= M_PI / 2)     ? "declination (rad) is not within +-pi/2"
                          : !isfinite(s->pm_ra_mas_yr)          ? "proper motion in RA (mas/yr) is not finite"
                          : !isfinite(s->pm_dec_mas_yr)         ? "proper motion in Dec (mas/yr) is not finite"
                          : !isfinite(s->v_mag)                 ? "V magnitude is not finite"
                          : !isfinite(s->b_v)                   ? "B-V is not finite"
                          : i && s->v_mag < c->star[i - 1].v_mag ? "V magnitude is brighter than the star before"
                                                                  : NULL;
        if (bad)
            rc = nc_error(NC_ECONFIG, "%s: star %llu (from 0; byte %llu): %s (the stars are brightest first)", path,
                          (unsigned long long)i, (unsigned long long)(HEADER + i * RECORD), bad);
    }
    free(b);
    c->n = (size_t)n;
    c->epoch_jyear = rc ? 0 : nc_le_get_f64(h + 16);
    if (rc == 0 && !(c->epoch_jyear >= 1000 && c->epoch_jyear <= 3000)) /* Julian years: J1991.25 for Hipparcos */
        rc = nc_error(NC_ECONFIG, "%s: header: epoch J%g is not a catalogue epoch (1000 to 3000)", path,
                      c->epoch_jyear);
    if (rc < 0)
        nc_star_cat_free(c);
    return rc;
}

void nc_star_cat_free(struct nc_star_cat *c)
{
    free(c->star);
    memset(c, 0, sizeof *c);
}

size_t nc_star_cat_count_to(const struct nc_star_cat *c, double v_mag)
{
    const float lim = (float)v_mag; /* the catalogue's magnitudes are floats: 6.3 is 6.3000002 there */
    size_t lo = 0, hi = c->n;        /* first star fainter than lim */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (c->star[mid].v_mag <= lim)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* ---- directions --------------------------------------------------------------- */

struct nc_vec3 nc_star_direction(const struct nc_star *s, double epoch_jyear, double jyear)
{
    const double ca = cos(s->ra_rad), sa = sin(s->ra_rad), cd = cos(s->dec_rad), sd = sin(s->dec_rad);
    const double dt = jyear - epoch_jyear;
    /* east (increasing RA) and north unit vectors of the tangent plane */
    const struct nc_vec3 p = nc_v3(cd * ca, cd * sa, sd), e = nc_v3(-sa, ca, 0), nn = nc_v3(-sd * ca, -sd * sa, cd);
    const double de = s->pm_ra_mas_yr * MAS_RAD * dt, dn = s->pm_dec_mas_yr * MAS_RAD * dt;
    return nc_v3_unit(nc_v3_add(p, nc_v3_add(nc_v3_scale(e, de), nc_v3_scale(nn, dn))));
}

/* p' = (p / gamma + (1 + p.V / (1 + 1 / gamma)) V) / (1 + p.V), V = v / c
 * (the Explanatory Supplement to the Astronomical Almanac, 1992, eq. 3.252-3). */
struct nc_vec3 nc_aberrate(struct nc_vec3 p, struct nc_vec3 v_m_s)
{
    const struct nc_vec3 V = nc_v3_scale(v_m_s, 1.0 / LIGHT_M_S);
    const double v2 = nc_v3_dot(V, V), ig = sqrt(1 - v2), pv = nc_v3_dot(p, V);
    struct nc_vec3 q = nc_v3_add(nc_v3_scale(p, ig), nc_v3_scale(V, 1 + pv / (1 + ig)));
    return nc_v3_unit(nc_v3_scale(q, 1 / (1 + pv)));
}
