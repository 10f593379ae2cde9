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
 * Vertices on the cube's edges are listed once per face; copies with equal
 * coordinates are welded into one, so the surface is closed.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/mesh.h"

static const double *sort_base; /* qsort has no context argument; loading is single-threaded */

static int by_xyz(const void *a, const void *b)
{
    const double *p = sort_base + 3 * (size_t)*(const uint32_t *)a, *q = sort_base + 3 * (size_t)*(const uint32_t *)b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return *(const uint32_t *)a < *(const uint32_t *)b ? -1 : 1;
}

int nc_mesh_load_icq(const char *path, double scale, struct nc_mesh *out)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(NC_EMESH, "%s: %s", path, strerror(errno));
    char line[512];
    long q = 0;
    size_t lineno = 0, nv = 0, want = 0;
    double *v = NULL;
    uint32_t *tri = NULL, *order = NULL, *weld = NULL;
    int rc = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char *s = line + strspn(line, " \t\r\n");
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
            if (!(v = malloc(3 * want * sizeof *v))) {
                rc = nc_error(-ENOMEM, "%s: out of memory for %zu vertices", path, want);
                break;
            }
            continue;
        }
        double x[4];
        char *end;
        int k = 0;
        for (; k < 4; k++) {
            x[k] = strtod(s, &end);
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
        nv++;
    }
    fclose(f);
    if (rc == 0 && !want)
        rc = nc_error(NC_EMESH, "%s: empty: no Q line", path);
    if (rc == 0 && nv != want)
        rc = nc_error(NC_EMESH, "%s: %zu vertices, but Q = %ld needs 6 (Q+1)^2 = %zu", path, nv, q, want);
    /* Weld equal coordinates: the first of each run keeps its place. */
    if (rc == 0 && (!(order = malloc(nv * sizeof *order)) || !(weld = malloc(nv * sizeof *weld))))
        rc = nc_error(-ENOMEM, "%s: out of memory", path);
    if (rc == 0) {
        for (size_t i = 0; i < nv; i++)
            order[i] = (uint32_t)i;
        sort_base = v;
        qsort(order, nv, sizeof *order, by_xyz);
        for (size_t i = 0; i < nv; i++) {
            size_t first = i;
            while (first > 0 && !memcmp(v + 3 * (size_t)order[first - 1], v + 3 * (size_t)order[i], 3 * sizeof *v))
                first--;
            weld[order[i]] = order[first]; /* runs are short: at most 3 copies of a corner */
        }
        const size_t Q = (size_t)q, side = Q + 1, nt = 12 * Q * Q;
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
    return rc;
}
