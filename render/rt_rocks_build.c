/* rt_rocks_build.c - the rocks' tiles (rt_rocks.h): each rock's record
 * (its rotation over its size, its shape) and extent from its shape's
 * corners, the rocks sorted into the tiles of their octave and, within a
 * tile, into Morton order of their centres; the tiles' Embree scenes and
 * instances, the cut and the pose. */
#include "render/rt_rocks.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

#define MAX_CORNERS NC_ROCK_CORNERS_MAX

/* The traced record of rock b, whose shape has the nv corners v: R^T / s
 * for its rotation q (renormalised, as the generator placed it) and half
 * size s; and its extent along the body axes (the corners turned) into
 * ext. The centre and rank come with its tile. */
static void record(const struct nc_boulder *b, const float (*v)[3], int nv, struct nc__rt_rock *k, float *ext)
{
    double w = b->q[0], x = b->q[1], y = b->q[2], z = b->q[3];
    double n = sqrt(w * w + x * x + y * y + z * z);
    w /= n, x /= n, y /= n, z /= n;
    const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    memset(k, 0, sizeof *k);
    for (int i = 0; i < 3; i++) {
        double e = 0;
        for (int j = 0; j < nv; j++)
            e = fmax(e, fabs(R[i][0] * v[j][0] + R[i][1] * v[j][1] + R[i][2] * v[j][2]));
        ext[i] = (float)(e * b->half_m);
        for (int c = 0; c < 3; c++)
            k->M[3 * i + c] = (float)(R[c][i] / b->half_m);
    }
    k->shape = b->shape;
}

/* A rock's tile key: the cube of the body frame its centre falls in (of
 * its octave's size), and the Morton code of the centre in the cube. */
struct tile_key {
    uint64_t morton;
    int32_t x, y, z; /* within 2^31 cubes of the origin (checked) */
    uint32_t rock;
};

static int key_cmp(const void *pa, const void *pb)
{
    const struct tile_key *a = pa, *b = pb;
    if (a->x != b->x)
        return a->x < b->x ? -1 : 1;
    if (a->y != b->y)
        return a->y < b->y ? -1 : 1;
    if (a->z != b->z)
        return a->z < b->z ? -1 : 1;
    if (a->morton != b->morton)
        return a->morton < b->morton ? -1 : 1;
    return (a->rock > b->rock) - (a->rock < b->rock);
}

static uint64_t spread3(uint64_t x) /* the 21 bits of x spread to every third bit */
{
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

/* Centre c (body frame) in the cube key of side S: its Morton code, 2^21 steps an axis. */
static uint64_t morton(const double *c, const int32_t *key, double S)
{
    uint64_t m = 0;
    for (int i = 0; i < 3; i++) {
        double q = (c[i] / S - (double)key[i]) * 2097152.0;
        m |= spread3(q <= 0 ? 0 : q >= 2097151 ? 2097151 : (uint64_t)q) << i;
    }
    return m;
}

/* Cube edge of octave j's tiles: 1024 times its largest diameter. For the
 * million rocks of bench_rubble that is a few tiles an octave, traced as
 * fast as one tree (alternating runs, 6 km and 1.5 km); 1 412 tiles of 64
 * times traced 8 to 20 % slower. */
static double tile_size_m(int j) { return 1024.0 * exp2(j + 1); }

static int make_tile(RTCDevice dev, struct nc__rt_rocks *r, struct nc__rt_rock_tile *tl)
{
    if (!(tl->scene = rtcNewScene(dev)) || !(tl->geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_USER)))
        return nc_error(NC_ERENDER, "embree: cannot create a boulder tile");
    /* A tile's tree is built once. COMPACT: 1.07 million rocks took 176 MB
     * with it, 201 MB without (test_boulders), at the same frame time. */
    rtcSetSceneBuildQuality(tl->scene, RTC_BUILD_QUALITY_MEDIUM);
    rtcSetSceneFlags(tl->scene, RTC_SCENE_FLAG_COMPACT);
    tl->rocks = r;
    tl->enabled = 1;
    rtcSetGeometryUserPrimitiveCount(tl->geom, tl->n);
    rtcSetGeometryUserData(tl->geom, tl);
    nc__rt_rock_callbacks(tl->geom);
    rtcCommitGeometry(tl->geom);
    rtcAttachGeometry(tl->scene, tl->geom);
    rtcCommitScene(tl->scene);
    return 0;
}

int nc__rt_rocks_init(RTCDevice dev, const struct nc_boulder_field *f, struct nc__rt_rocks *r)
{
    memset(r, 0, sizeof *r);
    r->field = f;
    int rc = nc__rt_rock_meshes(dev, r);
    if (rc < 0)
        return rc;
    if (!(r->rock = aligned_alloc(64, (f->n ? f->n : 1) * sizeof *r->rock)))
        return nc_error(-ENOMEM, "out of memory for %zu boulders", f->n);
    float(*v)[3] = malloc((size_t)f->nshapes * MAX_CORNERS * sizeof *v);
    int *nv = malloc((size_t)f->nshapes * sizeof *nv);
    float(*ext)[3] = malloc((f->n ? f->n : 1) * sizeof *ext); /* the extents, until the trees are built */
    if (!v || !nv || !ext) {
        free(ext);
        free(v);
        free(nv);
        return nc_error(-ENOMEM, "out of memory");
    }
    for (int i = 0; i < f->nshapes; i++) {
        float(*c)[3] = v + (size_t)i * MAX_CORNERS;
        nv[i] = nc_rock_shape_corners(&f->shape[i], c, MAX_CORNERS);
        if (nv[i] < 4 || nv[i] == MAX_CORNERS) { /* not a proper solid: its box's corners bound it */
            const float *h = f->shape[i].half;
            for (int j = 0; j < 8; j++)
                c[j][0] = j & 1 ? h[0] : -h[0], c[j][1] = j & 2 ? h[1] : -h[1], c[j][2] = j & 4 ? h[2] : -h[2];
            nv[i] = 8;
        }
    }
    /* Tiles: each octave's rocks grouped by cube, in Morton order inside. */
    struct tile_key *key = malloc((f->n ? f->n : 1) * sizeof *key);
    size_t cap = 64;
    r->tile = calloc(cap, sizeof *r->tile);
    if (!key || !r->tile) {
        free(key);
        free(v);
        free(nv);
        free(ext);
        return nc_error(-ENOMEM, "out of memory for %zu boulders' tiles", f->n);
    }
    size_t at = 0;
    for (int k = 0; k < f->noctaves && rc == 0; k++) {
        const struct nc_boulder_octave *oc = &f->octave[k];
        const double S = tile_size_m(oc->j);
        for (size_t i = 0; i < oc->n; i++) {
            const double *c = f->rock[oc->first + i].centre_m, far = fmax(fabs(c[0]), fmax(fabs(c[1]), fabs(c[2])));
            if (!(far / S < 2147483647.0)) {
                rc = nc_error(NC_ERANGE, "boulder %zu lies %g m from the body's origin: too far for rocks of %g m",
                              oc->first + i, far, 2 * f->rock[oc->first].half_m);
                break;
            }
            struct tile_key *q = &key[i];
            *q = (struct tile_key){0, (int32_t)floor(c[0] / S), (int32_t)floor(c[1] / S), (int32_t)floor(c[2] / S),
                                   (uint32_t)(oc->first + i)};
            q->morton = morton(c, &q->x, S);
        }
        if (rc)
            break;
        qsort(key, oc->n, sizeof *key, key_cmp);
        for (size_t i = 0; i < oc->n && rc == 0;) {
            size_t e = i;
            while (e < oc->n && key[e].x == key[i].x && key[e].y == key[i].y && key[e].z == key[i].z)
                e++;
            if (r->ntiles == cap) {
                struct nc__rt_rock_tile *t = realloc(r->tile, 2 * cap * sizeof *t);
                if (!t) {
                    rc = nc_error(-ENOMEM, "out of memory for boulder tiles");
                    break;
                }
                memset(t + cap, 0, cap * sizeof *t);
                r->tile = t, cap *= 2;
            }
            struct nc__rt_rock_tile *tl = &r->tile[r->ntiles++];
            /* the records are relative to the middle of the tile's rocks, not of
             * its cube (up to 0.87 S from them: 1 mm of float error on a 28 km
             * cube), so they carry 6e-8 of the rocks' spread */
            for (int c = 0; c < 3; c++) {
                double lo = INFINITY, hi = -INFINITY;
                for (size_t q = i; q < e; q++) {
                    lo = fmin(lo, f->rock[key[q].rock].centre_m[c]);
                    hi = fmax(hi, f->rock[key[q].rock].centre_m[c]);
                }
                tl->origin_m[c] = 0.5 * (lo + hi);
            }
            tl->octave = k;
            tl->ext = ext + at;
            tl->rec = r->rock + at;
            tl->n = (unsigned)(e - i);
            for (size_t q = i; q < e; q++, at++) {
                const uint32_t id = key[q].rock;
                const struct nc_boulder *b = &f->rock[id];
                record(b, v + (size_t)b->shape * MAX_CORNERS, nv[b->shape], &r->rock[at], ext[at]);
                r->rock[at].rank = id;
                for (int c = 0; c < 3; c++)
                    r->rock[at].c[c] = (float)(b->centre_m[c] - tl->origin_m[c]);
            }
            i = e;
        }
    }
    free(key);
    free(v);
    free(nv);
    for (size_t t = 0; t < r->ntiles && rc == 0; t++)
        rc = make_tile(dev, r, &r->tile[t]);
    for (size_t t = 0; t < r->ntiles; t++)
        r->tile[t].ext = NULL;
    free(ext);
    r->traced = f->n;
    return rc;
}

int nc__rt_rocks_attach(struct nc__rt_rocks *r, RTCDevice dev, RTCScene top, RTCScene solo)
{
    for (size_t t = 0; t < r->ntiles; t++) {
        struct nc__rt_rock_tile *tl = &r->tile[t];
        if (!(tl->inst = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_INSTANCE)) ||
            !(tl->inst_solo = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_INSTANCE)))
            return nc_error(NC_ERENDER, "embree: cannot create a boulder tile's instance");
        rtcSetGeometryInstancedScene(tl->inst, tl->scene);
        rtcSetGeometryInstancedScene(tl->inst_solo, tl->scene);
        tl->inst_id = rtcAttachGeometry(top, tl->inst);
        rtcAttachGeometryByID(solo, tl->inst_solo, tl->inst_id);
    }
    return 0;
}

void nc__rt_rocks_cut(struct nc__rt_rocks *r, double min_d_m)
{
    if (min_d_m == r->min_d_m)
        return;
    r->min_d_m = min_d_m;
    size_t traced = nc_boulders_at_least(r->field, min_d_m);
    if (traced != r->traced)
        r->cut_cover = nc_boulders_cover(r->field, traced);
    r->traced = traced;
    for (size_t t = 0; t < r->ntiles; t++) {
        struct nc__rt_rock_tile *tl = &r->tile[t];
        const struct nc_boulder_octave *oc = &r->field->octave[tl->octave];
        int on = 2.0 * r->field->rock[oc->first].half_m >= min_d_m; /* its octave's largest rock */
        if (on != tl->enabled) {
            (on ? rtcEnableGeometry : rtcDisableGeometry)(tl->inst);
            (on ? rtcEnableGeometry : rtcDisableGeometry)(tl->inst_solo);
            tl->enabled = on;
        }
    }
}

void nc__rt_rocks_place(struct nc__rt_rocks *r, const struct nc_mat3 *R, struct nc_vec3 origin_rel)
{
    float xfm[12];
    for (int c = 0; c < 3; c++)
        for (int i = 0; i < 3; i++)
            xfm[3 * c + i] = (float)R->m[i][c];
    for (size_t t = 0; t < r->ntiles; t++) {
        struct nc__rt_rock_tile *tl = &r->tile[t];
        if (!tl->enabled)
            continue;
        const struct nc_vec3 T =
            nc_v3_add(nc_mat_mul_v(R, nc_v3(tl->origin_m[0], tl->origin_m[1], tl->origin_m[2])), origin_rel);
        xfm[9] = tl->place_m[0] = (float)T.x, xfm[10] = tl->place_m[1] = (float)T.y;
        xfm[11] = tl->place_m[2] = (float)T.z;
        const struct nc_vec3 cam = nc_mat_tmul_v(R, nc_v3_scale(T, -1)); /* R^T (camera - tile origin) */
        tl->cam_m[0] = (float)cam.x, tl->cam_m[1] = (float)cam.y, tl->cam_m[2] = (float)cam.z;
        rtcSetGeometryTransform(tl->inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
        rtcCommitGeometry(tl->inst);
        rtcSetGeometryTransform(tl->inst_solo, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
        rtcCommitGeometry(tl->inst_solo);
    }
}

struct inside_query {
    const struct nc__rt_rock_tile *tl;
    long rank;
};

/* A rock whose box holds the point: is the point within its planes? */
static bool inside_rock(struct RTCPointQueryFunctionArguments *a)
{
    struct inside_query *u = a->userPtr;
    const struct nc__rt_rock *k = &u->tl->rec[a->primID];
    const struct nc__rt_rocks *r = u->tl->rocks;
    if (k->rank >= r->traced)
        return false;
    const struct nc_rock_shape *sh = &r->field->shape[k->shape];
    const float rel[3] = {a->query->x - k->c[0], a->query->y - k->c[1], a->query->z - k->c[2]};
    float p[3];
    for (int j = 0; j < 3; j++)
        p[j] = k->M[3 * j] * rel[0] + k->M[3 * j + 1] * rel[1] + k->M[3 * j + 2] * rel[2];
    for (int g = 0; g < sh->nplanes; g++)
        if (sh->nx[g] * p[0] + sh->ny[g] * p[1] + sh->nz[g] * p[2] > sh->d[g])
            return false;
    if (u->rank < 0 || (long)k->rank < u->rank)
        u->rank = (long)k->rank;
    return false;
}

long nc__rt_rocks_camera_inside(const struct nc__rt_rocks *r)
{
    struct inside_query u = {.rank = -1};
    for (size_t t = 0; t < r->ntiles; t++) {
        if (!r->tile[t].enabled)
            continue;
        u.tl = &r->tile[t];
        struct RTCPointQuery q = {.x = u.tl->cam_m[0], .y = u.tl->cam_m[1], .z = u.tl->cam_m[2], .radius = 0};
        struct RTCPointQueryContext ctx;
        rtcInitPointQueryContext(&ctx);
        rtcPointQuery(u.tl->scene, &q, &ctx, inside_rock, &u);
    }
    return u.rank;
}

void nc__rt_rocks_free(struct nc__rt_rocks *r)
{
    for (size_t t = 0; t < r->ntiles; t++) {
        struct nc__rt_rock_tile *tl = &r->tile[t];
        if (tl->inst)
            rtcReleaseGeometry(tl->inst);
        if (tl->inst_solo)
            rtcReleaseGeometry(tl->inst_solo);
        if (tl->geom)
            rtcReleaseGeometry(tl->geom);
        if (tl->scene)
            rtcReleaseScene(tl->scene);
    }
    nc__rt_rock_meshes_free(r);
    free(r->tile);
    free(r->rock);
    memset(r, 0, sizeof *r);
}
