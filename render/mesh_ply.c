/* mesh_ply.c - the PLY loader (mesh.h): ASCII, binary little and big endian;
 * the vertex element's x, y, z and the face element's vertex_indices (or
 * vertex_index) lists of three, every other element and property read past.
 * An ASCII file holds one element a line, as the format says, so that a
 * missing or extra value is an error at its line, not a shift of every
 * value after it; data past the elements the header announces is an error
 * too (a header that undercounts would otherwise drop the rest unseen). */
#include "render/mesh.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/lines.h"

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
    const struct ply_elem *el; /* the element being read: el->name, its index i, from ASCII line `line` */
    size_t i, line;
    char at[4200]; /* where() writes "PATH:LINE: vertex 3" here, for an error */
};

/* Where the element being read is, for an error message (formatted only then: a mesh has millions). */
static const char *where(struct ply_reader *r)
{
    if (r->fmt == PLY_ASCII)
        snprintf(r->at, sizeof r->at, "%.4000s:%zu: %.63s %zu", r->path, r->line, r->el->name, r->i);
    else
        snprintf(r->at, sizeof r->at, "%.4000s: %.63s %zu (counted from 0)", r->path, r->el->name, r->i);
    return r->at;
}

/* The next element (ASCII: the next line that is not blank), named in errors by where(). */
static int ply_begin(struct ply_reader *r, const struct ply_elem *x, size_t i)
{
    if (r->fmt == PLY_ASCII) {
        for (;;) {
            const int got = nc_lines_next(&r->ln);
            if (got < 0)
                return got;
            if (got == 0)
                return nc_error(NC_EMESH, "%s:%zu: the file ends at %s %zu (counted from 0) of the %zu the header "
                                "announces", r->path, r->ln.no, x->name, i, x->count);
            r->cur = r->ln.line + strspn(r->ln.line, " \t\r\n");
            if (*r->cur)
                break;
        }
    }
    r->el = x, r->i = i, r->line = r->ln.no;
    return 0;
}

/* The element's line holds no more values (ASCII). */
static int ply_end(struct ply_reader *r)
{
    if (r->fmt == PLY_ASCII && r->cur[strspn(r->cur, " \t\r\n")])
        return nc_error(NC_EMESH, "%s: more values on the line than its properties take ('%.*s')", where(r),
                        (int)strcspn(r->cur + strspn(r->cur, " \t"), "\r\n"), r->cur + strspn(r->cur, " \t"));
    return 0;
}

/* Read one number of type t, ASCII from the element's own line. */
static int ply_read(struct ply_reader *r, enum ply_type t, double *out)
{
    if (r->fmt == PLY_ASCII) {
        r->cur += strspn(r->cur, " \t");
        if (!*r->cur || *r->cur == '\r' || *r->cur == '\n')
            return nc_error(NC_EMESH, "%s: the line ends before its properties do", where(r));
        char *end;
        *out = strtod(r->cur, &end);
        if (end == r->cur || (*end && !isspace((unsigned char)*end)))
            return nc_error(NC_EMESH, "%s: '%.*s' is not a number", where(r), (int)strcspn(r->cur, " \t\r\n"), r->cur);
        r->cur = end;
        return 0;
    }
    unsigned char b[8];
    size_t n = ply_size(t);
    if (fread(b, 1, n, r->f) != n)
        return nc_error(NC_EMESH, "%s: unexpected end of binary data", where(r));
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

/* The least the body can hold: binary, each property's bytes (a list's
 * count at least); ASCII, two bytes a value ("0 "), the last one's end of
 * line left out. */
static size_t ply_min_bytes(const struct ply_elem *el, int nel, enum ply_format fmt)
{
    size_t n = 0;
    for (int e = 0; e < nel; e++) {
        size_t each = 0;
        for (int p = 0; p < el[e].nprop; p++) {
            const struct ply_prop *pr = &el[e].prop[p];
            each += fmt == PLY_ASCII ? 2 : ply_size(pr->count_type ? pr->count_type : pr->type);
        }
        n += el[e].count * (each ? each : 1);
    }
    return fmt == PLY_ASCII && n ? n - 1 : n;
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
    const long at = ftell(r.f);
    const size_t least = ply_min_bytes(el, nel, r.fmt);
    if (fstat(fileno(r.f), &st) == 0 && at >= 0 && least > (size_t)(st.st_size - at)) {
        rc = nc_error(NC_EMESH, "%s: the header announces elements of at least %zu bytes, more than the %lld bytes "
                      "after it hold", path, least, (long long)(st.st_size - at));
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
        if ((is_v && have_v) || (is_f && have_f)) {
            rc = nc_error(NC_EMESH, "%s: the PLY header declares a second %s element", path, x->name);
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
            if ((rc = ply_begin(&r, x, i)) < 0)
                goto out;
            for (int p = 0; p < x->nprop; p++) {
                struct ply_prop *pr = &x->prop[p];
                double val;
                if (!pr->count_type) {
                    if ((rc = ply_read(&r, pr->type, &val)) < 0)
                        goto out;
                    if (is_v && (p == ix || p == iy || p == iz)) {
                        if (!isfinite(val)) {
                            rc = nc_error(NC_EMESH, "%s: a coordinate is not finite", where(&r));
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
                    rc = nc_error(NC_EMESH, "%s: a face of %g vertices; NavCam needs triangles (triangulate the mesh)",
                                  where(&r), cnt);
                    goto out;
                }
                if (!(cnt >= 0 && cnt <= 1e6) || cnt != floor(cnt)) {
                    rc = nc_error(NC_EMESH, "%s: bad list length %g", where(&r), cnt);
                    goto out;
                }
                for (long k = 0; k < (long)cnt; k++) {
                    if ((rc = ply_read(&r, pr->type, &val)) < 0)
                        goto out;
                    if (is_f && p == ilist) {
                        if (!have_v) {
                            rc = nc_error(NC_EMESH, "%s: a face before the vertex element: NavCam reads PLY files "
                                          "with the vertices first", where(&r));
                            goto out;
                        }
                        if (val < 0 || val >= (double)m.nv || val != floor(val)) {
                            rc = nc_error(NC_EMESH, "%s: vertex index %g out of range (%zu vertices, counted from 0)%s",
                                          where(&r), val, m.nv, r.fmt == PLY_ASCII ? "" : "; is the byte order right?");
                            goto out;
                        }
                        m.tri[3 * i + k] = (uint32_t)val;
                    }
                }
            }
            if ((rc = ply_end(&r)) < 0)
                goto out;
        }
    }
    if (!have_v || !have_f) {
        rc = nc_error(NC_EMESH, "%s: PLY has no %s element", path, have_v ? "face" : "vertex");
        goto out;
    }
    if (r.fmt == PLY_ASCII) {
        while ((rc = nc_lines_next(&r.ln)) > 0)
            if (r.ln.line[strspn(r.ln.line, " \t\r\n")]) {
                rc = nc_error(NC_EMESH, "%s:%zu: data after the elements the header announces (does it count them "
                              "all?)", path, r.ln.no);
                break;
            }
        if (rc < 0)
            goto out;
    } else {
        int c; /* a line end or blanks after binary data are a writer's habit, not data */
        while ((c = fgetc(r.f)) != EOF && (c == '\n' || c == '\r' || c == ' ' || c == '\t'))
            ;
        if (c != EOF) {
            rc = nc_error(NC_EMESH, "%s: data after the elements the header announces (does it count them all?)",
                          path);
            goto out;
        }
    }
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
