/* rt_rock_mesh.c - the rocks' detailed surfaces (rt_rocks.h): each shape's
 * surface (nc_rock_shape_mesh) is an Embree scene of one triangle mesh,
 * built once and shared by every rock of that shape, with normals at its
 * triangles' corners for shading; a rock resolved by enough pixels is
 * traced through it with the ray in the rock's own frame, from inside its
 * intersection test (rt_rocks.c). */
#include "render/rt_rocks.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* Shading normals at each triangle's corners (9 a triangle, rock frame,
 * unit, times 32767: half the memory of floats, within 1e-4 rad): the
 * area-weighted mean of the normals of the triangles around that corner's
 * vertex that turn less than CREASE_DEG from the triangle's own, so that
 * the polyhedron's edges stay sharp while the triangles within a face
 * shade smoothly. */
#define CREASE_DEG 30.0
static int corner_normals(const struct nc_mesh *m, int16_t *cn)
{
    double *fn = malloc(3 * m->nt * sizeof *fn);
    size_t *start = calloc(m->nv + 1, sizeof *start), *list = malloc(3 * m->nt * sizeof *list);
    if (!fn || !start || !list) {
        free(fn), free(start), free(list);
        return nc_error(-ENOMEM, "out of memory");
    }
    for (size_t t = 0; t < m->nt; t++) { /* area-weighted normals; each vertex's triangles */
        struct nc_vec3 u;
        double a = nc_mesh_face(m, t, &u);
        fn[3 * t] = a * u.x, fn[3 * t + 1] = a * u.y, fn[3 * t + 2] = a * u.z;
        for (int j = 0; j < 3; j++)
            start[m->tri[3 * t + j] + 1]++;
    }
    for (size_t v = 0; v < m->nv; v++)
        start[v + 1] += start[v];
    size_t *fill = calloc(m->nv, sizeof *fill);
    if (!fill) {
        free(fn), free(start), free(list);
        return nc_error(-ENOMEM, "out of memory");
    }
    for (size_t t = 0; t < m->nt; t++)
        for (int j = 0; j < 3; j++) {
            const uint32_t v = m->tri[3 * t + j];
            list[start[v] + fill[v]++] = t;
        }
    const double c = cos(CREASE_DEG * M_PI / 180);
    for (size_t t = 0; t < m->nt; t++)
        for (int j = 0; j < 3; j++) {
            const uint32_t v = m->tri[3 * t + j];
            const double *f = fn + 3 * t, ff = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            double s[3] = {0, 0, 0};
            for (size_t q = start[v]; q < start[v + 1]; q++) {
                const double *g = fn + 3 * list[q], gg = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
                if (f[0] * g[0] + f[1] * g[1] + f[2] * g[2] >= c * ff * gg)
                    s[0] += g[0], s[1] += g[1], s[2] += g[2];
            }
            const double n = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            for (int k = 0; k < 3; k++)
                cn[9 * t + 3 * j + k] = (int16_t)lrint(n > 0 ? 32767 * s[k] / n : 0.0);
        }
    free(fn), free(start), free(list), free(fill);
    return 0;
}

/* The detailed surfaces are one-sided, as the planes' test is, for every
 * ray: a shadow or bounce ray whose origin lies within float rounding under
 * the surface (it starts 4e-6 of its camera distance off the point, and the
 * rock's record is placed to 6e-8 of its tile's spread) leaves through the
 * surface's back, which neither stops nor lights it, and a camera inside a
 * rock sees out of it. Outward is away from the rock's centre, the origin of
 * its frame (the surface is the relief on a convex polyhedron). */
static void front_faces(const struct RTCFilterFunctionNArguments *a)
{
    const unsigned N = a->N;
    const float *ray = (const float *)a->ray, *hit = (const float *)a->hit; /* RTCRayN, RTCHitN: N-wide SOA */
    for (unsigned i = 0; i < N; i++) {
        if (!a->valid[i])
            continue;
        const float t = ray[8 * N + i], *d = ray + 4 * N + i, *o = ray + i, *ng = hit + i;
        float out = 0, dn = 0;
        for (unsigned k = 0; k < 3; k++)
            out += ng[k * N] * (o[k * N] + t * d[k * N]), dn += ng[k * N] * d[k * N];
        if ((out > 0) == (dn > 0)) /* leaving: the back */
            a->valid[i] = 0;
    }
}

int nc__rt_rock_meshes(RTCDevice dev, struct nc__rt_rocks *r)
{
    const struct nc_boulder_field *f = r->field;
    if (!(f->relief[0] > 0) || !f->n)
        return 0;
    if (!(r->surf = calloc((size_t)f->nshapes, sizeof *r->surf)))
        return nc_error(-ENOMEM, "out of memory");
    for (int s = 0; s < f->nshapes; s++) {
        struct nc_mesh m;
        int rc = nc_rock_shape_mesh(f, s, NC_ROCK_MESH_SUBDIVISIONS, &m);
        if (rc < 0)
            return rc;
        struct nc__rt_rock_surface *sf = &r->surf[s];
        if (!(sf->cn = malloc(9 * m.nt * sizeof *sf->cn)))
            rc = nc_error(-ENOMEM, "out of memory");
        else
            rc = corner_normals(&m, sf->cn);
        if (rc < 0) {
            nc_mesh_free(&m);
            return rc;
        }
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *v = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.nv)
                     : NULL;
        unsigned *t = v ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                  m.nt)
                        : NULL;
        if (!t || !(sf->scene = rtcNewScene(dev))) {
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
        rtcSetSceneFlags(sf->scene, RTC_SCENE_FLAG_COMPACT);
        rtcSetGeometryOccludedFilterFunction(g, front_faces);
        rtcSetGeometryIntersectFilterFunction(g, front_faces);
        rtcCommitGeometry(g);
        rtcAttachGeometry(sf->scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(sf->scene);
    }
    return 0;
}

void nc__rt_rock_meshes_free(struct nc__rt_rocks *r)
{
    for (int s = 0; r->surf && s < r->field->nshapes; s++) {
        if (r->surf[s].scene)
            rtcReleaseScene(r->surf[s].scene);
        free(r->surf[s].cn);
    }
    free(r->surf);
    r->surf = NULL;
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
    const struct nc__rt_rock_surface *sf = &r->surf[k->shape];
    if (!n) {
        rtcOccluded1(sf->scene, &ctx, &rh.ray);
        return rh.ray.tfar < 0;
    }
    rtcIntersect1(sf->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    *t = rh.ray.tfar;
    const int16_t *c = sf->cn + 9 * (size_t)rh.hit.primID;
    const float u = rh.hit.u, v = rh.hit.v, w = 1 - u - v, ng[3] = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    float ns[3], gd = 0, sd = 0, sg = 0;
    for (int j = 0; j < 3; j++) {
        ns[j] = w * c[j] + u * c[3 + j] + v * c[6 + j];
        gd += ng[j] * dl[j], sd += ns[j] * dl[j], sg += ns[j] * ng[j];
    }
    const int smooth = (gd < 0) == (sd < 0) && sg > 0; /* a shading normal never shows a face the geometry hides */
    for (int j = 0; j < 3; j++)
        n[j] = smooth ? ns[j] : ng[j];
    return 1;
}
