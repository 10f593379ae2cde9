/* mesh_geom.c - measures of a mesh (mesh.h): face areas and normals, total
 * area, area-weighted vertex normals. Pure geometry; no I/O, no Embree. */
#include "render/mesh.h"

#include <math.h>
#include <string.h>

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
