/* mesh_lod.c - levels of detail of a triangle mesh (mesh.h), by edge
 * collapse (meshoptimizer's quadric simplifier). Every level keeps the
 * original vertices (it only drops some), so the bounding sphere holds for
 * all of them and one vertex buffer serves every level. */
#include <errno.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/mesh.h"

void nc_mesh_lod_free(struct nc_mesh_lod *l)
{
    for (int k = 1; k < l->nlevels; k++) /* level 0 is the mesh's own list */
        free(l->level[k].tri);
    memset(l, 0, sizeof *l);
}

int nc_mesh_lod_build(const struct nc_mesh *m, size_t min_triangles, struct nc_mesh_lod *out)
{
    memset(out, 0, sizeof *out);
    out->level[0] = (struct nc_mesh_lod_level){.tri = m->tri, .nt = m->nt, .error_m = 0};
    out->nlevels = 1;
    if (m->nt / 4 < min_triangles)
        return 0;
    float *p = malloc(m->nv * 3 * sizeof *p); /* body frame, metres: relative errors of 1e-7 */
    if (!p)
        return nc_error(-ENOMEM, "out of memory for %zu vertices", m->nv);
    for (size_t i = 0; i < 3 * m->nv; i++)
        p[i] = (float)m->v[i];
    const double scale_m = meshopt_simplifyScale(p, m->nv, 3 * sizeof *p);
    int rc = 0;
    while (out->nlevels < NC_LOD_MAX_LEVELS) {
        const struct nc_mesh_lod_level *prev = &out->level[out->nlevels - 1];
        size_t target = prev->nt / 4;
        if (target < min_triangles)
            break;
        uint32_t *tri = malloc(prev->nt * 3 * sizeof *tri); /* the simplifier's worst case */
        if (!tri) {
            rc = nc_error(-ENOMEM, "out of memory for a level of detail of %zu triangles", prev->nt);
            break;
        }
        float rel = 0;
        size_t ni = meshopt_simplify(tri, prev->tri, prev->nt * 3, p, m->nv, 3 * sizeof *p, target * 3, 1.0f, 0, &rel);
        /* The simplifier stops short where topology forbids collapses: a level
         * under 1.5x fewer triangles is not worth its memory. */
        if (ni / 3 == 0 || ni / 3 > prev->nt * 2 / 3) {
            free(tri);
            break;
        }
        uint32_t *fit = realloc(tri, ni * sizeof *tri);
        /* Each level's error is measured against the level it came from; the
         * sum bounds the distance from the full mesh (triangle inequality). */
        out->level[out->nlevels] = (struct nc_mesh_lod_level){
            .tri = fit ? fit : tri, .nt = ni / 3, .error_m = prev->error_m + (double)rel * scale_m};
        out->nlevels++;
    }
    free(p);
    if (rc < 0)
        nc_mesh_lod_free(out);
    return rc;
}

int nc_mesh_lod_pick_error(const double *error_m, int nlevels, double max_error_m)
{
    int k = 0;
    while (k + 1 < nlevels && error_m[k + 1] <= max_error_m)
        k++;
    return k;
}
