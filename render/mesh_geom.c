/* mesh_geom.c - measures of a mesh (mesh.h): face areas and normals, total
 * area, area-weighted vertex normals. Pure geometry; no I/O, no Embree. */
#include "render/mesh.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

double nc_mesh_face(const struct nc_mesh *m, size_t t, struct nc_vec3 *unit_normal)
{
    const double *v0 = m->v + 3 * m->tri[3 * t], *v1 = m->v + 3 * m->tri[3 * t + 1], *v2 = m->v + 3 * m->tri[3 * t + 2];
    struct nc_vec3 c = nc_v3_cross(nc_v3(v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]),
                                   nc_v3(v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]));
    double len = nc_v3_norm(c);
    if (unit_normal)
        *unit_normal = len > 0 ? nc_v3_scale(c, 1 / len) : nc_v3(0, 0, 0);
    return 0.5 * len;
}

double nc_mesh_mean_edge_m(const struct nc_mesh *m)
{
    double len = 0;
    for (size_t t = 0; t < m->nt; t++)
        for (int e = 0; e < 3; e++) {
            const double *a = m->v + 3 * m->tri[3 * t + e], *b = m->v + 3 * m->tri[3 * t + (e + 1) % 3];
            double d2 = 0;
            for (int k = 0; k < 3; k++)
                d2 += (b[k] - a[k]) * (b[k] - a[k]);
            len += sqrt(d2);
        }
    return m->nt ? len / (3.0 * (double)m->nt) : 0;
}

double nc_mesh_area_m2(const struct nc_mesh *m)
{
    double a = 0;
    for (size_t t = 0; t < m->nt; t++)
        a += nc_mesh_face(m, t, NULL);
    return a;
}

void nc_mesh_vertex_normals(const struct nc_mesh *m, double *n)
{
    memset(n, 0, 3 * m->nv * sizeof *n);
    for (size_t t = 0; t < m->nt; t++) {
        struct nc_vec3 u;
        double a = nc_mesh_face(m, t, &u);
        for (int k = 0; k < 3; k++) {
            double *p = n + 3 * m->tri[3 * t + k];
            p[0] += a * u.x;
            p[1] += a * u.y;
            p[2] += a * u.z;
        }
    }
    for (size_t i = 0; i < m->nv; i++) {
        double *p = n + 3 * i, len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (int k = 0; k < 3; k++)
            p[k] = len > 0 ? p[k] / len : 0;
    }
}

static int cmp_u64(const void *pa, const void *pb)
{
    const uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
    return (a > b) - (a < b);
}

/* For each half-edge h (of triangle h / 3, from its corner h % 3 to the
 * next), rep[h] = the first half-edge, in triangle order, of the same edge
 * in either direction. A counting sort of the half-edges by their lower
 * end, then within each end's few half-edges a sort by (other end,
 * half-edge): its writes follow the mesh's vertex order, where a hash table
 * of edges made each one a cache miss. */
static int edge_firsts(const struct nc_mesh *m, uint32_t *rep)
{
    const size_t nv = m->nv, H = 3 * m->nt;
    if (m->nt > UINT32_MAX / 3)
        return nc_error(NC_ERANGE, "%zu triangles: too many half-edges for 32-bit indices", m->nt);
    uint32_t *start = calloc(nv + 1, sizeof *start), *at = malloc((nv ? nv : 1) * sizeof *at);
    uint64_t *e = malloc((H ? H : 1) * sizeof *e);
    if (!start || !at || !e) {
        free(start);
        free(at);
        free(e);
        return nc_error(-ENOMEM, "out of memory for the edges of %zu triangles", m->nt);
    }
    for (size_t h = 0; h < H; h++) {
        const uint32_t a = m->tri[h], b = m->tri[h - h % 3 + (h + 1) % 3];
        if (a >= nv || b >= nv) {
            free(start);
            free(at);
            free(e);
            return nc_error(NC_EMESH, "triangle %zu names vertex %u of %zu", h / 3, a > b ? a : b, nv);
        }
        start[(a < b ? a : b) + 1]++;
    }
    for (size_t i = 0; i < nv; i++) {
        start[i + 1] += start[i];
        at[i] = start[i];
    }
    for (size_t h = 0; h < H; h++) {
        const uint32_t a = m->tri[h], b = m->tri[h - h % 3 + (h + 1) % 3];
        e[at[a < b ? a : b]++] = (uint64_t)(a < b ? b : a) << 32 | h;
    }
    for (size_t i = 0; i < nv; i++) {
        uint64_t *x = e + start[i];
        const size_t n = start[i + 1] - start[i];
        if (n > 16) /* a fan's hub */
            qsort(x, n, sizeof *x, cmp_u64);
        else /* insertion sort: about 6 a vertex */
            for (size_t j = 1; j < n; j++)
                for (size_t k = j; k > 0 && x[k - 1] > x[k]; k--) {
                    const uint64_t t = x[k];
                    x[k] = x[k - 1];
                    x[k - 1] = t;
                }
        for (size_t j = 0; j < n;) {
            size_t k = j;
            while (k < n && x[k] >> 32 == x[j] >> 32)
                rep[(uint32_t)x[k++]] = (uint32_t)x[j];
            j = k;
        }
    }
    free(start);
    free(at);
    free(e);
    return 0;
}

int nc_mesh_subdivide(struct nc_mesh *m, nc_mesh_midpoint_fn place, void *ctx)
{
    const size_t nt = m->nt, cap_v = m->nv + 3 * nt; /* at most one new vertex per half-edge */
    if (cap_v > UINT32_MAX || 4 * nt > (SIZE_MAX / 3) / sizeof(uint32_t))
        return nc_error(NC_ERANGE, "subdividing %zu triangles: too many vertices", nt);
    uint32_t *rep = malloc((nt ? 3 * nt : 1) * sizeof *rep), *mid = malloc((nt ? 3 * nt : 1) * sizeof *mid);
    double *v = realloc(m->v, 3 * cap_v * sizeof *v);
    if (v)
        m->v = v;
    uint32_t *tri = malloc(3 * 4 * nt * sizeof *tri);
    int rc = !rep || !mid || !v || !tri ? nc_error(-ENOMEM, "out of memory subdividing %zu triangles", nt)
                                        : edge_firsts(m, rep);
    if (rc < 0) {
        free(rep);
        free(mid);
        free(tri);
        return rc;
    }
    /* New vertices in order of their edges' first half-edges, as the faces
     * are read: mid[h] is the midpoint of half-edge h's edge. */
    for (size_t f = 0; f < nt; f++) {
        const uint32_t *t = m->tri + 3 * f;
        for (int e = 0; e < 3; e++) {
            const size_t h = 3 * f + (size_t)e;
            if (rep[h] == h) {
                const uint32_t a = t[e], b = t[(e + 1) % 3];
                double *p = m->v + 3 * m->nv;
                for (int i = 0; i < 3; i++)
                    p[i] = 0.5 * (m->v[3 * a + i] + m->v[3 * b + i]);
                if (place)
                    place(ctx, m, a < b ? a : b, a < b ? b : a, (uint32_t)m->nv, p);
                mid[h] = (uint32_t)m->nv++;
            } else
                mid[h] = mid[rep[h]];
        }
        const uint32_t *md = mid + 3 * f;
        /* corners a, b, c; midpoints ab, bc, ca */
        const uint32_t nf[4][3] = {{t[0], md[0], md[2]}, {t[1], md[1], md[0]}, {t[2], md[2], md[1]},
                                   {md[0], md[1], md[2]}};
        memcpy(tri + 12 * f, nf, sizeof nf);
    }
    free(rep);
    free(mid);
    free(m->tri);
    m->tri = tri;
    m->nt = 4 * nt;
    double *fit = realloc(m->v, 3 * m->nv * sizeof *fit);
    if (fit)
        m->v = fit;
    return 0;
}
