/* render.c - tiles, threads and shading. Hot path: one function,
 * shade_tile(); nothing here allocates per pixel or per packet. */
#include "render/render.h"

#include <errno.h>
#ifdef __SSE2__
#include <immintrin.h>
#endif
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/albedo_map.h"
#include "render/bounce.h"
#include "core/error.h"
#include "core/pool.h"
#include "core/proc.h"

#define TILE NC_TILE

int nc_frame_alloc(struct nc_frame *f, int w, int h)
{
    size_t n = (size_t)w * (size_t)h;
    memset(f, 0, sizeof *f);
    f->width_px = w;
    f->height_px = h;
    f->radiance = malloc(n * sizeof(float));
    f->iof = malloc(n * sizeof(float));
    f->range_m = malloc(n * sizeof(float));
    f->coverage = malloc(n * sizeof(float));
    if (!f->radiance || !f->iof || !f->range_m || !f->coverage) {
        nc_frame_free(f);
        return nc_error(-ENOMEM, "out of memory for a %dx%d frame", w, h);
    }
    /* Pages faulted in here, not by the first frame rendered into them: a
     * fault costs about 12 us on this project's virtual machine (core/proc.h),
     * and the four planes of a 512x512 frame with its margin take over a
     * thousand (the emulator's second render buffer made its first frame
     * 13-17 ms slower). */
    nc_touch_pages(f->radiance, n * sizeof(float));
    nc_touch_pages(f->iof, n * sizeof(float));
    nc_touch_pages(f->range_m, n * sizeof(float));
    nc_touch_pages(f->coverage, n * sizeof(float));
    return 0;
}

void nc_frame_free(struct nc_frame *f)
{
    free(f->radiance);
    free(f->iof);
    free(f->range_m);
    free(f->coverage);
    free(f->rock_id);
    free(f->geom);
    free(f->direct);
    free(f->direct_hard);
    free(f->one);
    memset(f, 0, sizeof *f);
}

int nc_renderer_init(struct nc_renderer *r, const struct nc_scene *s, int threads)
{
    memset(r, 0, sizeof *r);
    if (threads <= 0)
        threads = s->render.threads;
    if (threads <= 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        threads = n > 0 ? (int)n : 1;
    }
    r->threads = threads;
    for (int i = 0; i < NC_MAX_BODIES; i++)
        r->fold_theta_bar_deg[i] = -1;
    return nc_rt_create(s, threads, &r->rt);
}

double nc_render_fold_theta_bar_deg(const struct nc_renderer *r, int nbodies)
{
    double d = -1;
    for (int i = 0; i < nbodies; i++)
        d = fmax(d, r->fold_theta_bar_deg[i]);
    return d;
}

struct nc_frame *nc_renderer_scratch(struct nc_renderer *r, int i, int w, int h, unsigned planes)
{
    if (i < 0 || i >= NC_SCRATCH_FRAMES) {
        nc_error(NC_ERANGE, "render: scratch frame %d of %d", i, NC_SCRATCH_FRAMES);
        return NULL;
    }
    struct nc_frame *f = &r->scratch[i];
    if (f->width_px != w || f->height_px != h) {
        nc_frame_free(f);
        if (nc_frame_alloc(f, w, h) < 0)
            return NULL;
    }
    const size_t n = (size_t)w * (size_t)h;
    float **plane[3] = {&f->direct, &f->direct_hard, &f->one};
    for (int k = 0; k < 3; k++) {
        if (!(planes & 1u << k)) {
            free(*plane[k]);
            *plane[k] = NULL;
        } else if (!*plane[k] && !(*plane[k] = malloc(n * sizeof(float)))) {
            nc_error(-ENOMEM, "out of memory for a %dx%d frame", w, h);
            return NULL;
        }
    }
    return f;
}

void nc_renderer_free(struct nc_renderer *r)
{
    for (int i = 0; i < NC_SCRATCH_FRAMES; i++)
        nc_frame_free(&r->scratch[i]);
    nc_frame_free(&r->exp_sub);
    free(r->exp_sum);
    r->exp_sum = NULL;
    nc_pool_destroy(r->pool);
    r->pool = NULL;
    nc_rt_destroy(r->rt);
    r->rt = NULL;
}

/* Counter-based hash -> uniform [0,1): the jitter of sample s of pixel p
 * depends on (seed, p, s) only, never on thread or order. */
static inline uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static inline double hash01(uint64_t seed, uint64_t a, uint64_t b)
{
    uint64_t z = mix64(seed * 0x9e3779b97f4a7c15ull + mix64(a * 0xd6e8feb86659fd93ull + b + 1));
    /* (z >> 11) 2^-53 exactly, from two parts a signed 32-bit conversion
     * takes (AVX2 has no 64-bit one): the same bits, vectorised */
    return (double)(int32_t)(z >> 33) * 0x1.0p-31 + (double)(int32_t)((z >> 11) & 0x3fffff) * 0x1.0p-53;
}

/* Pixel (px, py)'s key p for the hashes: its index in the sensor's image
 * (the camera's margin_px taken off), so that a camera model's margin
 * changes no sample of the sensor's pixels; the margin's pixels apart
 * (their index in the whole image, top bit set). */
static inline uint64_t pixel_id(const struct nc_camera *c, int px, int py)
{
    const int m = c->margin_px, x = px - m, y = py - m, w = c->width_px - 2 * m, h = c->height_px - 2 * m;
    if (x >= 0 && y >= 0 && x < w && y < h)
        return (uint64_t)y * (uint64_t)w + (uint64_t)x;
    return 1ull << 63 | ((uint64_t)py * (uint64_t)c->width_px + (uint64_t)px);
}

static uint64_t gcd64(uint64_t u, uint64_t v)
{
    while (v) {
        uint64_t t = u % v;
        u = v;
        v = t;
    }
    return u;
}

/* Pixel pid's sample for slot x (0 <= x < N) of the exposure: an affine
 * permutation x -> (a x + b) mod N, a coprime to N, drawn per pixel, so
 * each sample is dealt to a uniformly random time sample. */
static int sample_of(uint64_t seed, uint64_t pid, int x, int N)
{
    if (N <= 1)
        return 0;
    const uint64_t h = mix64(seed ^ mix64(pid + 0x7065726dull)), n = (uint64_t)N; /* "perm" */
    uint64_t a = 1 + (h >> 32) % (n - 1), b = (h & 0xffffffffu) % n;
    if (x == 0)
        return (int)b;
    while (gcd64(a, n) != 1) /* a = 1 ends it */
        a = a % (n - 1) + 1;
    return (int)((a * (uint64_t)x + b) % n);
}

struct job {
    const struct nc_renderer *r;
    const struct nc_scene *s;
    struct nc_rt *rt;
    struct nc_frame *f;
    /* Per image row: the camera at that row's time (a rolling shutter exposes
     * rows at different times): origin o relative to the frame's camera
     * position, rotation R, and ray direction = d00 + x ex + y ey. */
    struct row_cam {
        struct nc_vec3 o, d00, ex, ey;
        struct nc_mat3 R;
    } *row;
    struct nc_mat3 body_R[NC_MAX_BODIES];      /* body -> scene */
    struct nc_vec3 body_rel[NC_MAX_BODIES];    /* body origin - camera, scene frame, m */
    struct nc_material mat[NC_MAX_BODIES];     /* each body's, with its rocks not traced folded in */
    int tiles_x, tiles_y, n_strata;
    struct nc_sample_pass pass; /* this time sample's share of each pixel's samples ({0, 1, S}: all) */
    int tile_row_begin, n_tile_rows; /* the rows of tiles to render: begin, begin + 1, ... */
    const int *tiles;                /* or these n_tiles tiles (not NULL) */
    int n_tiles;
    int blocks; /* 1, 2: only the 4x4 blocks of each tile on the even, odd squares of a checkerboard (nc_render_tile_list) */
    atomic_int next;
    /* Sun: constant in the scene frame unless the Sun is at a finite position. */
    struct nc_vec3 sun_dir;
    double sun_irr;
    double sun_tan_radius; /* soft shadows: tan of the Sun's angular radius (0: hard) */
    struct nc_vec3 sun_e1, sun_e2; /* axes across sun_dir, for points of the disk */
    uint64_t disk_seed;
    int bounces, roulette_after; /* indirect light (render.bounces, render.roulette_after) */
    uint64_t path_seed;          /* the bounce directions' stream */
    int cull; /* skip 4x4 blocks whose rays cannot reach any body (block_can_hit) */
    int bins; /* camera rays through nc_rt_intersect_block (a pinhole at rest over meshes) */
    int plain; /* meshes only, no albedo maps, the Sun at infinity: surface16's lanes without exceptions */
    int far[NC_MAX_BODIES];        /* shadow rays leaving the body in its far frame (nc_rt_far_frame) */
    int any_far;                   /* ... for any body */
    double far_scale[NC_MAX_BODIES]; /* ... and the scale of its float coordinates there, m */
};

/* Whether any ray of the 4x4 pixel block at (px0, py0) can reach a body's
 * bounding sphere. Conservative: every sample of pixel (x, y) lies in
 * [x - 0.5, x + 0.5] x [y - 0.5, y + 0.5] and uses its row's camera, so the
 * cone from the block's centre direction through all rows' corner directions
 * holds every ray (the rays through a rectangle of the image plane form a
 * convex set whose extreme directions are its corners). Row origins differ by
 * the camera's motion over a rolling shutter: the spheres grow by the spread.
 * A block that fails the test would only trace misses (nothing adds to the
 * pixel), so skipping it leaves the frame bit-identical. */
static int block_can_hit(const struct job *j, int px0, int py0)
{
    const struct nc_scene *s = j->s;
    const int H = s->camera.height_px, py1 = py0 + 3 < H ? py0 + 3 : H - 1;
    const struct row_cam *top = &j->row[py0];
    struct nc_vec3 corner[16];
    int nc = 0;
    double spread = 0;
    for (int py = py0; py <= py1; py++) {
        const struct row_cam *rc = &j->row[py];
        spread = fmax(spread, nc_v3_norm(nc_v3_sub(rc->o, top->o)));
        for (int k = 0; k < 4; k++) {
            double fx = px0 - 0.5 + 4.0 * (k & 1), fy = py - 0.5 + (k >> 1);
            corner[nc++] = nc_v3_unit(nc_v3_add(rc->d00, nc_v3_add(nc_v3_scale(rc->ex, fx), nc_v3_scale(rc->ey, fy))));
        }
    }
    struct nc_vec3 axis = nc_v3(0, 0, 0);
    for (int k = 0; k < nc; k++)
        axis = nc_v3_add(axis, corner[k]);
    axis = nc_v3_unit(axis);
    double cos_half = 1.0;
    for (int k = 0; k < nc; k++)
        cos_half = fmin(cos_half, nc_v3_dot(axis, corner[k]));
    /* 1e-6 rad and 1e-6 relative: the float rays Embree traces, to spare */
    double half = acos(fmax(-1.0, fmin(1.0, cos_half))) + 1e-6;
    for (int b = 0; b < s->nbodies; b++) {
        struct nc_vec3 to = nc_v3_sub(j->body_rel[b], top->o);
        double d = nc_v3_norm(to), r = s->body[b].bounding_radius_m * (1 + 1e-6) + spread;
        if (d <= r)
            return 1; /* the camera is inside the sphere */
        double ang = acos(fmax(-1.0, fmin(1.0, nc_v3_dot(axis, to) / d)));
        if (ang <= half + asin(r / d))
            return 1;
    }
    return 0;
}

/* Whether to trace the 4x4 block at (px0, py0): where the bins serve the
 * pass, their lists tell (an empty list and no rocks: every ray misses),
 * else the bounding spheres; the frame is the same either way. */
static int block_live(const struct job *j, int px0, int py0)
{
    const int listed = j->bins ? nc_rt_block_listed(j->rt, px0, py0) : -1;
    return !j->cull || (listed >= 0 ? listed : block_can_hit(j, px0, py0));
}

/* The surface points a packet's rays reached: per lane, where and how. */
struct surf {
    int body[NC_PACKET];      /* -1: none (a miss, or a float hit the exact shape refutes) */
    int outside[NC_PACKET];   /* the ray came from the outer side of the surface */
    double t[NC_PACKET];      /* ray parameter, m */
    double scale[NC_PACKET];  /* the float error's scale there, m: t, or more for a refined mesh hit */
    struct nc_vec3 p[NC_PACKET];    /* position relative to the camera, scene frame, m */
    struct nc_vec3 n[NC_PACKET];    /* unit normal, turned to face the ray's origin */
    struct nc_vec3 d[NC_PACKET];    /* the ray's unit direction */
    struct nc_vec3 sdir[NC_PACKET]; /* unit direction to the Sun's centre */
    double irr[NC_PACKET];    /* solar irradiance there, W m^-2 */
    double factor[NC_PACKET]; /* on the albedo: variation and map */
    int facet_sun[NC_PACKET]; /* 0 where a smooth shading normal lies on a facet turned away from the Sun */
    /* The frame its shadow rays go in (shadow_frames; after the arrays
     * above, which keep their 64-byte alignment): frame -1, the camera's; b,
     * body b's far frame (nc_rt_far_frame), where the point is p - rel and
     * the float error's scale escale; far: the frames of a camera ray's
     * points while some body is in a far frame (the lanes in the camera's
     * frame then have rel 0 and escale their scale), else 0, every lane in
     * the camera's frame, and rock, rel and escale not set. */
    int frame[NC_PACKET];
    int rock[NC_PACKET]; /* a rock's surface (nc_hit16.rock >= 0) */
    struct nc_vec3 rel[NC_PACKET];
    double escale[NC_PACKET];
    const uint32_t *prim; /* the triangles met (nc_hit16.prim), to refine a far frame's point */
    int far;
};

/* (x, y, z) / |(x, y, z)| into lane i of u, as nc_v3_unit does it (the
 * same operations: the same bits); branch-free, for loops the compiler
 * vectorises. */
static inline void unit_lane(double x, double y, double z, double (*u)[NC_PACKET], int i)
{
    const double len = sqrt(x * x + y * y + z * z), s = 1.0 / len;
    u[0][i] = len > 0 ? x * s : x;
    u[1][i] = len > 0 ? y * s : y;
    u[2][i] = len > 0 ? z * s : z;
}

/* The unit facet normals of a packet's hits (zero where a lane missed), in
 * AVX-512 or AVX2 where the CPU has it (this file is compiled without
 * contraction: the same bits as plain code). */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void
unit_normals(const struct nc_hit16 *hit, double (*un)[NC_PACKET])
{
    for (int i = 0; i < NC_PACKET; i++)
        unit_lane(hit->nx[i], hit->ny[i], hit->nz[i], un, i);
}

/* Whether lane i's facet faces the Sun sdir on the side the ray d meets it:
 * 1 unless the hit's normal is a smooth shading normal (the facet's beside
 * it); the light of a point on a facet turned away from the Sun is none,
 * whatever its shading normal (an outside check saw such points lit, their
 * shadow rays lifted off along the shading normal past the facet). */
static inline int facet_faces_sun(const struct nc_hit16 *hit, int i, struct nc_vec3 d, struct nc_vec3 sdir)
{
    const int smooth = (hit->fnx[i] != hit->nx[i]) | (hit->fny[i] != hit->ny[i]) | (hit->fnz[i] != hit->nz[i]);
    const double fd = hit->fnx[i] * d.x + hit->fny[i] * d.y + hit->fnz[i] * d.z,
                 fs = hit->fnx[i] * sdir.x + hit->fny[i] * sdir.y + hit->fnz[i] * sdir.z;
    return (!smooth) | (fd <= 0 ? fs > 0 : fs < 0);
}

/* surface16 where j->plain holds, in one branch-free loop (AVX-512 or AVX2
 * where the CPU has it, without contraction: the same bits as the loop lane
 * by lane). A missed lane gets body -1 and values never read. */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void
plain_lanes(const struct job *j, const struct nc_hit16 *hit, const struct nc_vec3 *orig, const struct nc_vec3 *dir,
            const double (*un)[NC_PACKET], struct surf *s)
{
    for (int i = 0; i < NC_PACKET; i++) {
        const struct nc_vec3 d = dir[i];
        const double t = s->t[i];
        struct nc_vec3 nrm = nc_v3(un[0][i], un[1][i], un[2][i]);
        const int outside = nc_v3_dot(nrm, d) <= 0;
        const double flip = outside ? 1.0 : -1.0; /* as nc_v3_scale(nrm, -1.0) */
        nrm = nc_v3(nrm.x * flip, nrm.y * flip, nrm.z * flip);
        s->body[i] = hit->body[i];
        s->outside[i] = outside;
        s->p[i] = nc_v3_add(orig[i], nc_v3_scale(d, t));
        s->n[i] = nrm;
        s->d[i] = d;
        s->sdir[i] = j->sun_dir;
        s->irr[i] = j->sun_irr;
        s->factor[i] = hit->albedo[i];
        s->facet_sun[i] = facet_faces_sun(hit, i, d, j->sun_dir);
    }
}

/* s's shadow-ray frames: a camera ray's point on the outer side of a body
 * seen from farther than a bounding radius off its bounding sphere in its
 * far frame, anything else in the camera's (a bounce ray leaves a float
 * origin relative to the camera: its point is known to 6e-8 of its
 * distance from the camera, in a far frame too, and its shadow ray must
 * start as far off as before; a camera ray on a surface's inner side is a
 * float ray that slipped through the body's near side, in the far frame
 * shut in by it: black pixels at zero phase, found by a review). The
 * float error's scale: in a far frame the body's bounding radius (every
 * coordinate of its geometry there is within it; a mesh hit is refined once
 * a ray from it is traced: occluded_in), or for a rock's hit, known to 1e-7
 * of the range, the range if larger; in the camera's, the point's. */
static void shadow_frames(const struct job *j, const struct nc_hit16 *hit, int depth, struct surf *s)
{
    s->prim = hit->prim;
    s->far = j->any_far && !depth;
    if (!s->far) { /* every lane in the camera's frame */
        memset(s->frame, 0xff, sizeof s->frame); /* -1 */
        return;
    }
    for (int i = 0; i < NC_PACKET; i++) {
        const int b = s->body[i], far = b >= 0 && s->outside[i] && j->far[b];
        s->frame[i] = far ? b : -1;
        s->rock[i] = hit->rock[i] >= 0;
        s->rel[i] = far ? j->body_rel[b] : nc_v3(0, 0, 0);
        s->escale[i] = !far ? s->scale[i] : s->rock[i] ? fmax(j->far_scale[b], s->scale[i]) : j->far_scale[b];
    }
}

/* Fill s from a packet's hits, for rays from orig along the unit dir, at
 * path vertex depth (0: the camera rays'). */
static void surface16(const struct job *j, const struct nc_hit16 *hit, const struct nc_vec3 *orig,
                      const struct nc_vec3 *dir, int depth, struct surf *s)
{
    const struct nc_scene *sc = j->s;
    double un[3][NC_PACKET];
    unit_normals(hit, un);
    for (int i = 0; i < NC_PACKET; i++)
        s->t[i] = s->scale[i] = hit->t[i];
    if (nc_rt_refine_on(j->rt))
        nc_rt_refine_mesh16(j->rt, hit, orig, dir, s->t, s->scale);
    if (j->plain) {
        plain_lanes(j, hit, orig, dir, (const double(*)[NC_PACKET])un, s);
        shadow_frames(j, hit, depth, s);
        return;
    }
    for (int i = 0; i < NC_PACKET; i++) {
        s->body[i] = hit->body[i];
        if (hit->body[i] < 0)
            continue;
        struct nc_vec3 d = dir[i], nrm;
        double t = s->t[i];
        int exact = nc_rt_refine(j->rt, hit->body[i], orig[i], d, &t, &nrm);
        if (exact < 0) { /* the float trace grazed a limb the exact shape misses */
            s->body[i] = -1;
            continue;
        }
        if (exact == 0)
            nrm = nc_v3(un[0][i], un[1][i], un[2][i]);
        else /* an analytic body's exact hit */
            s->scale[i] = t;
        s->outside[i] = nc_v3_dot(nrm, d) <= 0;
        if (!s->outside[i]) /* back face: inconsistent winding, or the ray from inside */
            nrm = nc_v3_scale(nrm, -1.0);
        struct nc_vec3 p = nc_v3_add(orig[i], nc_v3_scale(d, t));
        s->t[i] = t;
        s->p[i] = p;
        s->n[i] = nrm;
        s->d[i] = d;
        s->sdir[i] = j->sun_dir;
        s->irr[i] = j->sun_irr;
        if (sc->sun.has_position)
            nc_scene_sun_at(sc, nc_v3_add(p, sc->camera.position_m), &s->sdir[i], &s->irr[i]);
        s->facet_sun[i] = facet_faces_sun(hit, i, d, s->sdir[i]);
        double factor = hit->albedo[i]; /* albedo variation */
        const struct nc_albedo_map *am = sc->body[hit->body[i]].material.albedo_map;
        if (am) { /* at the body-fixed position of the hit, in double */
            int bi = hit->body[i];
            factor *= nc_albedo_map_factor(am, nc_mat_tmul_v(&j->body_R[bi], nc_v3_sub(p, j->body_rel[bi])));
        }
        s->factor[i] = factor;
    }
    shadow_frames(j, hit, depth, s);
}

/* r (1/sr) for the lanes listed, each with its own body's material, in one
 * batch per body (usually one); r is 0 where a model gives NaN or Inf. */
static void eval_lanes(const struct job *j, const int *body, const struct nc_photometry *geo, const int *lanes,
                       int nlanes, double *r)
{
    int todo[NC_PACKET];
    memcpy(todo, lanes, (size_t)nlanes * sizeof *todo);
    while (nlanes > 0) {
        int b = body[todo[0]], lane[NC_PACKET], nl = 0, rest = 0;
        struct nc_photometry g[NC_PACKET];
        double rb[NC_PACKET];
        for (int k = 0; k < nlanes; k++) {
            if (body[todo[k]] == b) {
                lane[nl] = todo[k];
                g[nl++] = geo[todo[k]];
            } else {
                todo[rest++] = todo[k];
            }
        }
        nlanes = rest;
        nc_material_eval(&j->mat[b], (size_t)nl, g, rb);
        for (int k = 0; k < nl; k++)
            r[lane[k]] = rb[k] >= 0 && rb[k] < INFINITY ? rb[k] : 0.0; /* no NaN/Inf into a frame */
    }
}

/* Counters a tile adds up before it reports them (nc_rt_count_shadow_rays). */
struct tile_counts {
    unsigned long shadow_culled, shadow_traced, hits, back_hits;
};

/* Lane i of ray starts eps off point p (in the ray's frame) along the unit
 * normal n, rounded to float. */
static inline __attribute__((always_inline)) void start_off(struct nc_ray16 *ray, int i, struct nc_vec3 p, double eps,
                                                           struct nc_vec3 n)
{
    ray->ox[i] = (float)(p.x + eps * n.x);
    ray->oy[i] = (float)(p.y + eps * n.y);
    ray->oz[i] = (float)(p.z + eps * n.z);
}

/* The valid lanes of shadow, rays from the points of sf, all in frame fr:
 * occluded[i] and blocked[i] set where they meet something
 * (nc_rt_shadow_cull16, nc_rt_occluded16); returns how many were proven
 * clear. In a body's far frame the rays left to trace start from their
 * points refined (nc_rt_refine_far16), 4e-6 of their escale off. */
static int occluded_in(struct job *j, const struct surf *sf, struct nc_ray16 *shadow, const int *from, int fr,
                       int *occluded, int *blocked)
{
    int culled = j->r->no_shadow_cull ? 0 : nc_rt_shadow_cull16(j->rt, shadow, from, blocked, fr), left = 0;
    for (int i = 0; i < NC_PACKET; i++)
        left |= shadow->valid[i];
    if (!left) /* every ray proven lit, or blocked by a rock */
        return culled;
    if (fr >= 0) {
        double t[NC_PACKET];
        int done[NC_PACKET], mesh[NC_PACKET];
        struct nc_vec3 o[NC_PACKET]; /* the rays' origins, to 1e-16 of t */
        for (int i = 0; i < NC_PACKET; i++) {
            o[i] = nc_v3_sub(sf->p[i], nc_v3_scale(sf->d[i], sf->t[i]));
            mesh[i] = shadow->valid[i] && !sf->rock[i];
        }
        memcpy(t, sf->t, sizeof t);
        nc_rt_refine_far16(j->rt, fr, mesh, sf->prim, o, sf->d, t, done);
        for (int i = 0; i < NC_PACKET; i++) {
            if (!shadow->valid[i])
                continue;
            /* a point not refined: 1e-7 of the range off, the offset as in the camera's frame */
            const double eps = 4e-6 * (done[i] ? sf->escale[i] : fmax(sf->escale[i], t[i]));
            start_off(shadow, i, nc_v3_add(nc_v3_sub(sf->p[i], sf->rel[i]), nc_v3_scale(sf->d[i], t[i] - sf->t[i])),
                      eps, sf->n[i]);
        }
    }
    int occ[NC_PACKET];
    if (j->r->ray_hook)
        j->r->ray_hook(j->r->ray_hook_user, 1, shadow, fr);
    nc_rt_occluded16(j->rt, shadow, occ, fr);
    for (int i = 0; i < NC_PACKET; i++)
        occluded[i] |= occ[i];
    return culled;
}

/* Shadow rays' lanes that meet nothing: culled (proven) or traced, each
 * in its frame (usually one for the packet). */
static void unoccluded16(struct job *j, const struct surf *sf, struct nc_ray16 *shadow, const int *from, int any,
                         int *lit, struct tile_counts *cnt)
{
    const int *frame = sf->frame;
    int occluded[NC_PACKET] = {0}, blocked[NC_PACKET] = {0}, culled = 0, first = -1, one = 1;
    for (int i = 0; i < NC_PACKET; i++)
        if (shadow->valid[i] && first < 0)
            first = i;
        else if (shadow->valid[i])
            one &= frame[i] == frame[first];
    if (first >= 0 && one) {
        culled = occluded_in(j, sf, shadow, from, frame[first], occluded, blocked);
    } else if (first >= 0) {
        int todo[NC_PACKET];
        memcpy(todo, shadow->valid, sizeof todo);
        for (int i0 = 0; i0 < NC_PACKET; i0++) {
            if (!todo[i0])
                continue;
            struct nc_ray16 part = *shadow;
            const int fr = frame[i0];
            for (int i = 0; i < NC_PACKET; i++) {
                part.valid[i] = todo[i] && frame[i] == fr ? -1 : 0;
                todo[i] &= !part.valid[i];
            }
            culled += occluded_in(j, sf, &part, from, fr, occluded, blocked);
        }
    }
    cnt->shadow_culled += (unsigned long)culled;
    cnt->shadow_traced += (unsigned long)(any - culled);
    for (int i = 0; i < NC_PACKET; i++)
        lit[i] = lit[i] && !occluded[i] && !blocked[i];
}

/* sunlight16's lanes for the camera rays' points with hard shadows, in one
 * branch-free loop (AVX-512 or AVX2 where the CPU has it, without
 * contraction: the same bits as the loop lane by lane): a lane with no
 * point, or facing away from the Sun or the camera, gets lit 0 and an
 * invalid ray (its other fields unused); a ray starts 4e-6 t off the
 * surface, as in sunlight16. Returns how many are lit. */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static int
hard_lanes(const struct surf *s, struct nc_photometry *geo, struct nc_ray16 *shadow, int *from, int *lit)
{
    int any = 0;
    for (int i = 0; i < NC_PACKET; i++) {
        const struct nc_vec3 nrm = s->n[i], sdir = s->sdir[i], d = s->d[i], p = s->p[i];
        const double mu = -nc_v3_dot(nrm, d), mu0 = nc_v3_dot(nrm, sdir), eps = 4e-6 * s->scale[i];
        const int on = (s->body[i] >= 0) & (mu0 > 0) & (mu > 0) & s->facet_sun[i];
        geo[i] = (struct nc_photometry){mu0, mu, -nc_v3_dot(sdir, d), s->factor[i]};
        shadow->ox[i] = (float)(p.x + eps * nrm.x);
        shadow->oy[i] = (float)(p.y + eps * nrm.y);
        shadow->oz[i] = (float)(p.z + eps * nrm.z);
        shadow->dx[i] = (float)sdir.x;
        shadow->dy[i] = (float)sdir.y;
        shadow->dz[i] = (float)sdir.z;
        shadow->tnear[i] = 0.0f;
        shadow->tfar[i] = INFINITY;
        shadow->valid[i] = on ? -1 : 0;
        from[i] = on & s->outside[i] ? s->body[i] : -1; /* the ray leaves the outer side: n . s = mu0 > 0 */
        lit[i] = on;
        any += on;
    }
    return any;
}

/* The shadow rays of s's lanes in far frames (shadow_frames) start there:
 * from p - rel, 4e-6 escale off along the normal (a lane in the camera's
 * frame gets the bits it had: rel 0, escale its scale); branch-free. */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void far_origins(const struct surf *s,
                                                                                            struct nc_ray16 *ray)
{
    for (int i = 0; i < NC_PACKET; i++)
        start_off(ray, i, nc_v3_sub(s->p[i], s->rel[i]), 4e-6 * s->escale[i], s->n[i]);
}

/* Direct sunlight at the surface points of s seen along their rays: r[i]
 * (1/sr; radiance = r irr), 0 where the point is unlit, shadowed or missing.
 * (px0, py0) is the packet's pixel block, sidx the pixel sample and depth the
 * path vertex (0: the camera ray's), which key the solar disk's points.
 * r_hard (NULL: not wanted): the same with the shadow ray aimed at the
 * Sun's centre (hard shadows), r itself when shadows are hard. */
static void sunlight16(struct job *j, const struct surf *s, int px0, int py0, int sidx, int depth, double *r,
                       double *r_hard, struct tile_counts *cnt)
{
    struct nc_ray16 shadow, centre;
    struct nc_photometry geo[NC_PACKET];
    int from[NC_PACKET], lit[NC_PACKET], any = 0; /* how many lit */
    const int twin = r_hard && j->sun_tan_radius > 0;
    const uint64_t disk_seed = depth ? mix64(j->disk_seed + (uint64_t)depth) : j->disk_seed;
    for (int i = 0; i < NC_PACKET; i++) {
        r[i] = 0;
        if (r_hard)
            r_hard[i] = 0;
    }
    if (!depth && !(j->sun_tan_radius > 0) && !j->r->lane_by_lane) {
        any = hard_lanes(s, geo, &shadow, from, lit);
    } else {
        for (int i = 0; i < NC_PACKET; i++) {
            shadow.valid[i] = lit[i] = 0;
            from[i] = -1;
            if (s->body[i] < 0)
                continue;
            struct nc_vec3 nrm = s->n[i], sdir = s->sdir[i];
            double mu = -nc_v3_dot(nrm, s->d[i]), mu0 = nc_v3_dot(nrm, sdir);
            if (!(mu0 > 0 && mu > 0) || !s->facet_sun[i])
                continue;
            geo[i] = (struct nc_photometry){mu0, mu, -nc_v3_dot(sdir, s->d[i]), s->factor[i]};
            /* Offset the origin off the surface by a few float ulps of the
             * camera-relative coordinates (a bounce's t can be far shorter than
             * the point's distance from the camera; a lane in a far frame is
             * moved there below: far_origins); tnear stays 0. */
            start_off(&shadow, i, s->p[i], 4e-6 * (depth ? fmax(s->scale[i], nc_v3_norm(s->p[i])) : s->scale[i]),
                      nrm);
            struct nc_vec3 sray = sdir;
            if (twin) {
                centre.ox[i] = shadow.ox[i];
                centre.oy[i] = shadow.oy[i];
                centre.oz[i] = shadow.oz[i];
                centre.dx[i] = (float)sdir.x;
                centre.dy[i] = (float)sdir.y;
                centre.dz[i] = (float)sdir.z;
                centre.tnear[i] = 0.0f;
                centre.tfar[i] = INFINITY;
            }
            if (j->sun_tan_radius > 0) {
                /* Soft shadows: toward a point of the solar disk, uniform
                 * over it, from a stream of its own (pixel, sample, depth). */
                int px = px0 + (i & 3), py = py0 + (i >> 2);
                uint64_t pid = pixel_id(&j->s->camera, px, py);
                double rr = j->sun_tan_radius * sqrt(hash01(disk_seed, pid, 2 * (uint64_t)sidx)),
                       th = 2.0 * M_PI * hash01(disk_seed, pid, 2 * (uint64_t)sidx + 1);
                struct nc_vec3 e1 = j->sun_e1, e2 = j->sun_e2;
                if (j->s->sun.has_position) /* the direction differs from point to point */
                    nc_v3_basis(sdir, &e1, &e2);
                sray = nc_v3_unit(
                    nc_v3_add(sdir, nc_v3_add(nc_v3_scale(e1, rr * cos(th)), nc_v3_scale(e2, rr * sin(th)))));
            }
            shadow.dx[i] = (float)sray.x;
            shadow.dy[i] = (float)sray.y;
            shadow.dz[i] = (float)sray.z;
            shadow.tnear[i] = 0.0f;
            shadow.tfar[i] = INFINITY;
            shadow.valid[i] = -1;
            /* the grid's proof needs a ray leaving the outer side */
            from[i] = s->outside[i] && nc_v3_dot(nrm, sray) > 0 ? s->body[i] : -1;
            lit[i] = 1;
            any++;
        }
    }
    if (!any)
        return;
    if (s->far) { /* the lanes in far frames start there */
        far_origins(s, &shadow);
        if (twin)
            far_origins(s, &centre);
    }
    int lit_hard[NC_PACKET], from_hard[NC_PACKET];
    if (twin) { /* the soft shadows' grid serves every ray into the disk, its centre too */
        for (int i = 0; i < NC_PACKET; i++) {
            centre.valid[i] = shadow.valid[i];
            lit_hard[i] = lit[i];
            from_hard[i] = lit[i] && s->outside[i] && nc_v3_dot(s->n[i], s->sdir[i]) > 0 ? s->body[i] : -1;
        }
        unoccluded16(j, s, &centre, from_hard, any, lit_hard, cnt);
    }
    unoccluded16(j, s, &shadow, from, any, lit, cnt);
    int todo[NC_PACKET], ntodo = 0;
    for (int i = 0; i < NC_PACKET; i++)
        if (lit[i] || (twin && lit_hard[i]))
            todo[ntodo++] = i;
    double rr[NC_PACKET];
    eval_lanes(j, s->body, geo, todo, ntodo, rr);
    for (int k = 0; k < ntodo; k++) {
        int i = todo[k];
        r[i] = lit[i] ? rr[i] : 0.0;
        if (r_hard)
            r_hard[i] = (twin ? lit_hard[i] : lit[i]) ? rr[i] : 0.0;
    }
}

/* Indirect light: from the camera ray's surface points s (changed: on return
 * the paths' last vertices), paths of up to render.bounces further vertices,
 * each lit by the Sun (sunlight16). The next direction comes from the
 * mixture of bounce.h and the path's throughput beta (dimensionless) is
 * multiplied by r / pdf; after render.roulette_after bounces a path goes on
 * with probability min(1, beta), its beta divided by that (Russian roulette:
 * unbiased). Adds the radiance to L[i] and I/F (relative to the irradiance
 * at the camera ray's point) to iof[i]. */
static void indirect16(struct job *j, struct surf *s, int px0, int py0, int sidx, double *L, double *iof,
                       struct tile_counts *cnt)
{
    const struct nc_scene *sc = j->s;
    const int B = j->bounces;
    double beta[NC_PACKET], irr0[NC_PACKET], pdf[NC_PACKET], r[NC_PACKET], radius[NC_MAX_BODIES];
    uint64_t pid[NC_PACKET]; /* each lane's pixel, keying its random numbers */
    struct nc_vec3 w[NC_PACKET], orig[NC_PACKET], centre[NC_MAX_BODIES];
    struct nc_photometry geo[NC_PACKET];
    struct nc_ray16 ray;
    struct nc_hit16 hit;
    for (int b = 0; b < sc->nbodies; b++)
        radius[b] = sc->body[b].bounding_radius_m;
    for (int i = 0; i < NC_PACKET; i++) {
        beta[i] = 1.0;
        irr0[i] = s->irr[i];
    }
    for (int k = 1; k <= B; k++) {
        int lanes[NC_PACKET], nl = 0;
        for (int i = 0; i < NC_PACKET; i++) {
            if (s->body[i] < 0)
                continue;
            const uint64_t key = 4 * ((uint64_t)sidx * (uint64_t)B + (uint64_t)(k - 1));
            pid[i] = pixel_id(&sc->camera, px0 + (i & 3), py0 + (i >> 2));
            for (int b = 0; b < sc->nbodies; b++)
                centre[b] = nc_v3_sub(j->body_rel[b], s->p[i]);
            struct nc_bounce_mix mix;
            nc_bounce_init(&mix, s->n[i], centre, radius, sc->nbodies, s->body[i]);
            w[i] = nc_bounce_sample(&mix, hash01(j->path_seed, pid[i], key), hash01(j->path_seed, pid[i], key + 1),
                                    hash01(j->path_seed, pid[i], key + 2));
            pdf[i] = nc_bounce_pdf(&mix, w[i]);
            double mu0 = nc_v3_dot(s->n[i], w[i]), mu = -nc_v3_dot(s->n[i], s->d[i]);
            if (!(mu0 > 0 && mu > 0 && pdf[i] > 0)) { /* below the horizon: a cone's edge */
                s->body[i] = -1;
                continue;
            }
            geo[i] = (struct nc_photometry){mu0, mu, -nc_v3_dot(w[i], s->d[i]), s->factor[i]};
            lanes[nl++] = i;
        }
        eval_lanes(j, s->body, geo, lanes, nl, r);
        int live = 0;
        for (int n = 0; n < nl; n++) {
            int i = lanes[n];
            beta[i] *= r[i] / pdf[i];
            if (k > j->roulette_after && beta[i] < 1) {
                double u = hash01(j->path_seed, pid[i], 4 * ((uint64_t)sidx * (uint64_t)B + (uint64_t)(k - 1)) + 3);
                if (u < beta[i])
                    beta[i] = 1.0; /* beta / q with q = beta */
                else
                    beta[i] = 0;
            }
            if (!(beta[i] > 0 && beta[i] < INFINITY)) {
                s->body[i] = -1;
                continue;
            }
            /* a refined mesh hit (scale > t): its float triangle may lie an
             * edge's float error off the exact point */
            const double np = nc_v3_norm(s->p[i]);
            double eps = 4e-6 * (s->scale[i] > s->t[i] ? fmax(s->scale[i], np) : np) + 1e-9;
            orig[i] = nc_v3_add(s->p[i], nc_v3_scale(s->n[i], eps));
            live++;
        }
        if (!live)
            return;
        for (int i = 0; i < NC_PACKET; i++) {
            ray.valid[i] = s->body[i] >= 0 ? -1 : 0;
            if (!ray.valid[i])
                continue;
            ray.ox[i] = (float)orig[i].x;
            ray.oy[i] = (float)orig[i].y;
            ray.oz[i] = (float)orig[i].z;
            ray.dx[i] = (float)w[i].x;
            ray.dy[i] = (float)w[i].y;
            ray.dz[i] = (float)w[i].z;
            ray.tnear[i] = 0.0f;
            ray.tfar[i] = INFINITY;
        }
        if (j->r->ray_hook)
            j->r->ray_hook(j->r->ray_hook_user, 2, &ray, -1);
        nc_rt_intersect16(j->rt, &ray, &hit, 0);
        for (int i = 0; i < NC_PACKET; i++)
            if (!ray.valid[i])
                hit.body[i] = -1;
        surface16(j, &hit, orig, w, k, s);
        sunlight16(j, s, px0, py0, sidx, k, r, NULL, cnt);
        for (int i = 0; i < NC_PACKET; i++) {
            if (s->body[i] < 0 || r[i] == 0)
                continue;
            L[i] += beta[i] * r[i] * s->irr[i];
            iof[i] += beta[i] * M_PI * r[i] * s->irr[i] / irr0[i];
        }
    }
}

const char *const nc_geom_plane_names[NC_GEOM_PLANES] = {"range_m", "x_m", "y_m", "z_m", "nx", "ny", "nz",
                                                           "incidence_deg", "emission_deg", "phase_deg", "body"};

/* The geometry planes of a packet's camera rays (nc_frame.geom). */
static void record_geom(const struct job *j, const struct surf *sf, int px0, int py0)
{
    const size_t W = (size_t)j->s->camera.width_px, H = (size_t)j->s->camera.height_px, plane = W * H;
    const double deg = 180 / M_PI;
    for (int i = 0; i < NC_PACKET; i++) {
        size_t x = (size_t)(px0 + (i & 3)), y = (size_t)(py0 + (i >> 2));
        if (x >= W || y >= H)
            continue;
        float *g = j->f->geom + y * W + x, v[NC_GEOM_PLANES] = {0};
        v[NC_GEOM_BODY] = -1;
        int b = sf->body[i];
        if (b >= 0) {
            struct nc_vec3 p = nc_mat_tmul_v(&j->body_R[b], nc_v3_sub(sf->p[i], j->body_rel[b]));
            struct nc_vec3 n = nc_mat_tmul_v(&j->body_R[b], sf->n[i]);
            double c[3] = {nc_v3_dot(sf->n[i], sf->sdir[i]), -nc_v3_dot(sf->n[i], sf->d[i]),
                           -nc_v3_dot(sf->d[i], sf->sdir[i])};
            v[NC_GEOM_RANGE] = (float)sf->t[i];
            v[NC_GEOM_X] = (float)p.x, v[NC_GEOM_Y] = (float)p.y, v[NC_GEOM_Z] = (float)p.z;
            v[NC_GEOM_NX] = (float)n.x, v[NC_GEOM_NY] = (float)n.y, v[NC_GEOM_NZ] = (float)n.z;
            for (int k = 0; k < 3; k++)
                v[NC_GEOM_INCIDENCE + k] = (float)(acos(fmax(-1.0, fmin(1.0, c[k]))) * deg);
            v[NC_GEOM_BODY] = (float)b;
        }
        for (int k = 0; k < NC_GEOM_PLANES; k++)
            g[(size_t)k * plane] = v[k];
    }
}

/* A packet's camera samples: lane i is pixel (px, py) (its centre) and,
 * with strata, the point (jx, jy) / n - 1/2 of it (stratum plus jitter), on
 * its row's camera rc. */
struct image_points {
    double px[NC_PACKET], py[NC_PACKET], jx[NC_PACKET], jy[NC_PACKET];
    const struct row_cam *rc[NC_PACKET];
};

/* The jitter of each lane's sample g[i] within its stratum (jx, jy hold
 * the stratum's corner): two hashes of (seed, pixel, sample) added, for all
 * lanes at once (64-bit multiplies: AVX-512 or AVX2 where the CPU has it).
 * Integer arithmetic and an exact conversion to [0, 1) (hash01), so one
 * rounding (the sum's) on any path, contracted or not: the same bits. */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void
jitter16(uint64_t seed, const uint64_t *pid, const int *g, struct image_points *ip)
{
    for (int i = 0; i < NC_PACKET; i++) {
        ip->jx[i] += hash01(seed, pid[i], 2 * (uint64_t)g[i]);
        ip->jy[i] += hash01(seed, pid[i], 2 * (uint64_t)g[i] + 1);
    }
}

/* The unit directions d[i] of a packet's camera rays through the image
 * points ip (n strata a side; 0: the pixel centres). The pinhole case is
 * branch-free loops, vectorised (AVX-512 or AVX2 where the CPU has it,
 * without contraction: the same bits as plain scalar code, and as
 * nc_v3_unit). */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void
camera_dirs(const struct nc_camera *c, const struct image_points *ip, int n, struct nc_vec3 *d)
{
    double fx[NC_PACKET], fy[NC_PACKET];
    for (int i = 0; i < NC_PACKET; i++) {
        fx[i] = ip->px[i] + (n ? ip->jx[i] / n - 0.5 : 0.0);
        fy[i] = ip->py[i] + (n ? ip->jy[i] / n - 0.5 : 0.0);
    }
    const struct row_cam *const *rc = ip->rc;
    if (c->distorted) { /* the lens model, inverted exactly for each sample */
        for (int i = 0; i < NC_PACKET; i++)
            d[i] = nc_v3_unit(nc_mat_mul_v(&rc[i]->R, nc_camera_ray(c, fx[i], fy[i])));
        return;
    }
    /* R ((x - cx)/fx, (y - cy)/fy, 1) = d00 + x ex + y ey, expanded once per row */
    double a[9][NC_PACKET], u[3][NC_PACKET];
    for (int i = 0; i < NC_PACKET; i++) {
        a[0][i] = rc[i]->d00.x, a[1][i] = rc[i]->d00.y, a[2][i] = rc[i]->d00.z;
        a[3][i] = rc[i]->ex.x, a[4][i] = rc[i]->ex.y, a[5][i] = rc[i]->ex.z;
        a[6][i] = rc[i]->ey.x, a[7][i] = rc[i]->ey.y, a[8][i] = rc[i]->ey.z;
    }
    for (int i = 0; i < NC_PACKET; i++) {
        const double vx = a[0][i] + fx[i] * a[3][i] + fy[i] * a[6][i];
        const double vy = a[1][i] + fx[i] * a[4][i] + fy[i] * a[7][i];
        const double vz = a[2][i] + fx[i] * a[5][i] + fy[i] * a[8][i];
        unit_lane(vx, vy, vz, u, i);
    }
    for (int i = 0; i < NC_PACKET; i++)
        d[i] = nc_v3(u[0][i], u[1][i], u[2][i]);
}

/* Camera rays of one 4x4 pixel block, traced for up to SLOT_GROUP samples
 * at once: ray[q] is sample slot0 + q of the block's 16 pixels. Regrouped
 * into packets of 2x2 pixels x 4 samples (or as near as ns allows), each
 * packet spans a quarter of the image area of a 4x4-pixel one, so Embree
 * opens fewer tree nodes and tests fewer triangles per packet. Embree gives
 * each ray its own closest hit whatever its packet-mates (an exact tie
 * between two triangles might resolve either way; test_determinism compares
 * the two packings bit for bit and has met none). Where the bins of
 * nc_rt_bin_camera serve the pass, the block's packets go to them as they are. */
#define SLOT_GROUP 16
static void trace_camera(const struct job *j, int px0, int py0, const struct nc_ray16 *ray, struct nc_hit16 *hit,
                         int ns)
{
    if (j->bins) { /* a pinhole at rest: the block's own triangles */
        for (int q = 0; q < ns && j->r->ray_hook; q++)
            j->r->ray_hook(j->r->ray_hook_user, 0, &ray[q], -1);
        if (j->r->one_sample_packets)
            for (int q = 0; q < ns; q++)
                nc_rt_intersect_block(j->rt, px0, py0, &ray[q], &hit[q], 1);
        else
            nc_rt_intersect_block(j->rt, px0, py0, ray, hit, ns);
        return;
    }
    if (ns == 1 || j->r->one_sample_packets) {
        for (int q = 0; q < ns; q++) {
            if (j->r->ray_hook)
                j->r->ray_hook(j->r->ray_hook_user, 0, &ray[q], -1);
            nc_rt_intersect16(j->rt, &ray[q], &hit[q], 1);
        }
        return;
    }
    /* The 16 pixels (lane x + 4 y) along a Hilbert curve: each four make a
     * 2x2 quad and each next pixel is a neighbour. A packet's lanes are
     * consecutive (pixel, sample) pairs of this order. */
    static const int quad[NC_PACKET] = {0, 1, 5, 4, 8, 12, 13, 9, 10, 14, 15, 11, 7, 6, 2, 3};
    int lq = 0, lp = 0;
    for (int p0 = 0; p0 < NC_PACKET * ns; p0 += NC_PACKET) {
        struct nc_ray16 pk;
        struct nc_hit16 hk;
        int qk[NC_PACKET], ik[NC_PACKET]; /* lane k's sample and pixel */
        for (int k = 0; k < NC_PACKET; k++) {
            const int q = qk[k] = lq, i = ik[k] = quad[lp];
            if (++lq == ns) /* (p0 + k) mod ns and (p0 + k) / ns, without dividing */
                lq = 0, lp++;
            const struct nc_ray16 *rq = &ray[q];
            pk.ox[k] = rq->ox[i], pk.oy[k] = rq->oy[i], pk.oz[k] = rq->oz[i];
            pk.dx[k] = rq->dx[i], pk.dy[k] = rq->dy[i], pk.dz[k] = rq->dz[i];
            pk.tnear[k] = rq->tnear[i], pk.tfar[k] = rq->tfar[i], pk.valid[k] = rq->valid[i];
        }
        if (j->r->ray_hook)
            j->r->ray_hook(j->r->ray_hook_user, 0, &pk, -1);
        nc_rt_intersect16(j->rt, &pk, &hk, 1);
        for (int k = 0; k < NC_PACKET; k++) {
            const int i = ik[k];
            struct nc_hit16 *h = &hit[qk[k]];
            h->t[i] = hk.t[k], h->nx[i] = hk.nx[k], h->ny[i] = hk.ny[k], h->nz[i] = hk.nz[k];
            h->fnx[i] = hk.fnx[k], h->fny[i] = hk.fny[k], h->fnz[i] = hk.fnz[k];
            h->body[i] = hk.body[k], h->albedo[i] = hk.albedo[k], h->rock[i] = hk.rock[k];
            h->prim[i] = hk.prim[k];
        }
    }
}

/* A frame plane's pixel, stored past the caches (SSE2's MOVNTI; plain
 * elsewhere). The planes are megabytes and written once a frame: an
 * ordinary store first reads its line from memory, which cost about 5 % of
 * a 512x512 crop frame's CPU (bench figures in docs/emulator.md). The
 * same values either way; shade_tile fences them before it returns. */
static inline void stream_f(float *p, float v)
{
#ifdef __SSE2__
    int32_t b;
    memcpy(&b, &v, sizeof b);
    _mm_stream_si32((int *)p, b);
#else
    *p = v;
#endif
}

static void shade_tile(struct job *j, int tile)
{
    const struct nc_scene *s = j->s;
    const struct nc_camera *c = &s->camera;
    const int W = c->width_px, H = c->height_px, n = j->n_strata, S = n * n;
    const struct nc_sample_pass *ps = &j->pass;
    const int slots = ps->N / ps->K; /* samples each pixel takes in this pass */
    const int x0 = (tile % j->tiles_x) * TILE, y0 = (tile / j->tiles_x) * TILE;
    double acc_L[TILE * TILE], acc_iof[TILE * TILE], acc_range[TILE * TILE], acc_dir[TILE * TILE],
        acc_hard[TILE * TILE];
    int hits[TILE * TILE];
    const int planes = j->f->direct || j->f->direct_hard;
    /* This render's 4x4 blocks of the tile (the others are left as they are), and those traced. */
    int mine[TILE / 4][TILE / 4], live[TILE / 4][TILE / 4];
    for (int by = 0; by < TILE; by += 4)
        for (int bx = 0; bx < TILE; bx += 4) {
            mine[by / 4][bx / 4] = y0 + by < H && x0 + bx < W && (!j->blocks || (bx + by) / 4 % 2 == j->blocks - 1);
            live[by / 4][bx / 4] = mine[by / 4][bx / 4] && block_live(j, x0 + bx, y0 + by);
        }
    float *one = j->f->one;
    int one_g[TILE * TILE]; /* the sample plane `one` keeps: (0 <= g < N) */
    for (int k = 0; k < TILE * TILE && one; k++) {
        const int x = x0 + k % TILE, y = y0 + k / TILE;
        one_g[k] = sample_of(s->render.seed, pixel_id(c, x, y), ps->k, ps->N);
        if (mine[k / TILE / 4][k % TILE / 4] && x < W && y < H)
            one[(size_t)y * (size_t)W + (size_t)x] = 0.0f; /* where that sample hits nothing */
    }
    memset(acc_L, 0, sizeof acc_L);
    if (planes) {
        memset(acc_dir, 0, sizeof acc_dir);
        memset(acc_hard, 0, sizeof acc_hard);
    }
    memset(acc_iof, 0, sizeof acc_iof);
    memset(acc_range, 0, sizeof acc_range);
    memset(hits, 0, sizeof hits);
    /* Blocks no ray of which can reach a body show sky in the optional
     * planes too (they are never traced). */
    if (j->f->rock_id || j->f->geom) {
        struct surf sky;
        for (int i = 0; i < NC_PACKET; i++)
            sky.body[i] = -1;
        for (int by = 0; by < TILE; by += 4)
            for (int bx = 0; bx < TILE; bx += 4) {
                if (live[by / 4][bx / 4] || !mine[by / 4][bx / 4])
                    continue;
                for (int i = 0; i < NC_PACKET && j->f->rock_id; i++) {
                    int px = x0 + bx + (i & 3), py = y0 + by + (i >> 2);
                    if (px < W && py < H)
                        j->f->rock_id[(size_t)py * (size_t)W + (size_t)px] = -1;
                }
                if (j->f->geom)
                    record_geom(j, &sky, x0 + bx, y0 + by);
            }
    }

    /* The camera rays of up to SLOT_GROUP samples of a block at a time (trace_camera). */
    struct nc_ray16 ray[SLOT_GROUP];
    struct nc_vec3 dir[SLOT_GROUP][NC_PACKET], orig[SLOT_GROUP][NC_PACKET]; /* in double precision */
    int g_lane[SLOT_GROUP][NC_PACKET];
    struct nc_hit16 hit[SLOT_GROUP];
    struct surf sf;
    memset(&sf, 0, sizeof sf); /* hard_lanes and far_origins read every lane, hit or not */
    struct tile_counts cnt = {0, 0, 0, 0};
    double r[NC_PACKET];

    for (int slot0 = 0; slot0 < slots; slot0 += SLOT_GROUP) {
        const int ns = slots - slot0 < SLOT_GROUP ? slots - slot0 : SLOT_GROUP;
        for (int by = 0; by < TILE; by += 4)
            for (int bx = 0; bx < TILE; bx += 4) {
                if (!live[by / 4][bx / 4])
                    continue;
                /* Camera rays for a 4x4 pixel block, ns samples each: what
                 * the samples share (pixels, rows, origins) once a block. */
                struct image_points ip;
                uint64_t pid[NC_PACKET];
                int valid[NC_PACKET];
                float o32[3][NC_PACKET];
                for (int i = 0; i < NC_PACKET; i++) {
                    const int px = x0 + bx + (i & 3), py = y0 + by + (i >> 2);
                    valid[i] = (px < W && py < H) ? -1 : 0;
                    pid[i] = pixel_id(c, px, py);
                    ip.px[i] = px;
                    ip.py[i] = py;
                    ip.rc[i] = &j->row[py < H ? py : H - 1];
                    o32[0][i] = (float)ip.rc[i]->o.x;
                    o32[1][i] = (float)ip.rc[i]->o.y;
                    o32[2][i] = (float)ip.rc[i]->o.z;
                }
                for (int q = 0; q < ns; q++) {
                    const int slot = slot0 + q, vary = ps->K > 1 && (S > 1 || one); /* g differs from lane to lane */
                    /* Sample g lies in stratum g mod S = (sx, sy), jittered within it by the hashes. */
                    const int sx_slot = slot % S % n, sy_slot = slot % S / n;
                    for (int i = 0; i < NC_PACKET; i++) {
                        const int g = vary ? sample_of(s->render.seed, pid[i], ps->k + slot * ps->K, ps->N) : slot;
                        g_lane[q][i] = g;
                        if (S > 1) {
                            ip.jx[i] = vary ? g % S % n : sx_slot;
                            ip.jy[i] = vary ? g % S / n : sy_slot;
                        }
                    }
                    if (S > 1)
                        jitter16(s->render.seed, pid, g_lane[q], &ip);
                    camera_dirs(c, &ip, S > 1 ? n : 0, dir[q]);
                    for (int i = 0; i < NC_PACKET; i++) {
                        const struct nc_vec3 d = dir[q][i];
                        orig[q][i] = ip.rc[i]->o;
                        ray[q].valid[i] = valid[i];
                        ray[q].ox[i] = o32[0][i];
                        ray[q].oy[i] = o32[1][i];
                        ray[q].oz[i] = o32[2][i];
                        ray[q].dx[i] = (float)d.x;
                        ray[q].dy[i] = (float)d.y;
                        ray[q].dz[i] = (float)d.z;
                        ray[q].tnear[i] = 0.0f;
                        ray[q].tfar[i] = INFINITY;
                    }
                }
                trace_camera(j, x0 + bx, y0 + by, ray, hit, ns);
                for (int q = 0; q < ns; q++) {
                    /* This sample's number in the pixel's exposure (the soft-shadow and
                     * path streams'); the same in all lanes, unique per pixel. */
                    const int slot = slot0 + q, sidx = ps->k * slots + slot;
                    if (slot == 0 && j->f->rock_id) /* the rock each pixel's first sample (here) hit */
                        for (int i = 0; i < NC_PACKET; i++)
                            if (ray[q].valid[i])
                                j->f->rock_id[(size_t)(y0 + by + (i >> 2)) * (size_t)W + (size_t)(x0 + bx + (i & 3))] =
                                    hit[q].body[i] >= 0 ? hit[q].rock[i] : -1;
                    surface16(j, &hit[q], orig[q], dir[q], 0, &sf);
                    if (slot == 0 && j->f->geom)
                        record_geom(j, &sf, x0 + bx, y0 + by);
                    int any = 0;
                    for (int i = 0; i < NC_PACKET; i++) {
                        if (sf.body[i] < 0)
                            continue;
                        int k = (by + (i >> 2)) * TILE + bx + (i & 3);
                        acc_range[k] += sf.t[i];
                        hits[k]++;
                        any++;
                        cnt.hits++;
                        cnt.back_hits += !sf.outside[i];
                    }
                    if (!any)
                        continue;
                    /* Direct sunlight, then what reaches these points from other surfaces. */
                    double L[NC_PACKET], iof[NC_PACKET], sun[NC_PACKET], hard[NC_PACKET];
                    sunlight16(j, &sf, x0 + bx, y0 + by, sidx, 0, r, planes ? hard : NULL, &cnt);
                    for (int i = 0; i < NC_PACKET; i++) {
                        L[i] = sun[i] = sf.body[i] >= 0 ? r[i] * sf.irr[i] : 0.0;
                        iof[i] = M_PI * r[i];
                        if (planes)
                            hard[i] = sf.body[i] >= 0 ? hard[i] * sf.irr[i] : 0.0;
                    }
                    int seen[NC_PACKET]; /* the body each sample met (indirect16 walks sf on along its path) */
                    memcpy(seen, sf.body, sizeof seen);
                    if (j->bounces > 0)
                        indirect16(j, &sf, x0 + bx, y0 + by, sidx, L, iof, &cnt);
                    for (int i = 0; i < NC_PACKET; i++) {
                        int o = (by + (i >> 2)) * TILE + bx + (i & 3);
                        if (seen[i] >= 0 && j->r->as_point[seen[i]])
                            L[i] = iof[i] = sun[i] = hard[i] = 0; /* its light comes as a point (nc_render_exposure) */
                        acc_L[o] += L[i];
                        acc_iof[o] += iof[i];
                        if (one && ray[q].valid[i] && g_lane[q][i] == one_g[o])
                            one[(size_t)(y0 + by + (i >> 2)) * (size_t)W + (size_t)(x0 + bx + (i & 3))] =
                                (float)L[i];
                        if (planes) {
                            acc_dir[o] += sun[i];
                            acc_hard[o] += hard[i];
                        }
                    }
                }
            }
    }
    nc_rt_count_shadow_rays(j->rt, cnt.shadow_culled, cnt.shadow_traced);
    nc_rt_count_camera_hits(j->rt, cnt.hits, cnt.back_hits);
    const double inv = 1.0 / slots;
    for (int y = y0; y < y0 + TILE && y < H; y++)
        for (int x = x0; x < x0 + TILE && x < W; x++) {
            int k = (y - y0) * TILE + (x - x0);
            if (!mine[(y - y0) / 4][(x - x0) / 4])
                continue;
            size_t o = (size_t)y * (size_t)W + (size_t)x;
            stream_f(&j->f->radiance[o], (float)(acc_L[k] * inv));
            stream_f(&j->f->iof[o], (float)(acc_iof[k] * inv));
            stream_f(&j->f->range_m[o], hits[k] ? (float)(acc_range[k] / hits[k]) : 0.0f);
            stream_f(&j->f->coverage[o], (float)(hits[k] * inv));
            if (j->f->direct)
                j->f->direct[o] = (float)(acc_dir[k] * inv);
            if (j->f->direct_hard)
                j->f->direct_hard[o] = (float)(acc_hard[k] * inv);
        }
#ifdef __SSE2__
    _mm_sfence(); /* the streamed stores visible before the tile counts as done */
#endif
}

static void *worker(void *arg)
{
    struct job *j = arg;
    const int ntiles = j->tiles ? j->n_tiles : j->tiles_x * j->n_tile_rows;
    for (;;) {
        int t = atomic_fetch_add(&j->next, 1);
        if (t >= ntiles)
            break;
        shade_tile(j, j->tiles ? j->tiles[t] : t + j->tile_row_begin * j->tiles_x);
    }
    return NULL;
}

int nc_render_frame(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f)
{
    return nc_render_rows(r, s, f, 0, (s->camera.height_px + TILE - 1) / TILE);
}

int nc_render_tile_rows(const struct nc_scene *s) { return (s->camera.height_px + TILE - 1) / TILE; }

int nc_render_rows(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, int tile_row_begin,
                   int tile_row_end)
{
    return nc_render_rows_timed(r, s, f, tile_row_begin, tile_row_end, NULL, NULL);
}

static int render_rows(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, int tile_row_begin,
                       int tile_row_end, const int *tiles, int blocks, const double *row_dt,
                       const struct nc_sample_pass *pass);

int nc_render_rows_timed(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, int tile_row_begin,
                         int tile_row_end, const double *row_dt, const struct nc_sample_pass *pass)
{
    return render_rows(r, s, f, tile_row_begin, tile_row_end, NULL, 0, row_dt, pass);
}

int nc_render_tile_list(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, const int *tiles, int n,
                        int blocks, const struct nc_sample_pass *pass)
{
    const int all = nc_render_tile_rows(s) * ((s->camera.width_px + TILE - 1) / TILE);
    for (int i = 0; i < n; i++)
        if (tiles[i] < 0 || tiles[i] >= all)
            return nc_error(NC_ERANGE, "render: tile %d of %d", tiles[i], all);
    if (blocks < 0 || blocks > 2)
        return nc_error(NC_ERANGE, "render: blocks %d (0, 1 or 2)", blocks);
    return render_rows(r, s, f, 0, n, tiles, blocks, NULL, pass);
}

/* Every pose of the scene finite: the camera's, the bodies', the Sun's
 * (a pose propagated by rates too large for its time turns into NaN, and
 * a frame of it would be no image of anything). */
static int pose_finite(const struct nc_scene *s)
{
    int ok = nc_v3_isfinite(s->camera.position_m) && nc_quat_isfinite(s->camera.attitude_q) &&
             nc_v3_isfinite(s->sun.has_position ? s->sun.position_m : s->sun.direction);
    for (int b = 0; b < s->nbodies; b++)
        ok = ok && nc_v3_isfinite(s->body[b].position_m) && nc_quat_isfinite(s->body[b].attitude_q);
    return ok ? 0 : nc_error(NC_ERANGE, "the pose to render is not finite (the camera's, a body's or the Sun's: "
                                        "rates too large for the time they are propagated over?)");
}

/* Tile rows [begin, end), or the tiles tiles[0 .. end - begin) where not NULL. */
static int render_rows(struct nc_renderer *r, const struct nc_scene *s, struct nc_frame *f, int tile_row_begin,
                       int tile_row_end, const int *tiles, int blocks, const double *row_dt,
                       const struct nc_sample_pass *pass)
{
    const struct nc_camera *c = &s->camera;
    if (f->width_px != c->width_px || f->height_px != c->height_px)
        return nc_error(NC_ERANGE, "frame is %dx%d but the camera is %dx%d", f->width_px, f->height_px,
                        c->width_px, c->height_px);
    int rc = pose_finite(s);
    if (rc < 0 || (rc = nc_rt_update(r->rt, s)) < 0)
        return rc;
    struct job j = {.r = r, .s = s, .rt = r->rt, .f = f};
    struct nc_rt_stats st;
    nc_rt_get_stats(r->rt, &st);
    for (int b = 0; b < s->nbodies; b++) {
        j.body_R[b] = nc_quat_to_mat(s->body[b].attitude_q);
        j.body_rel[b] = nc_v3_sub(s->body[b].position_m, c->position_m);
        j.mat[b] = s->body[b].material;
        j.far[b] = nc_rt_far_frame(r->rt, b, &j.far_scale[b]);
        j.any_far |= j.far[b];
        r->fold_theta_bar_deg[b] = -1;
        if (s->render.boulder_fold && st.boulder_cut_cover[b] > 0)
            r->fold_theta_bar_deg[b] = nc_material_fold_rocks(&s->body[b].material, st.boulder_cut_cover[b], &j.mat[b]);
    }
    j.row = malloc((size_t)c->height_px * sizeof *j.row);
    if (!j.row)
        return nc_error(-ENOMEM, "out of memory");
    /* the rows of the tile rows rendered (a rolling shutter's band), else all */
    int ya = 0, yb = c->height_px;
    if (!tiles) {
        ya = tile_row_begin > 0 ? TILE * tile_row_begin : 0;
        yb = TILE * tile_row_end < c->height_px ? TILE * tile_row_end : c->height_px;
    }
    for (int y = ya; y < yb; y++) {
        struct row_cam *rw = &j.row[y];
        double dt = row_dt ? row_dt[y] : 0.0;
        struct nc_quat q = dt != 0 ? nc_quat_propagate(c->attitude_q, c->angular_velocity_rad_s, dt) : c->attitude_q;
        rw->R = nc_quat_to_mat(q);
        rw->o = nc_v3_scale(c->velocity_m_s, dt);
        rw->d00 = nc_mat_mul_v(&rw->R, nc_camera_dir(c, 0, 0));
        rw->ex = nc_mat_mul_v(&rw->R, nc_v3(1.0 / c->fx_px, 0, 0));
        rw->ey = nc_mat_mul_v(&rw->R, nc_v3(0, 1.0 / c->fy_px, 0));
    }
    j.tiles_x = (c->width_px + TILE - 1) / TILE;
    j.tiles_y = (c->height_px + TILE - 1) / TILE;
    j.tiles = tiles;
    j.blocks = blocks;
    j.n_tiles = tile_row_end - tile_row_begin;
    j.tile_row_begin = tile_row_begin < 0 ? 0 : tile_row_begin;
    j.n_tile_rows = (tile_row_end <= j.tiles_y ? tile_row_end : j.tiles_y) - j.tile_row_begin;
    if (tiles ? j.n_tiles <= 0 : j.n_tile_rows <= 0) {
        free(j.row);
        return 0;
    }
    j.n_strata = (int)lround(sqrt((double)s->render.samples_per_pixel));
    if (j.n_strata < 1)
        j.n_strata = 1;
    const int S = j.n_strata * j.n_strata;
    j.pass = pass ? *pass : (struct nc_sample_pass){0, 1, S};
    if (j.pass.K < 1 || j.pass.k < 0 || j.pass.k >= j.pass.K || j.pass.N < S || j.pass.N % j.pass.K ||
        j.pass.N % S) {
        free(j.row);
        return nc_error(NC_ERANGE, "render: sample pass %d of %d with %d samples a pixel (%d strata)", j.pass.k,
                        j.pass.K, j.pass.N, S);
    }
    atomic_init(&j.next, 0);
    j.cull = !c->distorted && !r->no_cull; /* the lens model's rays are not linear in the pixel */
    /* Threads kept between frames (and between a rolling shutter's bands);
     * fewer threads only cost time, never change pixels. */
    if (r->pool_threads != r->threads) { /* a caller changed r->threads */
        nc_pool_destroy(r->pool);
        r->pool = nc_pool_create(r->threads);
        r->pool_threads = r->threads;
    }
    /* Camera rays through binned triangles when every row has the same
     * camera (no rolling-shutter motion) and the rays are linear in the pixel. */
    int pinhole = !c->distorted && !r->no_bins;
    for (int y = ya + 1; y < yb && pinhole; y++)
        pinhole = !memcmp(&j.row[y].o, &j.row[ya].o, sizeof j.row[ya].o) &&
                  !memcmp(&j.row[y].d00, &j.row[ya].d00, sizeof j.row[ya].d00) &&
                  !memcmp(&j.row[y].ex, &j.row[ya].ex, sizeof j.row[ya].ex) &&
                  !memcmp(&j.row[y].ey, &j.row[ya].ey, sizeof j.row[ya].ey);
    const struct nc_rt_pinhole pin = {j.row[ya].o,    j.row[ya].d00, j.row[ya].ex,
                                      j.row[ya].ey,   c->width_px,   c->height_px,
                                      j.pass.N};
    if ((rc = nc_rt_bin_camera(r->rt, pinhole ? &pin : NULL, r->pool, r->threads)) < 0) {
        free(j.row);
        return rc;
    }
    j.bins = rc > 0;
    j.plain = !s->sun.has_position && !r->lane_by_lane;
    for (int b = 0; b < s->nbodies; b++)
        j.plain &= nc_body_is_mesh(&s->body[b]) &&
                   !s->body[b].material.albedo_map;
    nc_scene_sun_at(s, s->body[0].position_m, &j.sun_dir, &j.sun_irr);
    j.sun_tan_radius = s->render.soft_shadows ? tan(nc_scene_sun_radius_rad(s)) : 0.0;
    nc_v3_basis(j.sun_dir, &j.sun_e1, &j.sun_e2);
    j.disk_seed = mix64(s->render.seed ^ 0x736f6674ull); /* "soft": not the pixel jitter's stream */
    j.bounces = s->render.bounces;
    j.roulette_after = s->render.roulette_after;
    j.path_seed = mix64(s->render.seed ^ 0x70617468ull); /* "path" */

    nc_pool_run(r->pool, worker, &j);
    free(j.row);
    return 0;
}
