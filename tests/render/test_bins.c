/* test_bins.c - camera rays through binned triangles (render/rt_bins.h)
 * against Embree: the same first hits, ranges and normals ray by ray on
 * procedural asteroids (flat, smooth with albedo variation, two bodies), a
 * grid whose lines run through the pixel centres (no ray slips between
 * triangles), the AVX-512 and plain tests and list builds bit for bit, clusters of
 * triangles skipped whole without changing the lists, the cases the bins
 * refuse, and whole frames; with boulders, the rocks' bins against
 * Embree's trees, and a block's packets through them together and one at
 * a time bit for bit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/camera.h"
#include "render/rt.h"
#include "render/rt_bins.h"
#include "testutil.h"

static uint64_t rng = 88172645463325252ull;
static double uni(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) * 0x1p-53;
}

static struct nc_rt_pinhole pinhole_of(const struct nc_camera *c)
{
    const struct nc_mat3 R = nc_quat_to_mat(c->attitude_q);
    return (struct nc_rt_pinhole){nc_v3(0, 0, 0), nc_mat_mul_v(&R, nc_camera_dir(c, 0, 0)),
                                  nc_mat_mul_v(&R, nc_v3(1.0 / c->fx_px, 0, 0)),
                                  nc_mat_mul_v(&R, nc_v3(0, 1.0 / c->fy_px, 0)), c->width_px, c->height_px, 4};
}

/* Packet q of block (px0, py0): lane i is pixel (i & 3, i >> 2) of it, at a
 * random point of the pixel (or its centre). */
static void block_rays(const struct nc_rt_pinhole *p, int px0, int py0, int centre, struct nc_ray16 *r)
{
    for (int i = 0; i < NC_PACKET; i++) {
        const int px = px0 + (i & 3), py = py0 + (i >> 2);
        const double x = px + (centre ? 0 : uni() - 0.5), y = py + (centre ? 0 : uni() - 0.5);
        const struct nc_vec3 d = nc_v3_unit(nc_v3_add(p->d00, nc_v3_add(nc_v3_scale(p->ex, x), nc_v3_scale(p->ey, y))));
        r->ox[i] = (float)p->o.x, r->oy[i] = (float)p->o.y, r->oz[i] = (float)p->o.z;
        r->dx[i] = (float)d.x, r->dy[i] = (float)d.y, r->dz[i] = (float)d.z;
        r->tnear[i] = 0.0f;
        r->tfar[i] = INFINITY;
        r->valid[i] = px < p->width_px && py < p->height_px ? -1 : 0;
    }
}

struct agree {
    long rays, hits, differ, body, facet; /* facet: hits whose normals differ by over 1e-3 rad (another facet) */
    double t_rel, n_rad, albedo;
};

/* Every block of the scene's image, 4 packets of random samples each
 * (centres with centre), through Embree and the bins. */
static struct agree compare_rays(const struct nc_scene *s, int centre, const char *what)
{
    struct nc_rt *rt;
    struct agree a = {0};
    CHECK(nc_rt_create(s, 1, &rt) == 0, "%s: nc_rt_create", what);
    const struct nc_rt_pinhole p = pinhole_of(&s->camera);
    CHECK(nc_rt_bin_camera(rt, &p, NULL, 1) == 1, "%s: the bins refuse the pinhole", what);
    for (int py0 = 0; py0 < p.height_px; py0 += 4)
        for (int px0 = 0; px0 < p.width_px; px0 += 4) {
            struct nc_ray16 r[4];
            struct nc_hit16 he, hb[4];
            for (int q = 0; q < 4; q++)
                block_rays(&p, px0, py0, centre, &r[q]);
            nc_rt_intersect_block(rt, px0, py0, r, hb, 4);
            for (int q = 0; q < 4; q++) {
                nc_rt_intersect16(rt, &r[q], &he, 1);
                const struct nc_hit16 *h = &hb[q];
                for (int i = 0; i < NC_PACKET; i++) {
                    if (!r[q].valid[i])
                        continue;
                    a.rays++;
                    if ((he.body[i] < 0) != (h->body[i] < 0)) {
                        a.differ++;
                        continue;
                    }
                    if (he.body[i] < 0)
                        continue;
                    a.hits++;
                    a.body += he.body[i] != h->body[i];
                    a.t_rel = fmax(a.t_rel, fabs(h->t[i] / he.t[i] - 1));
                    struct nc_vec3 ne = nc_v3_unit(nc_v3(he.nx[i], he.ny[i], he.nz[i])),
                                   nb = nc_v3_unit(nc_v3(h->nx[i], h->ny[i], h->nz[i]));
                    const double dn = nc_v3_norm(nc_v3_sub(ne, nb));
                    if (dn > 1e-3)
                        a.facet++;
                    else
                        a.n_rad = fmax(a.n_rad, dn);
                    a.albedo = fmax(a.albedo, fabs(h->albedo[i] - he.albedo[i]));
                }
            }
        }
    nc_rt_destroy(rt);
    printf("%s: %ld rays, %ld hits; hit or miss differ %ld, body %ld, facet %ld; range within %.2g, normal %.2g rad "
           "(same facet), albedo %.2g\n",
           what, a.rays, a.hits, a.differ, a.body, a.facet, a.t_rel, a.n_rad, a.albedo);
    CHECK(a.hits > a.rays / 4, "%s: %ld hits of %ld rays", what, a.hits, a.rays);
    /* a ray decides differently only within float precision of a limb */
    CHECK(a.differ <= a.rays / 20000, "%s: %ld of %ld rays hit in one and miss in the other", what, a.differ, a.rays);
    CHECK(a.body == 0, "%s: %ld hits on different bodies", what, a.body);
    /* Embree's float ranges and facets, anchor-relative, against the bins' */
    CHECK(a.t_rel < 2e-6, "%s: ranges differ by %.3g", what, a.t_rel);
    /* Another facet only for a ray within float precision of a shared edge
     * (an exact tie may go either way). The same facet's normal: the bins'
     * from the double vertices, Embree's from float vertices relative to
     * the ray's origin (6 km: 5e-4 m, 1e-4 rad on a 7 m facet). */
    CHECK(a.facet <= a.hits / 10000, "%s: %ld of %ld hits on another facet", what, a.facet, a.hits);
    CHECK(a.n_rad < 1e-3, "%s: normals differ by %.3g rad", what, a.n_rad);
    CHECK(a.albedo < 1e-3, "%s: albedo factors differ by %.3g", what, a.albedo);
    return a;
}

/* Whether two builds made the same lists, entry for entry. */
static int same_lists(const struct nc__bins *a, const struct nc__bins *b)
{
    const size_t n = a->start[a->nblocks];
    if (a->nblocks != b->nblocks || memcmp(a->start, b->start, (a->nblocks + 1) * sizeof *a->start) != 0)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (a->tri[a->list[i]] != b->tri[b->list[i]] ||
            memcmp(&a->cand[a->list[i]], &b->cand[b->list[i]], sizeof *a->cand) != 0)
            return 0;
    return 1;
}

/* A plane grid of n x n squares (2 triangles each) at z = 100 m seen from
 * the origin along +z, its lines through pixel centres: every ray through a
 * centre lies on an edge or a vertex, and each must still hit. The test in
 * AVX-512 registers (where the CPU has them) and in plain C agree bit for bit. */
static void check_grid(void)
{
    enum { n = 32, W = 4 * n + 8 };
    const double z = 100.0, f = 1000.0; /* focal length, px: a square is 4 px wide */
    double *v = malloc(3 * (n + 1) * (n + 1) * sizeof *v);
    unsigned *tri = malloc(6 * n * n * sizeof *tri);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            double *p = &v[3 * (j * (n + 1) + i)];
            p[0] = (4.0 * i + 4 - W / 2.0) * z / f; /* pixel x = 4 i + 4 */
            p[1] = (4.0 * j + 4 - W / 2.0) * z / f;
            p[2] = z;
        }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            unsigned a = (unsigned)(j * (n + 1) + i), b = a + 1, c = a + n + 1, d = c + 1, *t = &tri[6 * (j * n + i)];
            /* alternate diagonals, both windings: an open surface (both sides listed) */
            if ((i + j) % 2)
                t[0] = a, t[1] = b, t[2] = d, t[3] = a, t[4] = d, t[5] = c;
            else
                t[0] = a, t[1] = c, t[2] = b, t[3] = b, t[4] = c, t[5] = d;
        }
    float *ng = calloc(6 * n * n, sizeof *ng);
    struct nc__bins_body body = {.v = v, .tri = tri, .ng = ng, .nv = (n + 1) * (n + 1), .nt = 2 * n * n,
                                 .R = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, .origin = nc_v3(0, 0, 0), .front_only = 0};
    struct nc__bins_view view = {nc_v3(-W / 2.0 / f, -W / 2.0 / f, 1), nc_v3(1 / f, 0, 0), nc_v3(0, 1 / f, 0), W, W};
    const struct nc_rt_pinhole p = {nc_v3(0, 0, 0), view.d00, view.ex, view.ey, W, W, 1};
    struct nc__bins b;
    memset(&b, 0, sizeof b);
    CHECK(nc__bins_build(&b, &view, &body, 1, NULL, 3) == 1, "grid: bins built");
    long inside = 0, hit = 0, bad_t = 0, differ = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int py0 = 0; py0 < W; py0 += 4)
            for (int px0 = 0; px0 < W; px0 += 4) {
                struct nc_ray16 r[4];
                int32_t s1[4][NC_PACKET], s2[4][NC_PACKET];
                float t1[4][NC_PACKET], t2[4][NC_PACKET];
                for (int q = 0; q < 4; q++)
                    block_rays(&p, px0, py0, pass == 0, &r[q]);
                const int keep = b.avx512;
                nc__bins_intersect(&b, px0, py0, r, 4, s1, t1);
                b.avx512 = 0;
                nc__bins_intersect(&b, px0, py0, r, 4, s2, t2);
                b.avx512 = keep;
                differ += memcmp(s1, s2, sizeof s1) != 0 || memcmp(t1, t2, sizeof t1) != 0;
                for (int q = 0; q < 4; q++)
                    for (int i = 0; i < NC_PACKET; i++) {
                        const double x = r[q].dx[i] / r[q].dz[i] * f, y = r[q].dy[i] / r[q].dz[i] * f; /* from the centre */
                        /* well inside the grid's image (pixels 4 .. 4 n + 4 from the left) */
                        if (fabs(x) > 2.0 * n - 0.5 || fabs(y) > 2.0 * n - 0.5)
                            continue;
                        inside++;
                        hit += s1[q][i] >= 0;
                        bad_t += s1[q][i] >= 0 && fabs(t1[q][i] * r[q].dz[i] / z - 1) > 1e-6;
                    }
            }
    printf("grid: %ld rays inside (half through centres on its lines), %ld hit, %ld ranges off, AVX-512 %s (%ld "
           "blocks differ)\n",
           inside, hit, bad_t, b.avx512 ? "compared" : "absent", differ);
    CHECK(inside > 30000 && hit == inside, "grid: %ld of %ld rays slipped through", inside - hit, inside);
    CHECK(bad_t == 0, "grid: %ld ranges off", bad_t);
    CHECK(differ == 0, "grid: AVX-512 and plain tests differ in %ld blocks", differ);
    struct nc__bins bp; /* both sides listed: the plain setup's lists */
    memset(&bp, 0, sizeof bp);
    bp.plain = 1;
    CHECK(nc__bins_build(&bp, &view, &body, 1, NULL, 3) == 1 && same_lists(&b, &bp),
          "grid: the AVX-512 and plain setups make different lists");
    nc__bins_free(&bp);
    /* A triangle across the plane of the origin parallel to the image: refused. */
    body.origin = nc_v3(0, 0, -z);
    CHECK(nc__bins_build(&b, &view, &body, 1, NULL, 1) == 1, "grid in the plane of the origin: wholly behind it");
    body.origin = nc_v3(0, 0, -z + 0.1);
    double *tilt = malloc(3 * (n + 1) * (n + 1) * sizeof *tilt);
    for (int k = 0; k < (n + 1) * (n + 1); k++)
        tilt[3 * k] = v[3 * k], tilt[3 * k + 1] = v[3 * k + 1], tilt[3 * k + 2] = z + v[3 * k + 1];
    body.v = tilt;
    CHECK(nc__bins_build(&b, &view, &body, 1, NULL, 1) == 0, "grid across the plane of the origin: refused");
    nc__bins_free(&b);
    free(tilt);
    free(v);
    free(tri);
    free(ng);
}

/* Clusters skipped whole (outside the image, or facing away) lose no
 * listed triangle: the lists with and without them are the same entry for
 * entry, from views where they skip most of the mesh (min_skip: the share
 * of clusters at least skipped). The triangle setup in AVX-512 registers
 * (where the CPU has them) and in plain C make the same lists too. */
static void check_clusters(const struct nc_scene *s, double min_skip, const char *what)
{
    const struct nc_mesh *m = &s->body[0].mesh;
    const struct nc_rt_pinhole p = pinhole_of(&s->camera);
    const struct nc__bins_view view = {p.d00, p.ex, p.ey, p.width_px, p.height_px};
    const size_t ncl = (m->nt + NC_BINS_CLUSTER - 1) / NC_BINS_CLUSTER;
    struct nc__bins_cluster *cl = malloc(ncl * sizeof *cl);
    float *ng = calloc(3 * m->nt, sizeof *ng);
    nc__bins_facets(m->v, m->tri, m->nt, ng, cl);
    struct nc__bins_body body = {.v = m->v, .tri = m->tri, .ng = ng, .nv = m->nv, .nt = m->nt,
                                 .R = nc_quat_to_mat(s->body[0].attitude_q),
                                 .origin = nc_v3_sub(s->body[0].position_m, s->camera.position_m), .front_only = 1};
    struct nc__bins all, some, plain;
    memset(&all, 0, sizeof all);
    memset(&some, 0, sizeof some);
    memset(&plain, 0, sizeof plain);
    plain.plain = 1;
    CHECK(nc__bins_build(&all, &view, &body, 1, NULL, 2) == 1, "%s: bins without clusters", what);
    body.cl = cl;
    CHECK(nc__bins_build(&some, &view, &body, 1, NULL, 3) == 1, "%s: bins with clusters", what);
    CHECK(nc__bins_build(&plain, &view, &body, 1, NULL, 3) == 1, "%s: bins in plain C", what);
    size_t live = 0;
    for (size_t k = 0; k < ncl; k++)
        live += some.cl_live[k];
    const int same = same_lists(&all, &some), simd = same_lists(&some, &plain);
    printf("%s: %zu of %zu clusters skipped, %u list entries, %s; AVX-512 setup %s\n", what, ncl - live, ncl,
           some.start[some.nblocks], same ? "the same lists" : "lists differ",
           !some.avx512 ? "absent" : simd ? "and plain C: the same lists" : "and plain C: lists differ");
    CHECK(same, "%s: the clusters change the lists", what);
    CHECK(simd, "%s: the AVX-512 and plain setups make different lists", what);
    CHECK(ncl - live >= min_skip * ncl, "%s: only %zu of %zu clusters skipped", what, ncl - live, ncl);
    nc__bins_free(&all);
    nc__bins_free(&some);
    nc__bins_free(&plain);
    free(cl);
    free(ng);
}

/* Whole frames: bins and Embree give the same image to float precision.
 * With boulders, the bins' mesh hits and the rocks traced alone in front of
 * them (rt_embree.c rocks_over) against Embree over both: the same rock in
 * every pixel but a few at the rocks' edges. */
static void check_frames(const struct nc_scene *s, int rock_bins)
{
    struct nc_frame a, b;
    struct nc_renderer ra, rb;
    nc_renderer_init(&ra, s, 2);
    nc_renderer_init(&rb, s, 2);
    rb.no_bins = 1;
    const size_t n = (size_t)s->camera.width_px * s->camera.height_px;
    nc_frame_alloc(&a, s->camera.width_px, s->camera.height_px);
    nc_frame_alloc(&b, s->camera.width_px, s->camera.height_px);
    const int rocky = s->body[0].boulders.n > 0;
    if (rocky) {
        a.rock_id = malloc(n * sizeof *a.rock_id);
        b.rock_id = malloc(n * sizeof *b.rock_id);
    }
    CHECK(nc_render_frame(&ra, s, &a) == 0 && nc_render_frame(&rb, s, &b) == 0, "frames");
    if (rocky) {
        /* whether the rocks' own bins served the camera rays: their lists
         * tell a block with nothing in it (else -1) */
        int told = 1;
        for (int y = 0; y < s->camera.height_px; y += 4)
            for (int x = 0; x < s->camera.width_px; x += 4)
                told &= nc_rt_block_listed(ra.rt, x, y) >= 0;
        CHECK(told == rock_bins, "the rocks' bins %s the frame", told ? "served" : "did not serve");
        size_t rock = 0, other = 0;
        for (size_t i = 0; i < n; i++)
            rock += a.rock_id[i] >= 0, other += a.rock_id[i] != b.rock_id[i];
        printf("frames with boulders: %zu pixels show a rock, %zu show another than without the bins\n", rock, other);
        CHECK(rock > n / 20 && other <= rock / 1000, "%zu of %zu rock pixels differ", other, rock);
        /* The bins' packets one at a time: each lane meets the same
         * entries in the same order, whatever lanes the rocks' test packs
         * with it, so the same frame bit for bit. */
        struct nc_frame c;
        struct nc_renderer rc;
        nc_renderer_init(&rc, s, 2);
        rc.one_sample_packets = 1;
        nc_frame_alloc(&c, s->camera.width_px, s->camera.height_px);
        c.rock_id = malloc(n * sizeof *c.rock_id);
        CHECK(nc_render_frame(&rc, s, &c) == 0, "frame, one packet at a time");
        size_t differ = 0;
        for (size_t i = 0; i < n; i++)
            differ += memcmp(&a.radiance[i], &c.radiance[i], sizeof *c.radiance) != 0 || a.rock_id[i] != c.rock_id[i];
        printf("frames with boulders, the bins' packets together and one at a time: %zu pixels differ\n", differ);
        CHECK(differ == 0, "the bins' packets together and one at a time: %zu pixels differ", differ);
        nc_frame_free(&c);
        nc_renderer_free(&rc);
    }
    double sa = 0, sb = 0;
    long px = 0, cov = 0, off = 0;
    for (int i = 0; i < a.width_px * a.height_px; i++) {
        sa += a.radiance[i], sb += b.radiance[i];
        cov += a.coverage[i] != b.coverage[i];
        if (a.coverage[i] == 1 && b.coverage[i] == 1) {
            off += fabs(a.radiance[i] / b.radiance[i] - 1) > 1e-3;
            px++;
        }
    }
    /* a sample on another facet at a shared edge changes its pixel by a
     * few per cent at most; one whose shadow ray starts an ulp away, on the
     * other side of a shadow's edge, by a quarter (4 samples): a few of them
     * move a 256x256 frame's total by up to 3e-5 */
    printf("frames: %ld pixels on the body, %ld differ by over 0.1 %%, total %.3g, %ld coverages differ\n", px, off,
           sa / sb - 1, cov);
    CHECK(px > 10000 && off <= px / 1000 && fabs(sa / sb - 1) < 3e-5 && cov <= px / 10000, "frames differ");
    nc_frame_free(&a);
    nc_frame_free(&b);
    nc_renderer_free(&ra);
    nc_renderer_free(&rb);
}

int main(void)
{
    check_grid();
    /* The default scene at 256x256, the body over the whole frame (a crop at 5.5 um). */
    const char *crop[] = {"camera.width_px=256", "camera.height_px=256", "bodies.0.shape.subdivisions=6"};
    struct nc_scene s;
    nc_test_scene(nc_default_scene_yaml, crop, 3, &s);
    compare_rays(&s, 0, "default scene, 256x256 crop");
    compare_rays(&s, 1, "default scene, pixel centres");
    check_clusters(&s, 0.35, "clusters, the body in the frame (back faces)");
    check_frames(&s, 0);
    /* Smooth normals and albedo variation (the barycentric points) at 128x128, the whole body. */
    const char *smooth[] = {"camera.width_px=128", "camera.height_px=128", "camera.pixel_pitch_m=2.2e-5",
                            "bodies.0.shape.subdivisions=5", "bodies.0.shape.normals=smooth",
                            "bodies.0.albedo_variation.rms=0.3"};
    struct nc_scene s2;
    nc_test_scene(nc_default_scene_yaml, smooth, 6, &s2);
    compare_rays(&s2, 0, "smooth normals, albedo variation");
    /* A camera inside the bounding sphere (both sides of every triangle listed), 1.5 km from the centre. */
    const char *near[] = {"camera.width_px=128", "camera.height_px=128", "bodies.0.shape.subdivisions=5",
                          "camera.position_m=[0,-600,0]"};
    struct nc_scene s3;
    nc_test_scene(nc_default_scene_yaml, near, 4, &s3);
    compare_rays(&s3, 0, "camera near the surface");
    /* 1 km from the centre, turned and rolled: most of the body out of the frame. */
    const char *close[] = {"camera.width_px=200", "camera.height_px=150", "bodies.0.shape.subdivisions=6",
                           "camera.position_m=[200,-1000,300]", "camera.look_at_m=[50,0,120]",
                           "camera.up=[0.3,0,1]", "bodies.0.attitude_q=[0.9,0.1,0.3,0.3]"};
    struct nc_scene s7;
    nc_test_scene(nc_default_scene_yaml, close, 7, &s7);
    check_clusters(&s7, 0.8, "clusters, the body beyond the frame");
    /* Boulders over the crop, every one traced. */
    const char *rocks[] = {"camera.width_px=256", "camera.height_px=256", "bodies.0.shape.subdivisions=6",
                           "camera.position_m=[0,-1500,0]", "render.boulder_min_px=0",
                           "bodies.0.boulders={preset: bennu, min_diameter_m: 1}"};
    struct nc_scene s8;
    nc_test_scene(nc_default_scene_yaml, rocks, 6, &s8);
    check_frames(&s8, 1);
    /* The camera within the largest rock's bounding sphere, above its
     * centre (which may lie under the ground): the sphere's image is
     * unbounded, so the rocks' bins give way to their trees. */
    const struct nc_boulder *big = &s8.body[0].boulders.rock[0];
    const double *c = big->centre_m, up = 0.95 * big->half_m / sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    char at[96];
    snprintf(at, sizeof at, "camera.position_m=[%.6f,%.6f,%.6f]", c[0] * (1 + up), c[1] * (1 + up), c[2] * (1 + up));
    const char *inside[] = {"camera.width_px=128", "camera.height_px=128", "bodies.0.shape.subdivisions=6",
                            at, "camera.look_at_m=[0,0,0]", "bodies.0.attitude_q=[1,0,0,0]",
                            "render.boulder_min_px=0", "bodies.0.boulders={preset: bennu, min_diameter_m: 1}"};
    struct nc_scene s9;
    nc_test_scene(nc_default_scene_yaml, inside, 8, &s9);
    check_frames(&s9, 0);
    nc_scene_free(&s7);
    nc_scene_free(&s8);
    nc_scene_free(&s9);
    /* Two meshes, the small one in front of the large one. */
    static const char two[] =
        "bodies:\n"
        "  - shape: {type: asteroid, radii_m: [280, 230, 200], subdivisions: 5, seed: 7, craters: 30}\n"
        "    material: {model: lambert, A: 0.1}\n"
        "  - shape: {type: asteroid, radii_m: [60, 50, 40], subdivisions: 4, seed: 3, craters: 5}\n"
        "    material: {model: lambert, A: 0.1}\n"
        "    position_m: [100, -800, 50]\n"
        "sun: {direction: [0.643, -0.766, 0.3]}\n"
        "camera: {width_px: 128, height_px: 128, focal_length_m: 0.025, pixel_pitch_m: 2.2e-5,\n"
        "         position_m: [0, -3000, 0], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n";
    struct nc_scene s4;
    nc_test_scene(two, NULL, 0, &s4);
    struct agree a = compare_rays(&s4, 0, "two meshes");
    CHECK(a.body == 0, "two meshes: bodies differ");
    /* An analytic body (Embree's user geometry): the bins refuse the scene. */
    static const char ell[] = "bodies:\n  - shape: {type: ellipsoid, radii_m: [300, 250, 200]}\n"
                              "    material: {model: lambert, A: 0.1}\n"
                              "sun: {direction: [1, 0, 0]}\n"
                              "camera: {width_px: 64, height_px: 64, focal_length_m: 0.025, pixel_pitch_m: 2.2e-5,\n"
                              "         position_m: [0, -3000, 0], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n";
    struct nc_scene s5;
    nc_test_scene(ell, NULL, 0, &s5);
    struct nc_rt *rt;
    CHECK(nc_rt_create(&s5, 1, &rt) == 0, "ellipsoid: nc_rt_create");
    const struct nc_rt_pinhole p = pinhole_of(&s5.camera);
    CHECK(nc_rt_bin_camera(rt, &p, NULL, 1) == 0, "ellipsoid: the bins serve an analytic body");
    nc_rt_destroy(rt);
    /* 81 920 triangles in a body 11 pixels across: listing them costs more
     * than Embree's tree would on its few hundred samples. */
    const char *far[] = {"camera.width_px=64", "camera.height_px=64", "camera.pixel_pitch_m=2.2e-5",
                         "bodies.0.shape.subdivisions=6", "camera.position_m=[0,-60000,0]"};
    struct nc_scene s6;
    nc_test_scene(nc_default_scene_yaml, far, 5, &s6);
    CHECK(nc_rt_create(&s6, 1, &rt) == 0, "far: nc_rt_create");
    const struct nc_rt_pinhole pf = pinhole_of(&s6.camera);
    CHECK(nc_rt_bin_camera(rt, &pf, NULL, 1) == 0, "far: the bins list 81 920 triangles for a body 11 pixels wide");
    nc_rt_destroy(rt);
    nc_scene_free(&s6);
    nc_scene_free(&s);
    nc_scene_free(&s2);
    nc_scene_free(&s3);
    nc_scene_free(&s4);
    nc_scene_free(&s5);
    return nc_test_end();
}
