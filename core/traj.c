/* traj.c - reading trajectories (traj.h). */
#include "core/traj.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
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

/* The name of column c (0-based) of a layout's columns, into buf. */
static const char *col_name(const char *cols, int c, char *buf, size_t len)
{
    const char *p = cols;
    for (int i = 0; i < c && p; i++)
        p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL;
    if (!p)
        return "";
    snprintf(buf, len, "%.*s", (int)strcspn(p, ",["), p);
    return buf;
}

/* What is wrong with a data row (k numbers read into v, s where reading
 * stopped), naming the column: an error, or 0 if nothing. */
static int row_error(const char *path, size_t lineno, int sum, const double *v, int k, const char *s)
{
    const char *cols = sum ? sum_cols : pose_cols;
    const int need = sum ? 16 : 11;
    char name[32];
    s += strspn(s, " \t");
    const size_t tok = strcspn(s, ",\r\n");
    if (tok && k < need + 1)
        return nc_error(NC_ECONFIG, "%s:%zu: column %d (%s): '%.*s' is not a number%s", path, lineno, k + 1,
                        col_name(cols, k, name, sizeof name), (int)tok, s,
                        strchr(s, ';') ? " (columns are separated by commas)" : "");
    if (*s == ',' && k < need + 1)
        return nc_error(NC_ECONFIG, "%s:%zu: column %d (%s) is empty", path, lineno, k + 1,
                        col_name(cols, k, name, sizeof name));
    if (*s && *s != '\n' && *s != '\r')
        return nc_error(NC_ECONFIG, "%s:%zu: more than %d columns: %s", path, lineno, need + 1, cols);
    if (k < need)
        return nc_error(NC_ECONFIG, "%s:%zu: %d columns, expected %d or %d: %s", path, lineno, k, need, need + 1, cols);
    for (int i = 0; i < k; i++)
        if (!isfinite(v[i]))
            return nc_error(NC_ECONFIG, "%s:%zu: column %d (%s) is not finite", path, lineno, i + 1,
                            col_name(cols, i, name, sizeof name));
    if (k == need + 1 && v[need] != 0 && v[need] != 1)
        return nc_error(NC_ECONFIG, "%s:%zu: column %d (capture): %g, expected 0 or 1", path, lineno, need + 1,
                        v[need]);
    return 0;
}

/* Whether a header names the SUM-like layout: its first names t_s and
 * scobj_x_km, blanks around the comma and quotes around the names allowed. */
static int sum_header(const char *line)
{
    char c[32];
    size_t n = 0;
    for (const char *s = line; *s && n < sizeof c - 1; s++)
        if (!isspace((unsigned char)*s) && *s != '"')
            c[n++] = *s;
    c[n] = 0;
    return !strncmp(c, "t_s,scobj_x_km", 14);
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
    char line[2048];
    int rc = 0, sum = 0, header = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        if (line[strspn(line, " \t\r\n")] == '\0' || line[0] == '#')
            continue;
        const int need = sum ? 16 : 11;
        double v[17];
        int k = 0;
        char *s = line, *end;
        for (; k < need + 1; k++) {
            v[k] = strtod(s, &end);
            const char *after = end + strspn(end, " \t");
            if (end == s || (after == end && *after && !strchr(",\r\n", *after)))
                break; /* not a number, or one run into other characters: the field is reported whole */
            s = (char *)after;
            if (*s == ',')
                s++;
        }
        const char *f0 = line + strspn(line, " \t\"");
        if (k == 0 && n == 0 && !header && !(isdigit((unsigned char)*f0) || strchr("+-.,", *f0))) {
            header = 1; /* a header: which layout */
            sum = sum_header(line);
            continue;
        }
        if ((rc = row_error(path, lineno, sum, v, k, s)) < 0)
            break;
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            struct nc_traj_row *r2 = realloc(rows, cap * sizeof *rows);
            if (!r2) {
                rc = nc_error(-ENOMEM, "out of memory");
                break;
            }
            rows = r2;
        }
        struct nc_traj_row *r = &rows[n];
        r->t_s = v[0];
        r->capture = k == need + 1 ? v[need] != 0 : 1;
        r->line = (int)lineno;
        r->body_frame = 0;
        if (sum) {
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
        if (!(nc_v3_norm(r->sun) > 0)) {
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
