/* rt_rock_bins.c - camera rays against binned rocks (rt_rock_bins.h).
 *
 * A point q (relative to the rays' origin) lies on the ray through image
 * point (x, y) where x = (a . q) / (c . q), y = (b . q) / (c . q), a, b, c
 * the rows of the image map Mi (rt_bins.h). A sphere (centre C, radius r)
 * wholly in front (c . C > r |c|) spans the x between the two planes
 * (a - x c) . q = 0 tangent to it: ((a - x c) . C)^2 = r^2 |a - x c|^2, a
 * quadratic in x whose roots bound its image; the same for y.
 */
#include "render/rt_rock_bins.h"

#include <errno.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/grow.h"
#include "core/pool.h"

static int grow(void **p, size_t *cap, size_t n, size_t size)
{
    return nc_grow(p, cap, n, size) < 0 ? nc_error(-ENOMEM, "out of memory for %zu rock-bin entries", n) : 0;
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Rocks prim0 .. prim0 + n - 1 (n <= BATCH) of tile k (the build's
 * numbering), enabled: each one's pixels px[0..1][j] x px[2..3][j] and
 * nearest s; st[j] 1 if listed, 0 if not (below the cut, outside the
 * image, behind the origin), -1 if its sphere crosses the plane through
 * the origin parallel to the image. Branch-free loops over the batch that
 * the compiler vectorises (the clones' registers): the same operations
 * lane by lane, so the same bits on every path. */
#define BATCH 16
static inline __attribute__((always_inline)) void
rock_pixels(const struct nc__rock_bins *rb, size_t k, size_t prim0, int n, int (*px)[BATCH], float *s_near, int *st)
{
    const struct nc__rt_rock_tile *tl = rb->tile[k];
    const struct nc__rt_rocks *r = tl->rocks;
    const float *R = rb->rot[rb->tile_body[k]];
    const double *u = rb->view->Mi[0], *v = rb->view->Mi[1], *c = rb->view->Mi[2], pad = rb->view->pad_px;
    const double cc = dot3(c, c), cn = sqrt(cc), uc = dot3(u, c), uu = dot3(u, u), vc = dot3(v, c),
                 vv = dot3(v, v), W = rb->view->bw * NC_BINS_BLOCK - 1, H = rb->view->bh * NC_BINS_BLOCK - 1;
    double Cx[BATCH], Cy[BATCH], Cz[BATCH], h2[BATCH], m2[BATCH];
    int live[BATCH];
    for (int j = 0; j < BATCH; j++) {
        const struct nc__rt_rock *rk = &tl->rec[prim0 + (j < n ? j : 0)];
        const float *h = r->field->shape[rk->shape].half;
        live[j] = j < n && rk->rank < r->traced;
        double C[3];
        for (int i = 0; i < 3; i++)
            C[i] = (double)tl->place_m[i] - rb->o[i] + (double)R[3 * i] * rk->c[0] + (double)R[3 * i + 1] * rk->c[1] +
                   (double)R[3 * i + 2] * rk->c[2];
        Cx[j] = C[0], Cy[j] = C[1], Cz[j] = C[2];
        h2[j] = (double)h[0] * h[0] + (double)h[1] * h[1] + (double)h[2] * h[2];
        m2[j] = (double)rk->M[0] * rk->M[0] + (double)rk->M[1] * rk->M[1] + (double)rk->M[2] * rk->M[2];
    }
#pragma GCC unroll 1
    for (int j = 0; j < BATCH; j++) {
        const double X = Cx[j], Y = Cy[j], Z = Cz[j];
#define DOT(w) ((w)[0] * X + (w)[1] * Y + (w)[2] * Z)
        /* the test's sphere (rt_rocks.c rock_hit: 1.01 in its square), and more */
        const double r_m = 1.01 * sqrt(h2[j] / m2[j]) + 1e-6 * sqrt(X * X + Y * Y + Z * Z), ga = DOT(c);
        const double lo_s = ga - r_m * cn, r2 = r_m * r_m, D = ga * ga - r2 * cc;
        /* the image spans along u and v: the roots of the tangent planes' quadratics */
        const double au = DOT(u), Bu = au * ga - r2 * uc, du = Bu * Bu - D * (au * au - r2 * uu);
        const double av = DOT(v), Bv = av * ga - r2 * vc, dv = Bv * Bv - D * (av * av - r2 * vv);
#undef DOT
        const double su = sqrt(du > 0 ? du : 0), sv = sqrt(dv > 0 ? dv : 0);
        /* pixels a sample of which can fall in the spans padded by pad
         * (pixel centres at integers, samples within half a pixel) */
        const double x0 = ceil((Bu - su) / D - pad - 0.5), x1 = floor((Bu + su) / D + pad + 0.5),
                     y0 = ceil((Bv - sv) / D - pad - 0.5), y1 = floor((Bv + sv) / D + pad + 0.5);
        const int in = (x0 <= x1) & (x0 <= W) & (x1 >= 0) & (y0 <= y1) & (y0 <= H) & (y1 >= 0);
        const int behind = ga + r_m * cn <= 0, straddle = !behind & (lo_s <= 1e-9 * r_m * cn);
        st[j] = (!live[j]) | behind ? 0 : straddle ? -1 : in;
        /* clipped to the image (a NaN to its edge: it is not listed) before the conversions */
        const double xa = x0 < W ? x0 : W, xb = x1 < W ? x1 : W, ya = y0 < H ? y0 : H, yb = y1 < H ? y1 : H;
        px[0][j] = (int)(xa > 0 ? xa : 0);
        px[1][j] = (int)(xb > 0 ? xb : 0);
        px[2][j] = (int)(ya > 0 ? ya : 0);
        px[3][j] = (int)(yb > 0 ? yb : 0);
        s_near[j] = (float)(lo_s * (1 - 1e-6));
    }
}

static size_t part_begin(size_t n, int p, int nparts) { return n * (size_t)p / (size_t)nparts; }

enum { PHASE_COUNT, PHASE_FILL };

/* Part p's rocks: counted into its blocks, or entered at its cursors. */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void part(struct nc__rock_bins *rb, int p)
{
    const size_t total = rb->tile_first[rb->ntiles], g0 = part_begin(total, p, rb->nparts),
                 g1 = part_begin(total, p + 1, rb->nparts);
    const int bw = rb->view->bw;
    uint32_t *cnt = rb->count + (size_t)p * rb->view->nblocks;
    size_t k = 0;
    while (k + 1 < rb->ntiles && rb->tile_first[k + 1] <= g0)
        k++;
    for (size_t g = g0; g < g1;) {
        while (g >= rb->tile_first[k + 1])
            k++;
        if (!rb->tile[k]->enabled) { /* an octave wholly below the cut */
            g = rb->tile_first[k + 1];
            continue;
        }
        /* a batch within the tile and the part */
        const size_t prim0 = g - rb->tile_first[k], end = rb->tile_first[k + 1] < g1 ? rb->tile_first[k + 1] : g1;
        const int n = end - g < BATCH ? (int)(end - g) : BATCH;
        int px[4][BATCH], st[BATCH];
        float s_near[BATCH];
        rock_pixels(rb, k, prim0, n, px, s_near, st);
        g += (size_t)n;
        for (int j = 0; j < n; j++) {
            if (st[j] < 0) {
                atomic_store(&rb->straddle, 1);
                return;
            }
            if (!st[j])
                continue;
            for (int by = px[2][j] / NC_BINS_BLOCK; by <= px[3][j] / NC_BINS_BLOCK; by++)
                for (int bx = px[0][j] / NC_BINS_BLOCK; bx <= px[1][j] / NC_BINS_BLOCK; bx++) {
                    uint32_t *c = &cnt[(size_t)by * (size_t)bw + (size_t)bx];
                    if (rb->phase == PHASE_COUNT) {
                        ++*c;
                        continue;
                    }
                    const int x0 = px[0][j] > bx * 4 ? px[0][j] - bx * 4 : 0,
                              x1 = px[1][j] < bx * 4 + 3 ? px[1][j] - bx * 4 : 3;
                    const int y0 = px[2][j] > by * 4 ? px[2][j] - by * 4 : 0,
                              y1 = px[3][j] < by * 4 + 3 ? px[3][j] - by * 4 : 3;
                    const unsigned row = (2u << x1) - (1u << x0);
                    unsigned lanes = 0;
                    for (int y = y0; y <= y1; y++)
                        lanes |= row << 4 * y;
                    rb->list[(*c)++] =
                        (struct nc__rock_entry){(uint32_t)(prim0 + (size_t)j), (uint16_t)k, (uint16_t)lanes, s_near[j]};
                }
        }
    }
}

static void *worker(void *arg)
{
    struct nc__rock_bins *rb = arg;
    for (int p; (p = atomic_fetch_add(&rb->next, 1)) < rb->nparts;)
        part(rb, p);
    return NULL;
}

static void run(struct nc__rock_bins *rb, struct nc_pool *pool, int phase)
{
    rb->phase = phase;
    atomic_store(&rb->next, 0);
    nc_pool_run(pool, worker, rb);
}

int nc__rock_bins_build(struct nc__rock_bins *rb, const struct nc__bins *view, struct nc_vec3 o,
                        const struct nc__rock_bins_body *bodies, int nbodies, struct nc_pool *pool, int nparts)
{
    rb->view = view;
    rb->nparts = nparts < 1 ? 1 : nparts;
    rb->o[0] = o.x, rb->o[1] = o.y, rb->o[2] = o.z;
    for (int i = 0; i < 3; i++)
        rb->s_of[i] = (float)view->Mi[2][i];
    size_t nt = 0;
    for (int b = 0; b < nbodies; b++)
        nt += bodies[b].rocks ? bodies[b].rocks->ntiles : 0;
    if (nt > UINT16_MAX + 1u || nbodies > NC_MAX_BODIES)
        return 0;
    free(rb->tile);
    free(rb->tile_body);
    free(rb->tile_first);
    rb->tile = malloc((nt + 1) * sizeof *rb->tile);
    rb->tile_body = malloc((nt + 1) * sizeof *rb->tile_body);
    rb->tile_first = malloc((nt + 1) * sizeof *rb->tile_first);
    if (!rb->tile || !rb->tile_body || !rb->tile_first)
        return nc_error(-ENOMEM, "out of memory for the rocks' camera-ray bins");
    rb->ntiles = 0;
    rb->tile_first[0] = 0;
    for (int b = 0; b < nbodies; b++) {
        const float *R = bodies[b].rot;
        memcpy(rb->rot[b], R, sizeof rb->rot[b]);
        for (int j = 0; j < 3; j++)
            rb->o_body[b][j] = (float)(R[j] * o.x + R[3 + j] * o.y + R[6 + j] * o.z);
        for (size_t t = 0; bodies[b].rocks && t < bodies[b].rocks->ntiles; t++) {
            const struct nc__rt_rock_tile *tl = &bodies[b].rocks->tile[t];
            rb->tile[rb->ntiles] = tl;
            rb->tile_body[rb->ntiles] = (uint8_t)b;
            rb->tile_first[rb->ntiles + 1] = rb->tile_first[rb->ntiles] + tl->n;
            rb->ntiles++;
        }
    }
    if (!rb->ntiles)
        return 0;
    const size_t nb = view->nblocks;
    int rc;
    if ((rc = grow((void **)&rb->count, &rb->count_cap, (size_t)rb->nparts * nb, sizeof *rb->count)) < 0 ||
        (rc = grow((void **)&rb->start, &rb->start_cap, nb + 1, sizeof *rb->start)) < 0)
        return rc;
    memset(rb->count, 0, (size_t)rb->nparts * nb * sizeof *rb->count);
    atomic_store(&rb->straddle, 0);
    run(rb, pool, PHASE_COUNT);
    if (atomic_load(&rb->straddle))
        return 0;
    /* Block k's entries: part 0's, part 1's, ... each in the rocks' order. */
    size_t total = 0;
    for (size_t k = 0; k < nb; k++) {
        rb->start[k] = (uint32_t)total;
        for (int p = 0; p < rb->nparts; p++) {
            uint32_t *c = &rb->count[(size_t)p * nb + k];
            const size_t n = *c;
            *c = (uint32_t)total;
            total += n;
        }
        if (total > UINT32_MAX)
            return 0;
    }
    rb->start[nb] = (uint32_t)total;
    if ((rc = grow((void **)&rb->list, &rb->list_cap, total ? total : 1, sizeof *rb->list)) < 0)
        return rc;
    run(rb, pool, PHASE_FILL);
    return 1;
}

/* The lanes of the group's packets (bit 16 q + i: lane i of packet q) of
 * those in m whose closest hit so far reaches s_near. A packet at a time:
 * 16-lane loops the compiler vectorises (the clones' registers), as in
 * lanes_box. */
static inline __attribute__((always_inline)) uint64_t lanes_near(const float *s_far, float s_near, uint64_t m)
{
    for (int q = 0; q < NC_BINS_GROUP; q++) {
        if (!(m >> NC_PACKET * q & 0xffff))
            continue;
        unsigned near = 0;
#pragma GCC unroll 1 /* a vectorised loop, not 16 compares */
        for (int i = 0; i < NC_PACKET; i++)
            near |= (unsigned)(s_far[NC_PACKET * q + i] >= s_near) << i;
        m &= ~((uint64_t)(~near & 0xffff) << NC_PACKET * q);
    }
    return m;
}

/* Of the lanes m, those whose ray (d: the directions in the rock's body's
 * frame) can meet the rock's box [lo, hi] (its frame, padded) in front of
 * the origin and before t, the lane's closest hit so far: ol the rays'
 * origin in the rock's frame, M the record's body -> rock map (rock_hit's).
 * The box holds the rock (its shape lies within half), a tighter bound than
 * rock_hit's first sphere: about half the lanes that pass the sphere miss
 * the box. A lane whose direction has a zero component along an axis, or
 * whose slabs give a NaN, passes. */
static inline __attribute__((always_inline)) uint64_t lanes_box(const float (*d)[NC_ROCK_BINS_LANES], const float *ol,
                                                                const float *M, const float *lo, const float *hi,
                                                                const float *t, uint64_t m)
{
    for (int q = 0; q < NC_BINS_GROUP; q++) {
        if (!(m >> NC_PACKET * q & 0xffff))
            continue;
        unsigned miss = 0;
        const float *dx = d[0] + NC_PACKET * q, *dy = d[1] + NC_PACKET * q, *dz = d[2] + NC_PACKET * q;
        const float *tq = t + NC_PACKET * q;
#pragma GCC unroll 1
        for (int i = 0; i < NC_PACKET; i++) {
            float enter = -INFINITY, leave = INFINITY;
            int zero = 0;
            for (int a = 0; a < 3; a++) {
                const float dl = M[3 * a] * dx[i] + M[3 * a + 1] * dy[i] + M[3 * a + 2] * dz[i];
                const float t0 = (lo[a] - ol[a]) / dl, t1 = (hi[a] - ol[a]) / dl;
                const float tn = t0 < t1 ? t0 : t1, tf = t0 < t1 ? t1 : t0;
                enter = tn > enter ? tn : enter;
                leave = tf < leave ? tf : leave;
                zero |= !(dl != 0) | (t0 != t0) | (t1 != t1);
            }
            miss |= (unsigned)((!zero) & ((leave < enter) | (leave < 0) | (enter > tq[i]))) << i;
        }
        m &= ~((uint64_t)(miss & 0xffff) << NC_PACKET * q);
    }
    return m;
}

/* Entry en's exact test on the lanes m, NC__RT_LANES at a time (packed
 * whatever their packets): closer hits written to the group's lanes. */
static void entry_test(const struct nc__rock_bins *rb, const struct nc__rock_entry *en, int body, uint64_t m,
                       const float (*d)[NC_ROCK_BINS_LANES], const float *tnear, const float *sd,
                       struct nc__rock_bins_hits *h, float *s_far)
{
    const struct nc__rt_rock_tile *tl = rb->tile[en->tile];
    float o[3]; /* the rays' origin in the tile's frame */
    for (int j = 0; j < 3; j++)
        o[j] = tl->cam_m[j] + rb->o_body[body][j];
    while (m) {
        struct nc__rt_lanes p;
        int lane[NC__RT_LANES], nl = 0;
        for (; m && nl < NC__RT_LANES; m &= m - 1)
            lane[nl++] = __builtin_ctzll(m);
        for (int l = 0; l < NC__RT_LANES; l++) {
            const int i = lane[l < nl ? l : 0];
            for (int j = 0; j < 3; j++) {
                p.o[j][l] = o[j];
                p.d[j][l] = d[j][i];
            }
            p.tnear[l] = tnear[i];
            p.tfar[l] = h->t[i];
            p.valid[l] = l < nl ? -1 : 0;
        }
        float th[NC__RT_LANES], nh[NC__RT_LANES][3];
        int det;
        const unsigned hits = nc__rt_rock_lanes(tl, en->prim, &p, th, nh, &det);
        for (int l = 0; l < nl; l++)
            if (hits >> l & 1) {
                const int i = lane[l];
                h->t[i] = th[l];
                s_far[i] = th[l] * sd[i];
                h->tile[i] = en->tile;
                h->prim[i] = en->prim;
                h->detailed[i] = det;
                memcpy(h->n[i], nh[l], sizeof h->n[i]);
            }
    }
}

/* The packet of the group's lane i (lanes past npk's packets read packet 0; they are off). */
static inline const struct nc_ray16 *lane_ray(const struct nc_ray16 *ray, int npk, int i)
{
    return &ray[i / NC_PACKET < npk ? i / NC_PACKET : 0];
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) void
nc__rock_bins_intersect(const struct nc__rock_bins *rb, int px0, int py0, const struct nc_ray16 *ray, int npk,
                        struct nc__rock_bins_hits *h)
{
    for (int i = 0; i < NC_ROCK_BINS_LANES; i++)
        h->tile[i] = -1;
    const size_t k = (size_t)(py0 / NC_BINS_BLOCK) * (size_t)rb->view->bw + (size_t)(px0 / NC_BINS_BLOCK);
    const uint32_t b = rb->start[k], e = rb->start[k + 1];
    if (b == e)
        return;
    /* each lane's s per unit t, and the s of its closest hit so far */
    float sd[NC_ROCK_BINS_LANES], s_far[NC_ROCK_BINS_LANES], tnear[NC_ROCK_BINS_LANES];
    uint64_t on = 0;
    for (int i = 0; i < NC_ROCK_BINS_LANES; i++) {
        const struct nc_ray16 *r = lane_ray(ray, npk, i);
        const int l = i % NC_PACKET;
        sd[i] = rb->s_of[0] * r->dx[l] + rb->s_of[1] * r->dy[l] + rb->s_of[2] * r->dz[l];
        s_far[i] = h->t[i] * sd[i];
        tnear[i] = r->tnear[l];
        on |= (uint64_t)(i / NC_PACKET < npk && r->valid[l] == -1) << i;
    }
    /* the directions in the bodies' frames, when first needed */
    float d[NC_MAX_BODIES][3][NC_ROCK_BINS_LANES];
    unsigned have = 0;
    for (uint32_t q = b; q < e; q++) {
        const struct nc__rock_entry *en = &rb->list[q];
        const uint64_t lanes = en->lanes;
        uint64_t m = on & (lanes | lanes << 16 | lanes << 32 | lanes << 48);
        if (!m || !(m = lanes_near(s_far, en->s_near, m)))
            continue;
        const struct nc__rt_rock_tile *tl = rb->tile[en->tile];
        const int body = rb->tile_body[en->tile];
        if (!(have >> body & 1)) {
            const float *R = rb->rot[body];
            for (int j = 0; j < 3; j++)
                for (int i = 0; i < NC_ROCK_BINS_LANES; i++) {
                    const struct nc_ray16 *r = lane_ray(ray, npk, i);
                    const int l = i % NC_PACKET;
                    d[body][j][i] = R[j] * r->dx[l] + R[3 + j] * r->dy[l] + R[6 + j] * r->dz[l];
                }
            have |= 1u << body;
        }
        /* the lanes whose ray meets its box before their closest hit so far
         * (padded for the float transforms: 1 % of the rock and 1e-6 of its distance) */
        const struct nc__rt_rock *rk = &tl->rec[en->prim];
        const float *hf = tl->rocks->field->shape[rk->shape].half;
        const float m2 = rk->M[0] * rk->M[0] + rk->M[1] * rk->M[1] + rk->M[2] * rk->M[2];
        float rel[3], ol[3], lo[3], hi[3];
        for (int j = 0; j < 3; j++)
            rel[j] = tl->cam_m[j] + rb->o_body[body][j] - rk->c[j];
        const float pad = 0.01f + 1e-6f * sqrtf((rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]) * m2);
        for (int a = 0; a < 3; a++) {
            ol[a] = rk->M[3 * a] * rel[0] + rk->M[3 * a + 1] * rel[1] + rk->M[3 * a + 2] * rel[2];
            lo[a] = -hf[a] - pad;
            hi[a] = hf[a] + pad;
        }
        if (!(m = lanes_box(d[body], ol, rk->M, lo, hi, h->t, m)))
            continue;
        entry_test(rb, en, body, m, d[body], tnear, sd, h, s_far);
    }
}

void nc__rock_bins_free(struct nc__rock_bins *rb)
{
    free(rb->tile);
    free(rb->tile_body);
    free(rb->tile_first);
    free(rb->count);
    free(rb->start);
    free(rb->list);
    memset(rb, 0, sizeof *rb);
}
