/* rt_rock_mesh.c - the rocks' detailed surfaces (rt_rocks.h): each shape's
 * surface (nc_rock_shape_mesh) is an Embree scene of one triangle mesh,
 * built once and shared by every rock of that shape; a rock resolved by
 * enough pixels is traced through it with the ray in the rock's own frame,
 * from inside its intersection test (rt_rocks.c). */
#include "render/rt_rocks.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

int nc__rt_rock_meshes(RTCDevice dev, struct nc__rt_rocks *r)
{
    const struct nc_boulder_field *f = r->field;
    if (!(f->relief[0] > 0) || !f->n)
        return 0;
    if (!(r->mesh = calloc((size_t)f->nshapes, sizeof *r->mesh)))
        return nc_error(-ENOMEM, "out of memory");
    for (int s = 0; s < f->nshapes; s++) {
        struct nc_mesh m;
        int rc = nc_rock_shape_mesh(f, s, NC_ROCK_MESH_SUBDIVISIONS, &m);
        if (rc < 0)
            return rc;
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *v = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.nv)
                     : NULL;
        unsigned *t = v ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                  m.nt)
                        : NULL;
        if (!t || !(r->mesh[s] = rtcNewScene(dev))) {
            if (g)
                rtcReleaseGeometry(g);
            nc_mesh_free(&m);
            return nc_error(NC_ERENDER, "embree: cannot create a rock's surface");
        }
        for (size_t i = 0; i < 3 * m.nv; i++)
            v[i] = (float)m.v[i];
        memcpy(t, m.tri, 3 * m.nt * sizeof *t);
        r->mesh_triangles = m.nt;
        nc_mesh_free(&m);
        rtcSetSceneFlags(r->mesh[s], RTC_SCENE_FLAG_COMPACT);
        rtcCommitGeometry(g);
        rtcAttachGeometry(r->mesh[s], g);
        rtcReleaseGeometry(g);
        rtcCommitScene(r->mesh[s]);
    }
    return 0;
}

void nc__rt_rock_meshes_free(struct nc__rt_rocks *r)
{
    for (int s = 0; r->mesh && s < r->field->nshapes; s++)
        if (r->mesh[s])
            rtcReleaseScene(r->mesh[s]);
    free(r->mesh);
    r->mesh = NULL;
}

int nc__rt_rock_mesh_hit(const struct nc__rt_rocks *r, const struct nc__rt_rock *k, const float o[3],
                         const float d[3], float tnear, float tfar, float t0, float t1, float *t, float *n)
{
    float ol[3], dl[3], rel[3];
    for (int j = 0; j < 3; j++)
        rel[j] = o[j] - k->c[j];
    for (int j = 0; j < 3; j++) { /* into the rock's frame as the planes' test: t is unchanged */
        ol[j] = k->M[3 * j] * rel[0] + k->M[3 * j + 1] * rel[1] + k->M[3 * j + 2] * rel[2];
        dl[j] = k->M[3 * j] * d[0] + k->M[3 * j + 1] * d[1] + k->M[3 * j + 2] * d[2];
    }
    const float widen = 1e-3f / sqrtf(dl[0] * dl[0] + dl[1] * dl[1] + dl[2] * dl[2]);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh = {.ray = {.org_x = ol[0], .org_y = ol[1], .org_z = ol[2], .tnear = fmaxf(tnear, t0 - widen),
                                   .dir_x = dl[0], .dir_y = dl[1], .dir_z = dl[2], .tfar = fminf(tfar, t1 + widen),
                                   .mask = UINT32_MAX},
                           .hit = {.geomID = RTC_INVALID_GEOMETRY_ID}};
    if (!n) {
        rtcOccluded1(r->mesh[k->shape], &ctx, &rh.ray);
        return rh.ray.tfar < 0;
    }
    rtcIntersect1(r->mesh[k->shape], &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    *t = rh.ray.tfar;
    n[0] = rh.hit.Ng_x, n[1] = rh.hit.Ng_y, n[2] = rh.hit.Ng_z;
    return 1;
}
