/* test_rock_relief.c - relief on the rocks' faces (boulders.roughness_deg,
 * nc_boulder_relief): its gradient along a face has the stated RMS slope;
 * rendered, it changes the rocks' pixels and nothing else (shadows and
 * ground are the flat-faced rocks' bit for bit), gives them texture, and is
 * the same on 1 and 2 threads; a point of a rock is shaded with the same
 * normal seen from two camera positions. Rocks resolved by enough pixels
 * as detailed surfaces (render.boulder_mesh_px, nc_rock_shape_mesh): each
 * surface closed, within its planes and rough; rendered, they change the
 * frame and the rocks' brightness within stated tolerances, on 1 and 2
 * threads alike. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/noise.h"
#include "core/rng.h"
#include "render/boulders.h"
#include "render/render.h"
#include "render/rt.h"
#include "testutil.h"

/* The RMS magnitude of the gradient along random planes through random
 * points of random rocks. */
static void check_slope(const struct nc_boulder_field *f, double deg)
{
    uint64_t s = 11;
    double sum2 = 0, diff = 0;
    const int n = 200000;
    for (int i = 0; i < n; i++) {
        size_t k = (size_t)(nc_rng_uniform(&s) * (double)f->n);
        struct nc_vec3 u = nc_rng_dir(&s), nrm = nc_rng_dir(&s);
        double r = nc_rng_uniform(&s), p[3] = {r * u.x, r * u.y, r * u.z}, g[3], g2[3];
        nc_boulder_relief(f, k, p, 0, 0, g);
        nc_boulder_relief(f, (k + 1) % f->n, p, 0, 0, g2); /* another rock at the same point */
        double gn = g[0] * nrm.x + g[1] * nrm.y + g[2] * nrm.z;
        sum2 += g[0] * g[0] + g[1] * g[1] + g[2] * g[2] - gn * gn;
        diff += g[0] != g2[0];
    }
    double rms = sqrt(sum2 / n), want = tan(deg * M_PI / 180);
    printf("slope: RMS %.4f along a face (tan %g deg = %.4f); rocks differ at %.0f of %d points\n", rms, deg, want,
           diff, n);
    CHECK(fabs(rms / want - 1) < 0.03, "RMS slope %g, configured tan %g deg = %g", rms, deg, want);
    CHECK(diff > 0.99 * n, "two rocks share their relief at %.0f of %d points", n - diff, n);
}

/* A close frame of the test asteroid: 0.15 m pixels, rocks of 2 m and more,
 * those of mesh_px pixels or more as detailed surfaces (0: none). */
static void render_close(double deg, double mesh_px, int threads, struct nc_scene *s, struct nc_frame *f)
{
    char rocks[160], mesh[64];
    snprintf(rocks, sizeof rocks, "bodies[0].boulders={preset: bennu, min_diameter_m: 2, seed: 3, roughness_deg: %g}",
             deg);
    snprintf(mesh, sizeof mesh, "render.boulder_mesh_px=%g", mesh_px);
    const char *sets[] = {rocks, "camera.position_m=[0, -400, 0]", "render.samples_per_pixel=1", mesh};
    nc_test_scene(nc_test_asteroid_yaml, sets, 4, s);
    struct nc_renderer r;
    const int W = s->camera.width_px, H = s->camera.height_px;
    CHECK(nc_renderer_init(&r, s, threads) == 0 && nc_frame_alloc(f, W, H) == 0 &&
              (f->rock_id = malloc((size_t)W * H * sizeof *f->rock_id)) != NULL && nc_render_frame(&r, s, f) == 0,
          "%s", nc_errmsg());
    nc_renderer_free(&r);
}

/* Three close frames: a reference (deg0, mesh0 on 2 threads) and the case
 * (deg1, mesh1) on 2 threads and on 1. */
static void render_trio(double deg0, double mesh0, double deg1, double mesh1, struct nc_scene s[3],
                        struct nc_frame f[3])
{
    render_close(deg0, mesh0, 2, &s[0], &f[0]);
    render_close(deg1, mesh1, 2, &s[1], &f[1]);
    render_close(deg1, mesh1, 1, &s[2], &f[2]);
}

/* Texture on a face: over neighbouring pixel pairs (along rows and
 * columns) on the same rock whose flat-faced radiance is equal and lit (one
 * face: a Lambert face under a distant Sun is uniform), the RMS relative
 * difference of frame f; their count in *pairs. */
static double face_texture(const struct nc_frame *flat, const struct nc_frame *f, size_t *pairs)
{
    const int W = flat->width_px, H = flat->height_px;
    double s2 = 0;
    size_t n = 0;
    for (int y = 0; y + 1 < H; y++)
        for (int x = 0; x + 1 < W; x++)
            for (int d = 0; d < 2; d++) {
                size_t i = (size_t)y * W + x, j = d ? i + (size_t)W : i + 1;
                if (flat->rock_id[i] < 0 || flat->rock_id[i] != flat->rock_id[j] || !(flat->radiance[i] > 0) ||
                    flat->radiance[i] != flat->radiance[j])
                    continue;
                double r = 2 * (f->radiance[i] - f->radiance[j]) / (f->radiance[i] + f->radiance[j] + 1e-30);
                s2 += r * r, n++;
            }
    *pairs = n;
    return n ? sqrt(s2 / n) : 0;
}

/* The mean radiance of the pixels that show a rock in the flat frame. */
static double rock_mean(const struct nc_frame *flat, const struct nc_frame *f)
{
    double s = 0;
    size_t n = 0;
    for (size_t i = 0; i < (size_t)flat->width_px * flat->height_px; i++)
        if (flat->rock_id[i] >= 0)
            s += f->radiance[i], n++;
    return n ? s / n : 0;
}

static void check_render(void)
{
    struct nc_scene sc[3];
    struct nc_frame fr[3];
    render_trio(0, 0, 25, 0, sc, fr); /* flat faces; the relief in the shading */
    struct nc_scene *rough = &sc[1];
    struct nc_frame a = fr[0], b = fr[1], c = fr[2];
    size_t n = (size_t)a.width_px * a.height_px, rock = 0, ground = 0, rock_changed = 0, ground_changed = 0,
           id_changed = 0;
    for (size_t i = 0; i < n; i++) {
        id_changed += a.rock_id[i] != b.rock_id[i];
        if (a.rock_id[i] >= 0)
            rock++, rock_changed += a.radiance[i] != b.radiance[i];
        else
            ground++, ground_changed += a.radiance[i] != b.radiance[i];
    }
    printf("render: %zu rock pixels, %zu changed; %zu ground or sky pixels, %zu changed; %zu rock ids changed\n", rock,
           rock_changed, ground, ground_changed, id_changed);
    CHECK(rock > n / 20 && rock_changed > rock / 2, "%zu of %zu rock pixels changed", rock_changed, rock);
    CHECK(ground_changed == 0 && id_changed == 0, "the relief moved %zu ground pixels and %zu rock ids",
          ground_changed, id_changed);
    CHECK(!memcmp(b.radiance, c.radiance, n * sizeof *b.radiance), "1 and 2 threads differ");
    int finite = 1;
    for (size_t i = 0; i < n; i++)
        finite &= isfinite(b.radiance[i]) && b.radiance[i] >= 0;
    CHECK(finite, "a non-finite or negative pixel");
    size_t pairs;
    const double tex_b = face_texture(&a, &b, &pairs); /* 0 for the flat frame: the pairs are equal there */
    double mean = rock_mean(&a, &b) / rock_mean(&a, &a) - 1;
    printf("texture: %zu neighbouring pixel pairs equal on one lit face without relief: RMS relative difference "
           "%.4f at 25 deg; the rocks' mean radiance %+.2f %%\n", pairs, tex_b, 100 * mean);
    CHECK(pairs > 1000 && tex_b > 0.02, "face texture %g over %zu pairs", tex_b, pairs);
    CHECK(fabs(mean) < 0.1, "the relief changes the rocks' mean by %+.2f %%", 100 * mean);
    nc_frame_free(&a), nc_frame_free(&b), nc_frame_free(&c);
    nc_scene_free(&sc[0]), nc_scene_free(&sc[2]);

    /* One point of the largest rock seen from straight above and from 60 m
     * aside: the same shading normal (a function of the rock and the point,
     * not of the camera). */
    const size_t big = 0; /* the list starts with the largest rock */
    const struct nc_boulder *r = &rough->body[0].boulders.rock[big];
    struct nc_vec3 c0 = nc_v3(r->centre_m[0], r->centre_m[1], r->centre_m[2]), up = nc_v3_unit(c0);
    struct nc_vec3 side = nc_v3_unit(nc_v3_cross(up, nc_v3(0, 0, 1)));
    struct nc_vec3 cam[2] = {nc_v3_add(c0, nc_v3_scale(up, 50)), c0}, hitp = c0;
    struct nc_vec3 nrm[2];
    int32_t id[2];
    for (int v = 0; v < 2; v++) {
        rough->camera.position_m = cam[v];
        struct nc_rt *rt;
        CHECK(nc_rt_create(rough, 1, &rt) == 0, "%s", nc_errmsg());
        struct nc_vec3 d = v == 0 ? nc_v3_scale(up, -1) : nc_v3_unit(nc_v3_sub(hitp, cam[v]));
        struct nc_ray16 ray = {0};
        ray.dx[0] = (float)d.x, ray.dy[0] = (float)d.y, ray.dz[0] = (float)d.z;
        ray.tfar[0] = 1e4f;
        ray.valid[0] = -1;
        struct nc_hit16 h;
        nc_rt_intersect16(rt, &ray, &h, 0);
        nrm[v] = nc_v3_unit(nc_v3(h.nx[0], h.ny[0], h.nz[0]));
        id[v] = h.rock[0];
        if (v == 0) { /* the point hit, and a camera 60 m aside looking at it */
            hitp = nc_v3_add(cam[0], nc_v3_scale(d, h.t[0]));
            cam[1] = nc_v3_add(hitp, nc_v3_add(nc_v3_scale(up, 40), nc_v3_scale(side, 60)));
        }
        nc_rt_destroy(rt);
    }
    double ang = acos(fmin(1, nc_v3_dot(nrm[0], nrm[1])));
    printf("rock %zu: the normal at one point differs by %.2g rad between two cameras\n", big, ang);
    CHECK(id[0] == (int32_t)big && id[1] == (int32_t)big, "the rays hit rocks %d and %d, not %zu", id[0], id[1], big);
    CHECK(ang < 2e-3, "the shading normal moved by %g rad with the camera", ang);
    nc_scene_free(rough);
}

/* Each shape's detailed surface: closed (every edge in two triangles,
 * once each way), within its planes, rough. */
static void check_meshes(const struct nc_boulder_field *f)
{
    double worst = 0, slope2 = 0, area = 0;
    for (int s = 0; s < f->nshapes; s++) {
        struct nc_mesh m;
        CHECK(nc_rock_shape_mesh(f, s, NC_ROCK_MESH_SUBDIVISIONS, &m) == 0, "%s", nc_errmsg());
        const struct nc_rock_shape *sh = &f->shape[s];
        for (size_t i = 0; i < m.nv; i++)
            for (int g = 0; g < sh->nplanes; g++) {
                const double *v = m.v + 3 * i;
                worst = fmax(worst, sh->nx[g] * v[0] + sh->ny[g] * v[1] + sh->nz[g] * v[2] - sh->d[g]);
            }
        /* closed: the directed edges, each with its reverse exactly once */
        size_t ne = 3 * m.nt, unmatched = 0;
        uint64_t *e = malloc(2 * ne * sizeof *e);
        CHECK(e != NULL, "out of memory");
        for (size_t t = 0; t < m.nt; t++)
            for (int k = 0; k < 3; k++) {
                uint64_t a = m.tri[3 * t + k], b = m.tri[3 * t + (k + 1) % 3];
                e[3 * t + k] = a << 32 | b;
                e[ne + 3 * t + k] = b << 32 | a;
            }
        qsort(e, ne, sizeof *e, nc_test_cmp_u64);
        qsort(e + ne, ne, sizeof *e, nc_test_cmp_u64);
        for (size_t i = 0; i < ne; i++)
            unmatched += e[i] != e[ne + i] || (i && e[i] == e[i - 1]);
        free(e);
        CHECK(unmatched == 0, "shape %d's surface: %zu edges not in two triangles", s, unmatched);
        /* the facets' slope against the nearest plane of the shape */
        for (size_t t = 0; t < m.nt; t++) {
            struct nc_vec3 n;
            double a = nc_mesh_face(&m, t, &n), best = -2;
            for (int g = 0; g < sh->nplanes; g++)
                best = fmax(best, n.x * sh->nx[g] + n.y * sh->ny[g] + n.z * sh->nz[g]);
            double c = fmin(best, 1);
            slope2 += a * (1 - c * c) / (c * c), area += a;
        }
        if (s == 0)
            printf("meshes: %zu triangles a shape\n", m.nt);
        nc_mesh_free(&m);
    }
    /* the RMS slope the octaves in geometry give a face (the shading's own
     * scale: tan S = sqrt(2) NC_NOISE_GRAD_RMS |a|) */
    double a2 = 0;
    for (int o = 0; o < NC_ROCK_MESH_OCTAVES; o++)
        a2 += f->relief[o] * f->relief[o];
    const double geo = atan(M_SQRT2 * NC_NOISE_GRAD_RMS * sqrt(a2)) * 180 / M_PI;
    const double got = atan(sqrt(slope2 / area)) * 180 / M_PI;
    printf("meshes: vertices at most %.2g outside the planes; RMS facet slope against the nearest plane %.1f deg "
           "(roughness_deg %g, of which the octaves in geometry %.1f deg; pitted only: half the faces flat)\n",
           worst, got, f->params.roughness_deg, geo);
    CHECK(worst <= 1e-9, "a vertex %g outside its shape's planes", worst);
    CHECK(got > 0.5 * geo && got < 1.5 * geo, "the surfaces' slope %.1f deg for %.1f deg in geometry", got, geo);
}

/* Rocks resolved by 16 pixels or more as detailed surfaces, against the
 * same frame with every rock flat-faced (relief in the shading): pixels
 * change (outlines, pits, shadows), the same rocks in view, the frame's
 * total and the rocks' mean radiance within the stated tolerances, 1 and
 * 2 threads alike. */
static void check_mesh_render(void)
{
    struct nc_scene sc[3];
    struct nc_frame fr[3];
    render_trio(25, 0, 25, 16, sc, fr);
    struct nc_frame a = fr[0], b = fr[1], c = fr[2];
    const size_t n = (size_t)a.width_px * a.height_px;
    size_t rock = 0, id_changed = 0, changed = 0;
    double sa = 0, sb = 0, ra = 0, rb = 0;
    int finite = 1;
    for (size_t i = 0; i < n; i++) {
        sa += a.radiance[i], sb += b.radiance[i];
        changed += a.radiance[i] != b.radiance[i];
        finite &= isfinite(b.radiance[i]) && b.radiance[i] >= 0;
        if (a.rock_id[i] >= 0 || b.rock_id[i] >= 0) {
            rock++, id_changed += a.rock_id[i] != b.rock_id[i];
            ra += a.radiance[i], rb += b.radiance[i];
        }
    }
    printf("detailed surfaces (16 px): %zu of %zu pixels changed; %zu of %zu rock pixels show another rock or "
           "ground; frame total %+.3f %%, the rocks' pixels %+.2f %%\n", changed, n, id_changed, rock,
           100 * (sb / sa - 1), 100 * (rb / ra - 1));
    CHECK(finite, "a non-finite or negative pixel");
    CHECK(changed > n / 50, "the detailed surfaces changed only %zu pixels", changed);
    CHECK(id_changed < rock / 10, "%zu of %zu rock pixels changed rock", id_changed, rock);
    CHECK(fabs(sb / sa - 1) < 0.01 && fabs(rb / ra - 1) < 0.03, "total %+.3f %%, rocks %+.2f %%",
          100 * (sb / sa - 1), 100 * (rb / ra - 1));
    CHECK(!memcmp(b.radiance, c.radiance, n * sizeof *b.radiance) && !memcmp(b.rock_id, c.rock_id, n * sizeof *b.rock_id),
          "1 and 2 threads differ with detailed surfaces");
    nc_frame_free(&a), nc_frame_free(&b), nc_frame_free(&c);
    for (int i = 0; i < 3; i++)
        nc_scene_free(&sc[i]);
}

/* Close to a rock traced as its detailed surface, the Sun behind the camera:
 * every point seen is lit, so at one sample a pixel none is black. A shadow
 * ray starts 4e-6 of its camera distance off the surface, less than the
 * rock's placement in its tile is known to, so its origin can lie under the
 * surface; the surface is one-sided, as the planes are, and does not stop it
 * (before: thousands of black pixels at 1 m, and the rock's light 5 % low
 * even at 30 m). The mean against flat faces is printed, not checked: at
 * 1 m the frame sees a patch of one face, whose tilt the relief sets. */
static void check_close_sun_behind(void)
{
    const char *rocks = "bodies[0].boulders={preset: bennu, min_diameter_m: 2, seed: 3, roughness_deg: 20}";
    struct nc_scene s0;
    nc_test_scene(nc_test_asteroid_yaml, &rocks, 1, &s0);
    const struct nc_boulder *r = &s0.body[0].boulders.rock[0]; /* the largest */
    const struct nc_vec3 c = nc_v3(r->centre_m[0], r->centre_m[1], r->centre_m[2]), up = nc_v3_unit(c),
                         cam = nc_v3_add(c, nc_v3_scale(up, r->half_m + 1)), side = nc_v3_cross(up, nc_v3(0, 0, 1));
    char pos[128], at[128], upv[128], sun[128];
    snprintf(pos, sizeof pos, "camera.position_m=[%.17g, %.17g, %.17g]", cam.x, cam.y, cam.z);
    snprintf(at, sizeof at, "camera.look_at_m=[%.17g, %.17g, %.17g]", c.x, c.y, c.z);
    snprintf(upv, sizeof upv, "camera.up=[%.17g, %.17g, %.17g]", side.x, side.y, side.z);
    snprintf(sun, sizeof sun, "sun.direction=[%.17g, %.17g, %.17g]", up.x, up.y, up.z);
    /* a camera at the rock's centre is inside it (rocks are one-sided: it would see out of it unwarned), one
     * 1 m above its top is not */
    const struct nc_vec3 at_c[2] = {c, cam};
    long in[2];
    for (int v = 0; v < 2; v++) {
        s0.camera.position_m = at_c[v];
        struct nc_rt *rt;
        struct nc_rt_stats st;
        int body = -1;
        CHECK(nc_rt_create(&s0, 1, &rt) == 0, "%s", nc_errmsg());
        nc_rt_get_stats(rt, &st);
        in[v] = nc_rt_camera_in_rock(&st, s0.nbodies, &body);
        nc_rt_destroy(rt);
    }
    printf("a camera at the largest rock's centre is inside rock %ld; 1 m above its top, %ld\n", in[0], in[1]);
    CHECK(in[0] == 0 && in[1] == -1, "camera inside rock %ld at its centre, %ld above it (want 0, -1)", in[0], in[1]);
    nc_scene_free(&s0);
    /* The rock's place to float rounding of its tile's spread: the camera
     * stepped 0.31 mm at a time along the ray of the centre pixel of a 9 x 9
     * frame (one sample: that pixel's centre), toward the rock's face 1 m
     * away, sees it that much nearer each time (a tile's origin at the
     * middle of its cube, tens of km from its rocks, put 0.2-0.8 mm errors
     * on the range that jumped between such steps). Then, with the camera at
     * the rock's centre, looking out through its detailed surface, the rock is
     * in no pixel: its inner side stops no ray (the camera ray met it, and
     * its frame was the rock's back). */
    double worst = 0, r0 = 0;
    for (int k = 0; k < 7; k++) {
        const struct nc_vec3 ck = nc_v3_add(cam, nc_v3_scale(up, -0.31e-3 * k)), looks[2] = {ck, c};
        char cpos[2][128];
        for (int v = 0; v < 2; v++)
            snprintf(cpos[v], sizeof cpos[v], "camera.position_m=[%.17g, %.17g, %.17g]", looks[v].x, looks[v].y,
                     looks[v].z);
        const char *sets[] = {rocks, cpos[k == 6], at, upv, "camera.width_px=9", "camera.height_px=9",
                              "render.samples_per_pixel=1", "render.boulder_mesh_px=16"};
        if (k == 6) { /* at the centre, looking out, away from the body (down, the buried part is under the ground) */
            struct nc_vec3 out = nc_v3_add(c, up);
            snprintf(cpos[0], sizeof cpos[0], "camera.look_at_m=[%.17g, %.17g, %.17g]", out.x, out.y, out.z);
            sets[2] = cpos[0];
        }
        struct nc_scene s;
        struct nc_frame f;
        struct nc_renderer rr;
        nc_test_scene(nc_test_asteroid_yaml, sets, 8, &s);
        CHECK(nc_renderer_init(&rr, &s, 2) == 0 && nc_frame_alloc(&f, 9, 9) == 0 &&
                  (f.geom = calloc(NC_GEOM_PLANES * 81, sizeof *f.geom)) != NULL &&
                  (f.rock_id = malloc(81 * sizeof *f.rock_id)) != NULL && nc_render_frame(&rr, &s, &f) == 0,
              "%s", nc_errmsg());
        if (k < 6) {
            const double rk = f.geom[NC_GEOM_RANGE * 81 + 40];
            r0 = k ? r0 : rk;
            worst = fmax(worst, fabs(rk - (r0 - 0.31e-3 * k)));
            CHECK(f.rock_id[40] == 0, "the centre pixel shows rock %d, not the largest", f.rock_id[40]);
        } else {
            int rock0 = 0;
            for (int i = 0; i < 81; i++)
                rock0 += f.rock_id[i] == 0;
            printf("1 m from the largest rock's face, stepped 0.31 mm at a time: the range off by %.3g m at most; "
                   "from its centre, the rock in %d of 81 pixels\n", worst, rock0);
            CHECK(worst < 5e-6, "the range to the rock moved by %.3g m more or less than the camera", worst);
            CHECK(rock0 == 0, "a camera inside a rock's detailed surface sees the rock in %d of 81 pixels", rock0);
        }
        nc_renderer_free(&rr);
        nc_frame_free(&f);
        nc_scene_free(&s);
    }
    double mean[2];
    size_t dark = 0, seen = 0;
    for (int detailed = 0; detailed < 2; detailed++) {
        const char *sets[] = {rocks, pos, at, upv, sun, "camera.width_px=64", "camera.height_px=64",
                              "render.samples_per_pixel=1", detailed ? "render.boulder_mesh_px=16" : "render.boulder_mesh_px=0"};
        struct nc_scene s;
        struct nc_frame f;
        struct nc_renderer rr;
        nc_test_scene(nc_test_asteroid_yaml, sets, 9, &s);
        CHECK(nc_renderer_init(&rr, &s, 2) == 0 && nc_frame_alloc(&f, 64, 64) == 0 &&
                  (f.rock_id = malloc(64 * 64 * sizeof *f.rock_id)) != NULL && nc_render_frame(&rr, &s, &f) == 0,
              "%s", nc_errmsg());
        double sum = 0;
        size_t n = 0;
        for (size_t i = 0; i < 64 * 64; i++)
            if (f.rock_id[i] == 0) {
                sum += f.radiance[i], n++;
                if (detailed)
                    dark += f.radiance[i] == 0, seen++;
            }
        mean[detailed] = n ? sum / (double)n : 0;
        nc_renderer_free(&rr);
        nc_frame_free(&f);
        nc_scene_free(&s);
    }
    printf("1 m from the largest rock, the Sun behind the camera: %zu of %zu detailed-surface pixels black; its mean "
           "%+.2f %% from flat faces\n", dark, seen, 100 * (mean[1] / mean[0] - 1));
    CHECK(seen > 64 * 64 / 2 && dark == 0, "%zu of %zu pixels of the rock black with the Sun behind the camera", dark,
          seen);
}

int main(void)
{
    struct nc_mesh m;
    nc_test_asteroid_mesh(4, 20, &m);
    struct nc_boulder_params bp = {.d_min_m = 1, .d_max_m = 64, .burial_min = 0.1, .burial_max = 0.5, .shapes = 48,
                                   .seed = 5};
    CHECK(nc_boulder_preset("bennu", &bp) == 0, "%s", nc_errmsg());
    for (double deg = 10; deg <= 40; deg += 15) {
        struct nc_boulder_field f;
        bp.roughness_deg = deg;
        CHECK(nc_boulders_generate(&m, &bp, 1000000, &f) == 0 && f.n > 1000, "%s", nc_errmsg());
        check_slope(&f, deg);
        nc_boulders_free(&f);
    }
    bp.roughness_deg = 0;
    struct nc_boulder_field f;
    CHECK(nc_boulders_generate(&m, &bp, 1000000, &f) == 0, "%s", nc_errmsg());
    double g[3] = {1, 1, 1}, q[3] = {0.3, -0.2, 0.5};
    nc_boulder_relief(&f, 0, q, 0, 0, g);
    CHECK(g[0] == 0 && g[1] == 0 && g[2] == 0, "flat faces have a gradient");
    nc_boulders_free(&f);
    /* The pixel's footprint: every octave whole where the finest spans 4
     * footprints, none where the coarsest spans 2, in between less. */
    bp.roughness_deg = 25;
    CHECK(nc_boulders_generate(&m, &bp, 1000000, &f) == 0, "%s", nc_errmsg());
    double g0[3], g1[3], g2[3], g3[3];
    nc_boulder_relief(&f, 7, q, 0, 0, g0);
    nc_boulder_relief(&f, 7, q, 0.125 / 4, 0, g1);
    nc_boulder_relief(&f, 7, q, 0.125 / 3, 0, g2);
    nc_boulder_relief(&f, 7, q, 0.5 / 2, 0, g3);
    CHECK(!memcmp(g0, g1, sizeof g0) && memcmp(g0, g2, sizeof g0) && g3[0] == 0 && g3[1] == 0 && g3[2] == 0,
          "the footprint's fade: (%g %g %g) whole, (%g %g %g) at 4 footprints, (%g %g %g) at 3, (%g %g %g) at none",
          g0[0], g0[1], g0[2], g1[0], g1[1], g1[2], g2[0], g2[1], g2[2], g3[0], g3[1], g3[2]);
    nc_boulders_free(&f);
    bp.roughness_deg = 46;
    CHECK(nc_boulders_generate(&m, &bp, 1000000, &f) < 0 && nc_test_contains(nc_errmsg(), "roughness"),
          "a roughness of 46 deg: %s", nc_errmsg());
    bp.roughness_deg = 25;
    CHECK(nc_boulders_generate(&m, &bp, 1000000, &f) == 0, "%s", nc_errmsg());
    check_meshes(&f);
    nc_boulders_free(&f);
    nc_mesh_free(&m);
    check_render();
    check_mesh_render();
    check_close_sun_behind();
    return nc_test_end();
}
