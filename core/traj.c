/* traj.c - reading trajectories (traj.h). */
#include "core/traj.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"
#include "core/lines.h"
#include "navcam/protocol.h"
#include "core/pose.h"
#include "core/sumfile.h"

/* The built-in approach to the default scene's asteroid (as `make demo`):
 * 8 poses, 16 km to 3 km, one per second, looking at the body. */
static int builtin_approach(struct nc_traj_row **out)
{
    const int n = 8;
    struct nc_traj_row *r = calloc(n, sizeof *r);
    if (!r)
        return nc_error(-ENOMEM, "out of memory");
    for (int i = 0; i < n; i++) {
        double d = 16000 * exp(log(3000.0 / 16000) * i / (n - 1));
        r[i].t_s = i;
        r[i].p = nc_v3(0.08 * d, -d, 0.03 * d);
        nc_quat_look_at(r[i].p, nc_v3(0, 0, 0), nc_v3(0, 0, 1), &r[i].q);
        r[i].sun = nc_v3(0.643, -0.766, 0);
        r[i].capture = 1;
    }
    *out = r;
    return n;
}

static const char pose_cols[] = "t_s,cam_x_m,cam_y_m,cam_z_m,q_w,q_x,q_y,q_z,sun_x,sun_y,sun_z[,capture]";
static const char sum_cols[] = "t_s,scobj_x_km,scobj_y_km,scobj_z_km,cx_x,cx_y,cx_z,cy_x,cy_y,cy_z,cz_x,cz_y,cz_z,"
                               "sz_x,sz_y,sz_z[,capture]";

/* A SUM-like row: v[1..3] SCOBJ km, v[4..12] CX CY CZ, v[13..15] SZ. */
static int sum_row(const char *path, size_t lineno, const double *v, struct nc_traj_row *r)
{
    const double *ax[3] = {v + 4, v + 7, v + 10};
    int item;
    if (nc_sumfile_rotation(ax, &r->q, &item) < 0) {
        char why[256];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_error(NC_ECONFIG, "%s:%zu: %s", path, lineno, why);
    }
    r->p = nc_v3(-1e3 * v[1], -1e3 * v[2], -1e3 * v[3]);
    r->sun = nc_v3(v[13], v[14], v[15]);
    r->body_frame = 1;
    return 0;
}

/* How a file's columns map to a layout's: names[i] the name of the file's
 * column i, map[i] the layout's column it holds (its index in cols);
 * columns min..max per row (a header that names the columns fixes both);
 * the capture column's place in the layout is need. */
struct layout {
    int sum, need, min, max;
    int map[18];
    char names[18][24];
};

/* The name of column c (0-based) of a layout's columns, into buf. */
static const char *col_name(const char *cols, int c, char *buf, size_t len)
{
    const char *p = cols;
    for (int i = 0; i < c && p; i++)
        p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL;
    if (!p)
        return "";
    snprintf(buf, len, "%.*s", (int)strcspn(p, ",[]"), p);
    return buf;
}

/* The columns in the layout's own order: sum (1) or pose rows (0). */
static void layout_positional(int sum, struct layout *l)
{
    l->sum = sum;
    l->need = sum ? 16 : 11;
    l->min = l->need;
    l->max = l->need + 1;
    for (int i = 0; i < l->max; i++) {
        l->map[i] = i;
        col_name(sum ? sum_cols : pose_cols, i, l->names[i], sizeof l->names[i]);
    }
}

/* The index of name among a layout's columns (case aside), or -1. */
static int layout_index(int sum, const char *name)
{
    char buf[24];
    for (int i = 0; i < (sum ? 17 : 12); i++)
        if (!strcasecmp(name, col_name(sum ? sum_cols : pose_cols, i, buf, sizeof buf)))
            return i;
    return -1;
}

/* The layout a header line gives (traj.h): its names, split at commas or
 * blanks, quotes dropped, case aside. Columns go by place when no name is
 * the layout's (a header of other names), or when every name is the
 * layout's at its own place (all of them, or the first ones); by name when
 * the names are the layout's own, each once, with every column but
 * capture; otherwise (the layout's names mixed with others, or out of place
 * with some left out) the header is an error naming the first name that
 * does not fit: a header that names some columns as NavCam does and others
 * not (qx for q_x) is a mistake read either way. */
static int layout_header(const char *path, size_t lineno, const char *line, struct layout *l)
{
    char names[18][24];
    int n = 0;
    for (const char *s = line; *s && *s != '\n' && *s != '\r';) {
        s += strspn(s, " \t\",");
        const size_t len = strcspn(s, " \t\",\r\n");
        if (!len)
            continue;
        if (n == 18)
            return nc_error(NC_ECONFIG, "%s:%zu: the header names more than 17 columns", path, lineno);
        snprintf(names[n++], sizeof names[0], "%.*s", (int)(len < 23 ? len : 23), s);
        s += len;
    }
    int sum = 0, known = 0, placed = 1;
    for (int i = 0; i < n; i++)
        sum |= layout_index(0, names[i]) < 0 && layout_index(1, names[i]) >= 0;
    layout_positional(sum, l);
    int seen[18] = {0};
    for (int i = 0; i < n; i++) {
        const int c = layout_index(sum, names[i]);
        if (c < 0)
            continue;
        if (seen[c]++)
            return nc_error(NC_ECONFIG, "%s:%zu: the header names %s twice", path, lineno, names[i]);
        known++;
        placed &= c == i;
    }
    if (!known || (placed && known == n))
        return 0;
    const char *cols = sum ? sum_cols : pose_cols;
    for (int i = 0; i < n; i++)
        if (layout_index(sum, names[i]) < 0)
            return nc_error(NC_ECONFIG,
                            "%s:%zu: header column %d, '%s', is not a column of the layout %s; name every column "
                            "from it (in any order) to have them taken by name, or none",
                            path, lineno, i + 1, names[i], cols);
    for (int c = 0; c < l->need; c++)
        if (!seen[c])
            return nc_error(NC_ECONFIG,
                            "%s:%zu: the header names its columns in another order than %s but leaves out %s: "
                            "name every column to have them taken by name",
                            path, lineno, cols, l->names[c]);
    l->min = l->max = n;
    for (int i = 0; i < n; i++) {
        l->map[i] = layout_index(sum, names[i]);
        memcpy(l->names[i], names[i], sizeof names[i]);
    }
    return 0;
}

/* What is wrong with a data row (k numbers read into v, in the file's
 * order; s where reading stopped), naming the column: an error, or 0 if
 * nothing. */
static int row_error(const char *path, size_t lineno, const struct layout *l, const double *v, int k, const char *s)
{
    const char *cols = l->sum ? sum_cols : pose_cols;
    s += strspn(s, " \t");
    const size_t tok = strcspn(s, ",\r\n");
    if (tok && k < l->max)
        return nc_error(NC_ECONFIG, "%s:%zu: column %d (%s): '%.*s' is not a number%s", path, lineno, k + 1,
                        l->names[k], (int)tok, s, strchr(s, ';') ? " (columns are separated by commas)" : "");
    if (*s == ',' && k < l->max)
        return nc_error(NC_ECONFIG, "%s:%zu: column %d (%s) is empty", path, lineno, k + 1, l->names[k]);
    if (*s && *s != '\n' && *s != '\r')
        return l->min == l->max
                   ? nc_error(NC_ECONFIG, "%s:%zu: more than %d columns, the %d the header names", path, lineno,
                              l->max, l->max)
                   : nc_error(NC_ECONFIG, "%s:%zu: more than %d columns: %s", path, lineno, l->max, cols);
    if (k < l->min)
        return l->min == l->max
                   ? nc_error(NC_ECONFIG, "%s:%zu: %d columns, expected %d as the header names", path, lineno, k,
                              l->max)
                   : nc_error(NC_ECONFIG, "%s:%zu: %d columns, expected %d or %d: %s", path, lineno, k, l->min,
                              l->max, cols);
    for (int i = 0; i < k; i++) {
        if (!isfinite(v[i]))
            return nc_error(NC_ECONFIG, "%s:%zu: column %d (%s) is not finite", path, lineno, i + 1, l->names[i]);
        if (l->map[i] == l->need && v[i] != 0 && v[i] != 1)
            return nc_error(NC_ECONFIG, "%s:%zu: column %d (capture): %g, expected 0 or 1", path, lineno, i + 1,
                            v[i]);
    }
    return 0;
}

int nc_traj_read(const char *path, struct nc_traj_row **out)
{
    if (!strcmp(path, "builtin:approach"))
        return builtin_approach(out);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    struct nc_traj_row *rows = NULL;
    size_t n = 0, cap = 0, lineno = 0;
    struct nc_lines ln;
    nc_lines_init(&ln, f, path, NC_ECONFIG);
    int rc, header = 0;
    struct layout l;
    layout_positional(0, &l);
    while ((rc = nc_lines_next(&ln)) > 0) {
        char *line = ln.line;
        lineno = ln.no;
        line[strcspn(line, "#")] = '\0'; /* a comment: from '#' to the line's end */
        if (line[strspn(line, " \t\r\n")] == '\0')
            continue;
        double raw[18], v[17];
        int k = 0;
        char *s = line, *end;
        for (; k < l.max; k++) {
            raw[k] = nc_strtod_decimal(s, &end);
            const char *after = end + strspn(end, " \t");
            if (end == s || (after == end && *after && !strchr(",\r\n", *after)))
                break; /* not a decimal number (hexadecimal, inf, nan), or one run into other characters: the field
                        * is reported whole */
            s = (char *)after;
            if (*s == ',')
                s++;
        }
        const char *f0 = line + strspn(line, " \t\"");
        if (k == 0 && n == 0 && !header && !(isdigit((unsigned char)*f0) || strchr("+-.,", *f0))) {
            header = 1; /* a header: which layout, and the columns by name or by place */
            if ((rc = layout_header(path, lineno, line, &l)) < 0)
                break;
            continue;
        }
        if ((rc = row_error(path, lineno, &l, raw, k, s)) < 0)
            break;
        v[l.need] = 1; /* capture, unless given */
        for (int i = 0; i < k; i++)
            v[l.map[i]] = raw[i];
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            struct nc_traj_row *r2 = realloc(rows, cap * sizeof *rows);
            if (!r2) {
                rc = nc_error(-ENOMEM, "out of memory");
                break;
            }
            rows = r2;
        }
        if (!(fabs(v[0]) <= NC_PROTO_TIME_MAX_NS * 1e-9)) {
            rc = nc_error(NC_ECONFIG, "%s:%zu: t_s %g s is beyond +-%g s (about 146 years: a simulation time in "
                          "ns fits 64 bits)", path, lineno, v[0], NC_PROTO_TIME_MAX_NS * 1e-9);
            break;
        }
        struct nc_traj_row *r = &rows[n];
        r->t_s = v[0];
        r->capture = v[l.need] != 0;
        r->line = (int)lineno;
        r->body_frame = 0;
        if (l.sum) {
            if ((rc = sum_row(path, lineno, v, r)) < 0)
                break;
        } else {
            r->p = nc_v3(v[1], v[2], v[3]);
            r->q = (struct nc_quat){v[4], v[5], v[6], v[7]};
            r->sun = nc_v3(v[8], v[9], v[10]);
            double qn = nc_quat_norm(r->q);
            if (fabs(qn - 1) > 1e-3) {
                rc = nc_error(NC_ECONFIG, "%s:%zu: the quaternion [%g, %g, %g, %g] is not unit (norm %.6g)", path,
                              lineno, v[4], v[5], v[6], v[7], qn);
                break;
            }
            r->q = (struct nc_quat){r->q.w / qn, r->q.x / qn, r->q.y / qn, r->q.z / qn};
        }
        if (nc_v3_is_zero(r->sun)) {
            rc = nc_error(NC_ECONFIG, "%s:%zu: the Sun direction is zero", path, lineno);
            break;
        }
        if (!(nc_v3_norm(r->p) <= NC_CAMERA_MAX_M)) {
            rc = nc_error(NC_ECONFIG, "%s:%zu: the camera lies %g m from the scene's origin, beyond %g m", path,
                          lineno, nc_v3_norm(r->p), NC_CAMERA_MAX_M);
            break;
        }
        n++;
    }
    nc_lines_free(&ln);
    fclose(f);
    if (rc < 0) {
        free(rows);
        return rc;
    }
    if (n > 100000000 || n == 0) {
        free(rows);
        return n ? nc_error(NC_ERANGE, "%s: %zu rows: more than 10^8", path, n)
                 : nc_error(NC_ECONFIG, "%s: no poses (%zu lines: blank, comments or a header)", path, lineno);
    }
    *out = rows;
    return (int)n;
}
