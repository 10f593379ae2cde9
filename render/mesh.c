/* mesh.c - OBJ and PLY loaders (the procedural asteroid: mesh_procedural.c). */
#include "render/mesh.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/lines.h"
#include "core/grow.h"

void nc_mesh_free(struct nc_mesh *m)
{
    free(m->v);
    free(m->tri);
    memset(m, 0, sizeof *m);
}

static int check_mesh(const char *path, const struct nc_mesh *m)
{
    if (m->nt == 0)
        return nc_error(NC_EMESH, "%s: mesh has no triangles", path);
    if (m->nv > UINT32_MAX || m->nt > UINT32_MAX / 3)
        return nc_error(NC_EMESH, "%s: mesh too large (%zu vertices, %zu triangles)", path, m->nv, m->nt);
    return 0;
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
        if (!(r <= NC_MESH_MAX_M)) {
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
    return rc < 0 ? rc : nc_mesh_check_extent(out, path);
}

/* ---- OBJ -------------------------------------------------------------- */

/* Parse one face corner "i", "i/t", "i//n" or "i/t/n" (whole numbers; a
 * negative i counts back from the last vertex so far). */
static int obj_index(const char **s, long *out)
{
    char *end;
    errno = 0;
    *out = strtol(*s, &end, 10);
    if (end == *s || errno || (*end && *end != '/' && !isspace((unsigned char)*end)))
        return -1;
    end += strspn(end, "/+-0123456789");
    *s = end;
    return *end && !isspace((unsigned char)*end) ? -1 : 0;
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
    if ((rc = check_mesh(path, &m)) < 0)
        goto out;
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

/* ---- PLY -------------------------------------------------------------- */

enum ply_type { PLY_NONE, PLY_I8, PLY_U8, PLY_I16, PLY_U16, PLY_I32, PLY_U32, PLY_F32, PLY_F64 };

static enum ply_type ply_type_of(const char *s)
{
    static const struct { const char *name; enum ply_type t; } map[] = {
        {"char", PLY_I8}, {"int8", PLY_I8}, {"uchar", PLY_U8}, {"uint8", PLY_U8},
        {"short", PLY_I16}, {"int16", PLY_I16}, {"ushort", PLY_U16}, {"uint16", PLY_U16},
        {"int", PLY_I32}, {"int32", PLY_I32}, {"uint", PLY_U32}, {"uint32", PLY_U32},
        {"float", PLY_F32}, {"float32", PLY_F32}, {"double", PLY_F64}, {"float64", PLY_F64},
    };
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (strcmp(map[i].name, s) == 0)
            return map[i].t;
    return PLY_NONE;
}

static size_t ply_size(enum ply_type t)
{
    static const size_t sz[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return sz[t];
}

struct ply_prop {
    char name[64];
    enum ply_type type, count_type; /* count_type != NONE: a list */
};

struct ply_elem {
    char name[64];
    size_t count;
    struct ply_prop prop[32];
    int nprop;
};

enum ply_format { PLY_ASCII, PLY_LE, PLY_BE };

struct ply_reader {
    FILE *f;
    const char *path;
    enum ply_format fmt;
    struct nc_lines ln; /* the header's lines, and an ASCII body's */
    char *cur;          /* ASCII: cursor in ln.line */
};

/* Read one number of type t; ASCII reads the next token (continuing lines). */
static int ply_read(struct ply_reader *r, enum ply_type t, double *out)
{
    if (r->fmt == PLY_ASCII) {
        for (;;) {
            while (r->cur && isspace((unsigned char)*r->cur))
                r->cur++;
            if (r->cur && *r->cur)
                break;
            const int got = nc_lines_next(&r->ln);
            if (got <= 0)
                return got < 0 ? got : nc_error(NC_EMESH, "%s:%zu: unexpected end of file", r->path, r->ln.no);
            r->cur = r->ln.line;
        }
        char *end;
        *out = strtod(r->cur, &end);
        if (end == r->cur)
            return nc_error(NC_EMESH, "%s:%zu: expected a number", r->path, r->ln.no);
        r->cur = end;
        return 0;
    }
    unsigned char b[8];
    size_t n = ply_size(t);
    if (fread(b, 1, n, r->f) != n)
        return nc_error(NC_EMESH, "%s: unexpected end of binary data", r->path);
    int host_le = 1;
    host_le = *(unsigned char *)&host_le;
    if ((r->fmt == PLY_LE) != host_le)
        for (size_t i = 0; i < n / 2; i++) {
            unsigned char c = b[i];
            b[i] = b[n - 1 - i];
            b[n - 1 - i] = c;
        }
    union { int8_t i8; uint8_t u8; int16_t i16; uint16_t u16; int32_t i32; uint32_t u32; float f; double d; } u;
    memcpy(&u, b, n);
    switch (t) {
    case PLY_I8: *out = u.i8; break;
    case PLY_U8: *out = u.u8; break;
    case PLY_I16: *out = u.i16; break;
    case PLY_U16: *out = u.u16; break;
    case PLY_I32: *out = u.i32; break;
    case PLY_U32: *out = u.u32; break;
    case PLY_F32: *out = u.f; break;
    default: *out = u.d; break;
    }
    return 0;
}

static int ply_header(struct ply_reader *r, struct ply_elem *el, int *nel)
{
    int rc = 0, seen_format = 0;
    *nel = 0;
    for (;;) {
        if ((rc = nc_lines_next(&r->ln)) <= 0) {
            rc = rc < 0 ? rc : nc_error(NC_EMESH, "%s: PLY header has no end_header", r->path);
            break;
        }
        char *line = r->ln.line;
        line[strcspn(line, "\r\n")] = '\0';
        char a[64] = "", b[64] = "", c[64] = "", d[64] = "", e[64] = "";
        int n = sscanf(line, "%63s %63s %63s %63s %63s", a, b, c, d, e);
        if (r->ln.no == 1) {
            if (strcmp(a, "ply") != 0) {
                rc = nc_error(NC_EMESH, "%s:1: not a PLY file (no 'ply' magic)", r->path);
                break;
            }
            continue;
        }
        if (n <= 0 || strcmp(a, "comment") == 0 || strcmp(a, "obj_info") == 0)
            continue;
        if (strcmp(a, "format") == 0) {
            seen_format = 1;
            if (strcmp(b, "ascii") == 0)
                r->fmt = PLY_ASCII;
            else if (strcmp(b, "binary_little_endian") == 0)
                r->fmt = PLY_LE;
            else if (strcmp(b, "binary_big_endian") == 0)
                r->fmt = PLY_BE;
            else {
                rc = nc_error(NC_EMESH, "%s:%zu: unknown PLY format '%s'", r->path, r->ln.no, b);
                break;
            }
        } else if (strcmp(a, "element") == 0 && n == 3) {
            if (*nel == 16) {
                rc = nc_error(NC_EMESH, "%s:%zu: too many PLY elements", r->path, r->ln.no);
                break;
            }
            struct ply_elem *x = &el[(*nel)++];
            memset(x, 0, sizeof *x);
            snprintf(x->name, sizeof x->name, "%s", b);
            char *end;
            errno = 0;
            unsigned long long cnt = strtoull(c, &end, 10);
            if (*end || errno || cnt > (1ull << 32)) {
                rc = nc_error(NC_EMESH, "%s:%zu: bad element count '%s'", r->path, r->ln.no, c);
                break;
            }
            x->count = (size_t)cnt;
        } else if (strcmp(a, "property") == 0 && *nel > 0) {
            struct ply_elem *x = &el[*nel - 1];
            if (x->nprop == 32) {
                rc = nc_error(NC_EMESH, "%s:%zu: too many properties", r->path, r->ln.no);
                break;
            }
            struct ply_prop *p = &x->prop[x->nprop++];
            if (strcmp(b, "list") == 0 && n == 5) {
                p->count_type = ply_type_of(c);
                p->type = ply_type_of(d);
                snprintf(p->name, sizeof p->name, "%s", e);
                if (!p->count_type || !p->type) {
                    rc = nc_error(NC_EMESH, "%s:%zu: unknown property type", r->path, r->ln.no);
                    break;
                }
            } else if (n == 3) {
                p->type = ply_type_of(b);
                p->count_type = PLY_NONE;
                snprintf(p->name, sizeof p->name, "%s", c);
                if (!p->type) {
                    rc = nc_error(NC_EMESH, "%s:%zu: unknown property type '%s'", r->path, r->ln.no, b);
                    break;
                }
            } else {
                rc = nc_error(NC_EMESH, "%s:%zu: malformed property line", r->path, r->ln.no);
                break;
            }
        } else if (strcmp(a, "end_header") == 0) {
            if (!seen_format)
                rc = nc_error(NC_EMESH, "%s: PLY header has no format line", r->path);
            break;
        } else {
            rc = nc_error(NC_EMESH, "%s:%zu: unexpected PLY header line '%s'", r->path, r->ln.no, line);
            break;
        }
    }
    return rc < 0 ? rc : 0;
}

int nc_mesh_load_ply(const char *path, double scale, struct nc_mesh *out)
{
    memset(out, 0, sizeof *out);
    struct ply_reader r = {.path = path, .f = fopen(path, "rb")};
    if (!r.f)
        return nc_error(-errno, "%s: cannot open mesh: %s", path, strerror(errno));
    nc_lines_init(&r.ln, r.f, path, NC_EMESH);
    struct ply_elem el[16];
    int nel = 0, rc;
    struct nc_mesh m = {0};
    if ((rc = ply_header(&r, el, &nel)) < 0)
        goto out;
    struct stat st;
    long at = ftell(r.f);
    size_t announced = 0;
    for (int e = 0; e < nel; e++)
        announced += el[e].count;
    if (fstat(fileno(r.f), &st) == 0 && at >= 0 && announced > (size_t)(st.st_size - at)) { /* a byte each, at least */
        rc = nc_error(NC_EMESH, "%s: the header announces %zu elements, more than the %lld bytes after it hold", path,
                      announced, (long long)(st.st_size - at));
        goto out;
    }
    int have_v = 0, have_f = 0;
    for (int e = 0; e < nel; e++) {
        struct ply_elem *x = &el[e];
        int is_v = strcmp(x->name, "vertex") == 0, is_f = strcmp(x->name, "face") == 0;
        int ix = -1, iy = -1, iz = -1, ilist = -1;
        for (int p = 0; p < x->nprop; p++) {
            const char *nm = x->prop[p].name;
            if (is_v && !x->prop[p].count_type) {
                if (!strcmp(nm, "x")) ix = p;
                if (!strcmp(nm, "y")) iy = p;
                if (!strcmp(nm, "z")) iz = p;
            }
            if (is_f && x->prop[p].count_type && (!strcmp(nm, "vertex_indices") || !strcmp(nm, "vertex_index")))
                ilist = p;
        }
        if (is_v && (ix < 0 || iy < 0 || iz < 0)) {
            rc = nc_error(NC_EMESH, "%s: PLY vertex element lacks x, y or z", path);
            goto out;
        }
        if (is_f && ilist < 0) {
            rc = nc_error(NC_EMESH, "%s: PLY face element lacks vertex_indices", path);
            goto out;
        }
        if (is_v) {
            have_v = 1;
            m.nv = x->count;
            if (!(m.v = malloc((x->count ? x->count : 1) * 3 * sizeof *m.v)))
                goto nomem;
        }
        if (is_f) {
            have_f = 1;
            m.nt = x->count;
            if (!(m.tri = malloc((x->count ? x->count : 1) * 3 * sizeof *m.tri)))
                goto nomem;
        }
        for (size_t i = 0; i < x->count; i++) {
            for (int p = 0; p < x->nprop; p++) {
                struct ply_prop *pr = &x->prop[p];
                double val;
                if (!pr->count_type) {
                    if ((rc = ply_read(&r, pr->type, &val)) < 0)
                        goto out;
                    if (is_v && (p == ix || p == iy || p == iz)) {
                        if (!isfinite(val)) {
                            rc = nc_error(NC_EMESH, "%s: vertex %zu has a non-finite coordinate", path, i);
                            goto out;
                        }
                        m.v[3 * i + (p == ix ? 0 : p == iy ? 1 : 2)] = val * scale;
                    }
                    continue;
                }
                double cnt;
                if ((rc = ply_read(&r, pr->count_type, &cnt)) < 0)
                    goto out;
                if (is_f && p == ilist && cnt != 3) {
                    rc = nc_error(NC_EMESH, "%s: face %zu has %g vertices; NavCam needs triangles (triangulate the mesh)",
                                  path, i, cnt);
                    goto out;
                }
                if (cnt < 0 || cnt > 1e6) {
                    rc = nc_error(NC_EMESH, "%s: bad list length %g", path, cnt);
                    goto out;
                }
                for (long k = 0; k < (long)cnt; k++) {
                    if ((rc = ply_read(&r, pr->type, &val)) < 0)
                        goto out;
                    if (is_f && p == ilist) {
                        if (!have_v || val < 0 || val >= (double)m.nv || val != floor(val)) {
                            rc = nc_error(NC_EMESH, "%s: face %zu index %g out of range (%zu vertices)", path, i,
                                          val, m.nv);
                            goto out;
                        }
                        m.tri[3 * i + k] = (uint32_t)val;
                    }
                }
            }
        }
    }
    if (!have_v || !have_f) {
        rc = nc_error(NC_EMESH, "%s: PLY has no %s element", path, have_v ? "face" : "vertex");
        goto out;
    }
    if ((rc = check_mesh(path, &m)) < 0)
        goto out;
    *out = m;
    m = (struct nc_mesh){0};
    goto out;
nomem:
    rc = nc_error(-ENOMEM, "%s: out of memory", path);
out:
    nc_lines_free(&r.ln);
    nc_mesh_free(&m);
    fclose(r.f);
    return rc;
}
