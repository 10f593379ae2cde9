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

/* Edge -> midpoint vertex, open addressing. */
struct edge_map {
    uint64_t *key;
    uint32_t *val;
    size_t mask;
};

int nc_mesh_subdivide(struct nc_mesh *m, nc_mesh_midpoint_fn place, void *ctx)
{
    const size_t nt = m->nt, cap_v = m->nv + 3 * nt; /* at most one new vertex per half-edge */
    if (cap_v > UINT32_MAX || 4 * nt > (SIZE_MAX / 3) / sizeof(uint32_t))
        return nc_error(NC_ERANGE, "subdividing %zu triangles: too many vertices", nt);
    size_t cap = 64;
    while (cap < 2 * 3 * nt)
        cap *= 2;
    struct edge_map em = {malloc(cap * sizeof *em.key), malloc(cap * sizeof *em.val), cap - 1};
    double *v = realloc(m->v, 3 * cap_v * sizeof *v);
    if (v)
        m->v = v;
    uint32_t *tri = malloc(3 * 4 * nt * sizeof *tri);
    if (!em.key || !em.val || !v || !tri) {
        free(em.key);
        free(em.val);
        free(tri);
        return nc_error(-ENOMEM, "out of memory subdividing %zu triangles", nt);
    }
    memset(em.key, 0xff, cap * sizeof *em.key);
    for (size_t f = 0; f < nt; f++) {
        const uint32_t *t = m->tri + 3 * f;
        uint32_t mid[3];
        for (int e = 0; e < 3; e++) {
            uint32_t a = t[e], b = t[(e + 1) % 3];
            uint64_t k = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            size_t h = (size_t)((k * 0x9e3779b97f4a7c15ull) >> 20) & em.mask;
            while (em.key[h] != UINT64_MAX && em.key[h] != k)
                h = (h + 1) & em.mask;
            if (em.key[h] == UINT64_MAX) {
                double *p = m->v + 3 * m->nv;
                for (int i = 0; i < 3; i++)
                    p[i] = 0.5 * (m->v[3 * a + i] + m->v[3 * b + i]);
                if (place)
                    place(ctx, m, a < b ? a : b, a < b ? b : a, (uint32_t)m->nv, p);
                em.key[h] = k;
                em.val[h] = (uint32_t)m->nv++;
            }
            mid[e] = em.val[h];
        }
        /* corners a, b, c; midpoints ab, bc, ca */
        const uint32_t nf[4][3] = {{t[0], mid[0], mid[2]}, {t[1], mid[1], mid[0]}, {t[2], mid[2], mid[1]},
                                   {mid[0], mid[1], mid[2]}};
        memcpy(tri + 12 * f, nf, sizeof nf);
    }
    free(em.key);
    free(em.val);
    free(m->tri);
    m->tri = tri;
    m->nt = 4 * nt;
    double *fit = realloc(m->v, 3 * m->nv * sizeof *fit);
    if (fit)
        m->v = fit;
    return 0;
}
