/* mesh.c - meshes from files: the OBJ loader, and the checks every format's mesh passes (PLY: mesh_ply.c; SPC's
 * ICQ: mesh_icq.c; the procedural asteroid: mesh_procedural.c). */
#include "render/mesh.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"
#include "core/lines.h"
#include "core/grow.h"

void nc_mesh_free(struct nc_mesh *m)
{
    free(m->v);
    free(m->tri);
    memset(m, 0, sizeof *m);
}

double nc_mesh_bounding_radius(const struct nc_mesh *m)
{
    double r2 = 0;
    for (size_t t = 0; t < 3 * m->nt; t++) {
        const double *p = m->v + 3 * (size_t)m->tri[t];
        double d = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        if (d > r2)
            r2 = d;
    }
    return sqrt(r2);
}

int nc_mesh_check_extent(struct nc_mesh *m, const char *what)
{
    for (size_t i = 0; i < m->nv; i++) {
        const double *p = m->v + 3 * i, r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        if (!(r <= NC_MESH_MAX_M * (1 + 1e-9))) { /* a globe of the largest radius, to its vertices' rounding */
            nc_mesh_free(m);
            return nc_error(NC_EMESH, "%s: vertex %zu (counted from 1) lies %g m from the origin, beyond %g m "
                            "(a wrong unit or scale?)", what, i + 1, r, NC_MESH_MAX_M);
        }
    }
    for (size_t t = 0; t < m->nt; t++)
        if (nc_mesh_face(m, t, NULL) > 0)
            return 0;
    nc_mesh_free(m);
    return nc_error(NC_EMESH, "%s: no triangle has an area (every face is degenerate)", what);
}

static const char *ext_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

int nc_mesh_load(const char *path, double scale_to_m, struct nc_mesh *out)
{
    const char *ext = ext_of(path);
    int rc = 0;
    if (strcasecmp(ext, "obj") == 0)
        rc = nc_mesh_load_obj(path, scale_to_m, out);
    else if (strcasecmp(ext, "ply") == 0)
        rc = nc_mesh_load_ply(path, scale_to_m, out);
    else if (strcasecmp(ext, "icq") == 0 || strcasecmp(ext, "txt") == 0) /* SPC's SHAPE.TXT */
        rc = nc_mesh_load_icq(path, scale_to_m, out);
    else
        return nc_error(NC_EMESH, "%s: unknown mesh format '.%s' (expected .obj, .ply, or .icq/.txt for SPC's ICQ)", path,
                    ext);
    if (rc < 0)
        return rc;
    if (out->nt == 0 || out->nv > UINT32_MAX || out->nt > UINT32_MAX / 3) {
        rc = out->nt ? nc_error(NC_EMESH, "%s: mesh too large (%zu vertices, %zu triangles)", path, out->nv, out->nt)
                     : nc_error(NC_EMESH, "%s: mesh has no triangles", path);
        nc_mesh_free(out);
        return rc;
    }
    return nc_mesh_check_extent(out, path);
}

/* ---- OBJ -------------------------------------------------------------- */

/* Parse one face corner "i", "i/t", "i//n" or "i/t/n" (whole numbers; a
 * negative i counts back from the last vertex so far); a '#' may follow. */
static int obj_index(const char **s, long *out)
{
    char *end;
    errno = 0;
    *out = strtol(*s, &end, 10);
    if (end == *s || errno)
        return -1;
    for (int part = 0; part < 2 && *end == '/'; part++) { /* t, n: each may be empty */
        const char *at = ++end;
        if (*at == '+' || *at == '-' || isdigit((unsigned char)*at)) {
            strtol(at, &end, 10);
            if (end == at)
                return -1;
        }
    }
    *s = end;
    return *end && *end != '#' && !isspace((unsigned char)*end) ? -1 : 0;
}

int nc_mesh_load_obj(const char *path, double scale, struct nc_mesh *out)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(-errno, "%s: cannot open mesh: %s", path, strerror(errno));
    struct nc_mesh m = {0};
    size_t vcap = 0, tcap = 0;
    struct nc_lines ln;
    nc_lines_init(&ln, f, path, NC_EMESH);
    int rc = 0;
    /* Faces may reference vertices defined later; check indices at the end
     * but remember the line of each face for the message. */
    size_t *face_line = NULL, flcap = 0;
    while ((rc = nc_lines_next(&ln)) > 0) {
        const size_t lineno = ln.no;
        const char *s = ln.line + strspn(ln.line, " \t\n\v\f\r");
        if (s[0] == 'v' && isspace((unsigned char)s[1])) {
            if (nc_grow((void **)&m.v, &vcap, 3 * (m.nv + 1), sizeof *m.v) < 0)
                goto nomem;
            char *end = (char *)s + 1;
            for (int k = 0; k < 3; k++) {
                const char *st = end;
                double d = strtod(st, &end);
                if (end == st) {
                    rc = nc_error(NC_EMESH, "%s:%zu: vertex needs 3 numbers", path, lineno);
                    goto out;
                }
                if (!isfinite(d)) {
                    rc = nc_error(NC_EMESH, "%s:%zu: vertex coordinate is not finite", path, lineno);
                    goto out;
                }
                m.v[3 * m.nv + k] = d * scale;
            }
            for (const char *st = end; *(st += strspn(st, " \t\r\n")) && *st != '#';) { /* numbers: w, a colour */
                char *e;
                strtod(st, &e);
                if (e == st) {
                    rc = nc_error(NC_EMESH, "%s:%zu: vertex: '%.*s' after x y z is not a number", path, lineno,
                                  (int)strcspn(st, " \t\r\n"), st);
                    goto out;
                }
                st = e;
            }
            m.nv++;
        } else if (s[0] == 'f' && isspace((unsigned char)s[1])) {
            s++;
            long idx[4];
            int n = 0;
            for (;;) {
                while (isspace((unsigned char)*s))
                    s++;
                if (!*s || *s == '#')
                    break;
                long v;
                const char *at = s;
                if (obj_index(&s, &v) < 0) {
                    rc = nc_error(NC_EMESH, "%s:%zu: bad face index '%.*s' (expected i, i/t, i//n or i/t/n)", path,
                                  lineno, (int)strcspn(at, " \t\r\n"), at);
                    goto out;
                }
                if (n < 4)
                    idx[n] = v;
                n++;
            }
            if (n != 3) {
                rc = nc_error(NC_EMESH, "%s:%zu: face with %d vertices; NavCam needs triangles (triangulate the mesh)",
                              path, lineno, n);
                goto out;
            }
            if (nc_grow((void **)&m.tri, &tcap, 3 * (m.nt + 1), sizeof *m.tri) < 0 ||
                nc_grow((void **)&face_line, &flcap, m.nt + 1, sizeof *face_line) < 0)
                goto nomem;
            for (int k = 0; k < 3; k++) {
                const long a = idx[k] < 0 ? (long)m.nv + idx[k] + 1 : idx[k]; /* relative: back from the last */
                if (a < 1 || a > (long)UINT32_MAX) {
                    rc = nc_error(NC_EMESH, "%s:%zu: face index %ld out of range (%zu vertices before it)", path,
                                  lineno, idx[k], m.nv);
                    goto out;
                }
                m.tri[3 * m.nt + k] = (uint32_t)(a - 1);
            }
            face_line[m.nt++] = lineno;
        }
        /* Comments, normals, texture coordinates, groups, materials: not needed. */
    }
    if (rc < 0)
        goto out;
    for (size_t t = 0; t < m.nt; t++)
        for (int k = 0; k < 3; k++)
            if (m.tri[3 * t + k] >= m.nv) {
                rc = nc_error(NC_EMESH, "%s:%zu: face index %u out of range (the file has %zu vertices)", path,
                              face_line[t], m.tri[3 * t + k] + 1, m.nv);
                goto out;
            }
    *out = m;
    m = (struct nc_mesh){0};
    goto out;
nomem:
    rc = nc_error(-ENOMEM, "%s: out of memory", path);
out:
    nc_lines_free(&ln);
    free(face_line);
    nc_mesh_free(&m);
    fclose(f);
    return rc;
}
