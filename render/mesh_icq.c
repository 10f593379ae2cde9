/* mesh_icq.c - SPC's implicitly connected quadrilateral shape format (ICQ,
 * the SHAPE.TXT of Gaskell's stereophotoclinometry), read into a triangle
 * mesh. No Embree here.
 *
 * Line 1 holds Q; then 6 (Q+1)^2 lines of "x y z" (an optional fourth
 * column, an albedo, is ignored): the six faces of a cube, face F = 0..5
 * outermost, then J = 0..Q, then I = 0..Q fastest, vertex index
 * F (Q+1)^2 + J (Q+1) + I. The quadrilateral (I, J) of a face is
 * v(I, J), v(I, J+1), v(I+1, J+1), v(I+1, J), wound outward on every face
 * (the PDS icqm.txt description; its face axes are tabulated in
 * docs/sumfiles.md); it becomes two triangles with the same winding.
 * Vertices on the cube's edges are listed once per face; the copies of one
 * (the same point of the cube, by the face axes) are welded into one, so
 * the surface is closed, and must agree to 1e-6 of the model's extent.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/lines.h"
#include "render/mesh.h"

/* Face F's axes (docs/sumfiles.md): outward, I's and J's directions, each
 * an axis 1..3 (x, y, z) with its sign. */
static const int face_axes[6][3] = {{3, 1, -2}, {-2, 1, -3}, {-1, -2, -3}, {2, -1, -3}, {1, 2, -3}, {-3, 1, 2}};

/* Vertex (F, I, J) as a point of the cube [-Q, Q]^3 (twice its own
 * coordinates, so whole numbers), packed into one key: the copies of an
 * edge's vertex have the same. */
static uint64_t cube_point(long q, size_t face, size_t i, size_t j)
{
    const long w[3] = {q, 2 * (long)i - q, 2 * (long)j - q};
    long p[3] = {q, q, q}; /* from 0 to 2Q: 13 bits each for Q <= 2048 */
    for (int k = 0; k < 3; k++) {
        const int a = face_axes[face][k];
        p[abs(a) - 1] += a > 0 ? w[k] : -w[k];
    }
    return (uint64_t)p[0] << 26 | (uint64_t)p[1] << 13 | (uint64_t)p[2];
}

static const uint64_t *sort_base; /* qsort has no context argument; loading is single-threaded */

static int by_point(const void *a, const void *b)
{
    const uint32_t i = *(const uint32_t *)a, j = *(const uint32_t *)b;
    if (sort_base[i] != sort_base[j])
        return sort_base[i] < sort_base[j] ? -1 : 1;
    return i < j ? -1 : 1;
}

int nc_mesh_load_icq(const char *path, double scale, struct nc_mesh *out)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(NC_EMESH, "%s: %s", path, strerror(errno));
    struct nc_lines ln;
    nc_lines_init(&ln, f, path, NC_EMESH);
    long q = 0;
    size_t nv = 0, want = 0;
    double *v = NULL;
    uint32_t *tri = NULL, *order = NULL, *weld = NULL, *vline = NULL;
    uint64_t *cube = NULL;
    int rc;
    while ((rc = nc_lines_next(&ln)) > 0) {
        const size_t lineno = ln.no;
        char *s = ln.line + strspn(ln.line, " \t\r\n");
        if (!*s)
            continue;
        if (!want) {
            char *end;
            q = strtol(s, &end, 10);
            if (end == s || *(end + strspn(end, " \t\r\n")) || q < 1 || q > 2048) {
                rc = nc_error(NC_EMESH, "%s:%zu: expected Q, the ICQ resolution (a whole number 1..2048)", path,
                              lineno);
                break;
            }
            want = 6 * (size_t)(q + 1) * (size_t)(q + 1);
            if (!(v = malloc(3 * want * sizeof *v)) || !(vline = malloc(want * sizeof *vline))) {
                rc = nc_error(-ENOMEM, "%s: out of memory for %zu vertices", path, want);
                break;
            }
            continue;
        }
        double x[4];
        char *end;
        int k = 0;
        for (; k < 4; k++) {
            x[k] = nc_strtod_fortran(s, &end);
            if (end == s)
                break;
            s = end;
        }
        if (k < 3 || *(s + strspn(s, " \t\r\n")) || !isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2])) {
            rc = nc_error(NC_EMESH, "%s:%zu: expected a vertex: x y z (finite numbers, an optional fourth column)", path,
                          lineno);
            break;
        }
        if (nv == want) {
            rc = nc_error(NC_EMESH, "%s:%zu: more than the 6 (Q+1)^2 = %zu vertices of Q = %ld", path, lineno, want, q);
            break;
        }
        for (int c = 0; c < 3; c++)
            v[3 * nv + (size_t)c] = x[c] * scale;
        vline[nv] = (uint32_t)lineno;
        nv++;
    }
    nc_lines_free(&ln);
    fclose(f);
    if (rc == 0 && !want)
        rc = nc_error(NC_EMESH, "%s: empty: no Q line", path);
    if (rc == 0 && nv != want)
        rc = nc_error(NC_EMESH, "%s: %zu vertices, but Q = %ld needs 6 (Q+1)^2 = %zu", path, nv, q, want);
    /* Weld the copies of each point of the cube: the first keeps its place. */
    const size_t side = (size_t)q + 1;
    if (rc == 0 && (!(order = malloc(nv * sizeof *order)) || !(weld = malloc(nv * sizeof *weld)) ||
                    !(cube = malloc(nv * sizeof *cube))))
        rc = nc_error(-ENOMEM, "%s: out of memory", path);
    if (rc == 0) {
        double extent = 0;
        for (size_t i = 0; i < nv; i++) {
            order[i] = (uint32_t)i;
            cube[i] = cube_point(q, i / (side * side), i % side, i / side % side);
            for (int c = 0; c < 3; c++)
                extent = fmax(extent, fabs(v[3 * i + (size_t)c]));
        }
        sort_base = cube;
        qsort(order, nv, sizeof *order, by_point);
        for (size_t i = 0; i < nv && rc == 0; i++) {
            size_t first = i;
            while (first > 0 && cube[order[first - 1]] == cube[order[i]])
                first--;
            const uint32_t a = order[first], b = order[i];
            weld[b] = a; /* runs are short: at most 3 copies of a corner */
            const double *pa = v + 3 * (size_t)a, *pb = v + 3 * (size_t)b;
            const double d = sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                                  (pa[2] - pb[2]) * (pa[2] - pb[2]));
            if (d > 1e-6 * extent)
                rc = nc_error(NC_EMESH, "%s:%u: this vertex and the one on line %u are the same point of the cube's "
                                        "edges (faces %zu and %zu), but lie %.6g m apart: not a closed ICQ surface",
                              path, vline[b], vline[a], (size_t)a / (side * side) + 1, (size_t)b / (side * side) + 1, d);
        }
    }
    if (rc == 0) {
        const size_t Q = (size_t)q, nt = 12 * Q * Q;
        if (!(tri = malloc(3 * nt * sizeof *tri)))
            rc = nc_error(-ENOMEM, "%s: out of memory", path);
        for (size_t face = 0, t = 0; rc == 0 && face < 6; face++)
            for (size_t j = 0; j < Q; j++)
                for (size_t i = 0; i < Q; i++) {
                    size_t base = face * side * side;
                    uint32_t a = weld[base + j * side + i], b = weld[base + (j + 1) * side + i],
                             c = weld[base + (j + 1) * side + i + 1], d = weld[base + j * side + i + 1];
                    uint32_t two[6] = {a, b, c, a, c, d};
                    memcpy(tri + 3 * t, two, sizeof two);
                    t += 2;
                }
        out->v = v;
        out->nv = nv;
        out->tri = tri;
        out->nt = nt;
        v = NULL;
        tri = NULL;
    }
    free(v);
    free(tri);
    free(order);
    free(weld);
    free(cube);
    free(vline);
    return rc;
}
