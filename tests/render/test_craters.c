/* test_craters.c - crater populations and morphology (craters.h): the
 * configured SFD slope and density recovered from the generated list and
 * centres uniform over the surface; the same craters and the same carved
 * mesh from the same seed; on a flat grid, a fresh crater's floor, rim and
 * ejecta at the heights of the profile, an old one shallower by its age, a
 * young crater erasing the older relief inside its cavity, and a crater
 * smaller than the mesh spacing left out; the config forms (count,
 * density, saturation) and their errors; the population counted in
 * rendered frames (cavities that show) recovering the slope and density;
 * and a deep crater on a rough relief mesh, carved along the surface under
 * the relief, folding no face over. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/rng.h"
#include "render/craters.h"
#include "render/image_io.h"
#include "render/mesh.h"
#include "render/render.h"
#include "testutil.h"

static void check_population(void)
{
    struct nc_asteroid_params ap = {.radii_m = {1000, 1000, 1000}, .subdivisions = 4, .seed = 3};
    struct nc_mesh m;
    CHECK(nc_mesh_asteroid(&ap, &m) == 0, "%s", nc_errmsg());
    double area = 1e-6 * nc_mesh_area_m2(&m);
    const double slopes[] = {1.8, 2.0, 3.0};
    for (int k = 0; k < 3; k++) {
        struct nc_crater_params p;
        nc_crater_params_default(&m, &p);
        p.slope = slopes[k];
        p.d_min_m = 1;
        p.d_max_m = 500;
        p.seed = 11 + (uint64_t)k;
        p.c_per_km2 = nc_craters_density_for(&p, area, 200000);
        struct nc_crater_field f;
        CHECK(nc_craters_generate(&m, &p, NC_CRATERS_MAX, &f) == 0, "%s", nc_errmsg());
        double *d = malloc(f.n * sizeof *d);
        size_t over[4] = {0}, oct[8] = {0};
        int sorted = 1, on = 1;
        for (size_t i = 0; i < f.n; i++) {
            const struct nc_crater *c = &f.crater[i];
            d[i] = c->d_m;
            for (int j = 0; j < 4; j++)
                over[j] += c->d_m > 2 * exp2(j);
            oct[(c->centre_m[0] > 0) | (c->centre_m[1] > 0) << 1 | (c->centre_m[2] > 0) << 2]++;
            sorted &= i == 0 || f.crater[i - 1].age >= c->age;
            double r = sqrt(c->centre_m[0] * c->centre_m[0] + c->centre_m[1] * c->centre_m[1] +
                            c->centre_m[2] * c->centre_m[2]);
            on &= r <= 1000 * (1 + 1e-12) && r > 990; /* on a face of the icosphere */
        }
        double b = nc_test_fit_slope(d, f.n, p.d_min_m, p.d_max_m);
        CHECK(fabs(b / p.slope - 1) < 0.05, "slope %.4f fitted, %.4f configured", b, p.slope);
        CHECK(fabs((double)f.n / 200000 - 1) < 0.05, "%zu craters, 200000 expected", f.n);
        for (int j = 0; j < 4; j++) { /* N(>D) = C A (D^-b - Dmax^-b) at D = 2, 4, 8, 16 m */
            double D = 2 * exp2(j), want = p.c_per_km2 * area * (pow(D, -p.slope) - pow(p.d_max_m, -p.slope));
            if (want > 2000)
                CHECK(fabs((double)over[j] / want - 1) < 0.05, "N(>%g m) = %zu, %.0f expected (slope %g)", D,
                      over[j], want, p.slope);
        }
        for (int o = 0; o < 8; o++)
            CHECK(fabs((double)oct[o] / ((double)f.n / 8) - 1) < 0.05, "octant %d holds %zu of %zu", o, oct[o], f.n);
        CHECK(sorted, "the list runs from the oldest crater to the youngest");
        CHECK(on, "every centre lies on the surface");
        /* Same seed, same list, bit for bit. */
        struct nc_crater_field g;
        CHECK(nc_craters_generate(&m, &p, NC_CRATERS_MAX, &g) == 0, "%s", nc_errmsg());
        CHECK(g.n == f.n && !memcmp(g.crater, f.crater, f.n * sizeof *f.crater), "same seed, same craters");
        nc_craters_free(&g);
        free(d);
        nc_craters_free(&f);
    }
    /* Too many is an error that names the count. */
    struct nc_crater_params p;
    nc_crater_params_default(&m, &p);
    p.c_per_km2 = 1e12;
    struct nc_crater_field f;
    CHECK(nc_craters_generate(&m, &p, 1000, &f) == NC_ERANGE && nc_test_contains(nc_errmsg(), "min_diameter_m"),
          "an absurd population is refused: %s", nc_errmsg());
    nc_mesh_free(&m);
}

/* A flat square grid in z = 0, side n * step metres, centred on the origin,
 * faces wound toward +z. */
static void grid_mesh(int n, double step, struct nc_mesh *m)
{
    m->nv = (size_t)(n + 1) * (size_t)(n + 1);
    m->nt = 2 * (size_t)n * (size_t)n;
    m->v = malloc(3 * m->nv * sizeof *m->v);
    m->tri = malloc(3 * m->nt * sizeof *m->tri);
    for (int y = 0; y <= n; y++)
        for (int x = 0; x <= n; x++) {
            double *v = m->v + 3 * (size_t)(y * (n + 1) + x);
            v[0] = (x - n / 2) * step;
            v[1] = (y - n / 2) * step;
            v[2] = 0;
        }
    size_t t = 0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            uint32_t a = (uint32_t)(y * (n + 1) + x), b = a + 1, c = a + (uint32_t)(n + 1), d = c + 1;
            const uint32_t q[6] = {a, b, d, a, d, c};
            memcpy(m->tri + 3 * t, q, sizeof q);
            t += 2;
        }
}

/* Height of the grid vertex at (x, y) metres. */
static double height_at(const struct nc_mesh *m, int n, double step, double x, double y)
{
    int i = (int)lround(x / step) + n / 2, j = (int)lround(y / step) + n / 2;
    return m->v[3 * (size_t)(j * (n + 1) + i) + 2];
}

static void carve(struct nc_mesh *m, struct nc_crater *c, size_t n, struct nc_crater_field *f)
{
    memset(f, 0, sizeof *f);
    nc_crater_params_default(m, &f->params);
    f->crater = c;
    f->n = n;
    CHECK(nc_craters_apply(f, m, NULL) == 0, "%s", nc_errmsg());
}

static void check_morphology(void)
{
    const int n = 200;
    const double step = 1; /* 200 m square, 1 m spacing */
    struct nc_mesh m;
    grid_mesh(n, step, &m);
    struct nc_crater_params p;
    nc_crater_params_default(&m, &p);
    /* A fresh crater of 40 m centred on a vertex. */
    struct nc_crater c = {.centre_m = {0, 0, 0}, .normal = {0, 0, 1}, .d_m = 40, .age = 0};
    struct nc_crater_field f;
    carve(&m, &c, 1, &f);
    double rim = 0.036 * 40, depth = 0.196 * 40;
    CHECK(f.applied == 1, "the crater is carved");
    CHECK(fabs(height_at(&m, n, step, 0, 0) - (rim - depth)) < 1e-9, "floor at %.6f m, %.6f expected (Pike 1977)",
          height_at(&m, n, step, 0, 0), rim - depth);
    CHECK(fabs(height_at(&m, n, step, 20, 0) - rim) < 1e-9, "rim crest at %.6f m, %.6f expected",
          height_at(&m, n, step, 20, 0), rim);
    CHECK(fabs(height_at(&m, n, step, 10, 0) - (rim - 0.75 * depth)) < 1e-9, "cavity wall at r = R/2: %.6f m",
          height_at(&m, n, step, 10, 0));
    /* Ejecta (r/R)^-3, tapered: at r = 2R, rim * (1 - 1/4) / 8. */
    CHECK(fabs(height_at(&m, n, step, 0, -40) - rim * 0.75 / 8) < 1e-9, "ejecta at 2R: %.6f m, %.6f expected",
          height_at(&m, n, step, 0, -40), rim * 0.75 / 8);
    CHECK(height_at(&m, n, step, 60, 0) == 0 && height_at(&m, n, step, 43, 43) == 0, "nothing beyond 3R");
    nc_mesh_free(&m);

    /* Age: the oldest keeps half its depth (degradation 0.5) and a quarter of its rim. */
    grid_mesh(n, step, &m);
    c.age = 0.999;
    carve(&m, &c, 1, &f);
    double k = 1 - 0.5 * 0.999;
    CHECK(fabs(height_at(&m, n, step, 0, 0) - (rim * k * k - depth * k)) < 1e-9, "old floor at %.6f m",
          height_at(&m, n, step, 0, 0));
    nc_mesh_free(&m);

    /* Overlap: an old 80 m crater, then a young 20 m one on its wall. Inside
     * the young cavity the old slope is gone: the floor is the profile about
     * the mean height the old crater left there, symmetric about its centre. */
    grid_mesh(n, step, &m);
    struct nc_crater two[2] = {{.centre_m = {0, 0, 0}, .normal = {0, 0, 1}, .d_m = 80, .age = 0.8},
                               {.centre_m = {25, 0, 0}, .normal = {0, 0, 1}, .d_m = 20, .age = 0.1}};
    carve(&m, two, 2, &f);
    CHECK(f.applied == 2, "both craters carved");
    double left = height_at(&m, n, step, 25 - 6, 0), right = height_at(&m, n, step, 25 + 6, 0);
    double up = height_at(&m, n, step, 25, 6), down = height_at(&m, n, step, 25, -6);
    CHECK(fabs(left - right) < 1e-9 && fabs(up - down) < 1e-9 && fabs(left - up) < 1e-9,
          "the young cavity erases the old wall: %.6f %.6f %.6f %.6f m", left, right, up, down);
    double kk = 1 - 0.5 * 0.1;
    CHECK(fabs((left - height_at(&m, n, step, 25, 0)) - 0.196 * 20 * kk * 0.36) < 1e-9,
          "young profile: wall at 0.6 R rises %.6f m above the floor", left - height_at(&m, n, step, 25, 0));
    /* Order matters: the old crater carved last would cut the young one. */
    struct nc_mesh m2;
    grid_mesh(n, step, &m2);
    struct nc_crater swapped[2] = {two[1], two[0]};
    carve(&m2, swapped, 2, &f);
    CHECK(fabs(height_at(&m2, n, step, 25 - 6, 0) - height_at(&m2, n, step, 25 + 6, 0)) > 0.1,
          "carved in the other order the young crater is cut by the old one");
    nc_mesh_free(&m2);
    nc_mesh_free(&m);

    /* Smaller than the spacing, between vertices: not carved, not counted. */
    grid_mesh(n, step, &m);
    struct nc_crater tiny = {.centre_m = {0.5, 0.5, 0}, .normal = {0, 0, 1}, .d_m = 0.6, .age = 0};
    carve(&m, &tiny, 1, &f);
    CHECK(f.applied == 0 && height_at(&m, n, step, 0, 0) == 0, "a crater holding no vertex is left out");
    nc_mesh_free(&m);
}

static void check_config(void)
{
    const char *base = "bodies:\n"
                       "  - shape: {type: asteroid, radii_m: [300, 250, 200], subdivisions: 5, seed: 4}\n"
                       "    material: {model: lambert, A: 0.1}\n"
                       "sun: {direction: [1, 0, 0]}\n"
                       "camera: {width_px: 64, height_px: 64, focal_length_m: 0.05, pixel_pitch_m: 1e-5,\n"
                       "         position_m: [0, -3000, 0], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n";
    struct nc_scene a, b;
    /* The number form and the map form with the same count carve the same mesh. */
    const char *n1[] = {"bodies[0].shape.craters=300"}, *n2[] = {"bodies[0].shape.craters={count: 300}"};
    nc_test_scene(base, n1, 1, &a);
    nc_test_scene(base, n2, 1, &b);
    CHECK(a.body[0].mesh.nv == b.body[0].mesh.nv &&
              !memcmp(a.body[0].mesh.v, b.body[0].mesh.v, 3 * a.body[0].mesh.nv * sizeof(double)),
          "craters: 300 and {count: 300} give the same body");
    nc_scene_free(&b);
    const char *n3[] = {"bodies[0].shape.craters=0"};
    nc_test_scene(base, n3, 1, &b);
    CHECK(memcmp(a.body[0].mesh.v, b.body[0].mesh.v, 3 * a.body[0].mesh.nv * sizeof(double)) != 0,
          "the craters move the surface");
    nc_scene_free(&a);
    nc_scene_free(&b);
    static const struct {
        const char *set, *says;
    } bad[] = {
        {"bodies[0].shape.craters={count: 10, saturation: 0.05}", "give one of"},
        {"bodies[0].shape.craters={slope: 2}", "give one of"},
        {"bodies[0].shape.craters={saturation: 0.05, slope: 3}", "saturation implies slope 2"},
        {"bodies[0].shape.craters={count: 10, min_diameter_m: 50, max_diameter_m: 20}", "must exceed"},
        {"bodies[0].shape.craters={count: 10, depth: 0.2}", "depth"},
        {"bodies[0].shape.craters={density_per_km2: 1e15, min_diameter_m: 0.001}", "min_diameter_m"},
        /* beyond ten times geometric saturation (2 million craters on the default asteroid at subdivisions 3
         * took 6.5 min to carve) */
        {"bodies[0].shape.craters=2000000", "is 2.4e+03 times geometric saturation (1.54e6 D^-2) at D = 247 m: "
                                            "at most 10 times"},
        {"bodies[0].shape.craters={density_per_km2: 1e9, slope: 3}", "17.4 times geometric saturation (1.54e6 "
                                                                       "D^-2) at D = 37.2 m: at most 10 times "
                                                                       "(beyond it craters only erase each other; "
                                                                       "real surfaces saturate at a few per cent of "
                                                                       "it): a smaller count, density_per_km2 or "
                                                                       "saturation, or a larger min_diameter_m"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *set[] = {bad[i].set};
        struct nc_scene s;
        int rc = nc_test_scene_rc(base, set, 1, &s);
        CHECK(rc < 0 && nc_test_contains(nc_errmsg(), bad[i].says), "%s: rc %d, '%s'", bad[i].set, rc, nc_errmsg());
        if (rc == 0)
            nc_scene_free(&s);
    }
}


/* The population in a rendered frame: flat 512 m DEM tiles (0.5 m posts)
 * with craters of 3 to 40 m, slope 2, each seen straight down from 400 m at
 * 2048x2048 (0.25 m pixels at the centre: the smallest crater 12 pixels
 * across). A crater counts as seen when the frame shows its cavity: the
 * surface points of the pixels (each pixel's range along its centre's ray,
 * one sample) within 0.35 radii of its centre lie lower than those on its
 * rim (0.9 to 1.1 radii) by at least a quarter of its depth (Pike's
 * 0.196 D, less what its age took). Over TILES tiles (seeds), the craters
 * seen recover the configured slope and density within 5 % (the
 * statistical 1-sigma, 1/sqrt(N), is printed); those not seen are where
 * other craters' cavities and ejecta changed the relief. */
enum { TILES = 4, TILE_COUNT = 700 };
static const double tile_post = 0.5, tile_d_lo = 3, tile_d_hi = 40, tile_slope = 2, tile_half = 200;

/* One tile: the diameters of the craters seen (centres in the central
 * square of side 2 tile_half, whose rims are all in the frame) appended to
 * seen, and how many have centres there. */
static void frame_tile(const char *dem, int seed, double *seen, size_t *nseen, size_t *in_view)
{
    enum { W = 2048 };
    const double H = 400, F = 1650;
    char yaml[2048];
    snprintf(yaml, sizeof yaml,
             "bodies:\n"
             "  - shape: {type: dem, file: '%s', pixel_m: %g,\n"
             "            craters: {count: %d, min_diameter_m: %g, max_diameter_m: %g, slope: %g, seed: %d}}\n"
             "    material: {model: lambert, A: 0.1}\n"
             "sun: {direction: [0.3, 0.2, 1]}\n"
             "camera: {width_px: %d, height_px: %d, fx_px: %g, fy_px: %g, position_m: [0, 0, %g],\n"
             "         look_at_m: [0, 0, 0], up: [0, 1, 0]}\n"
             "render: {samples_per_pixel: 1}\n",
             dem, tile_post, TILE_COUNT, tile_d_lo, tile_d_hi, tile_slope, seed, W, W, F, F, H);
    struct nc_scene s;
    nc_test_scene(yaml, NULL, 0, &s);
    struct nc_frame f;
    nc_test_render(&s, 2, &f);
    const struct nc_crater_field *cf = &s.body[0].craters;
    const struct nc_vec3 cam = s.camera.position_m;
    const struct nc_mat3 Rc = nc_quat_to_mat(s.camera.attitude_q);
    for (size_t k = 0; k < cf->n; k++) {
        const struct nc_crater *c = &cf->crater[k];
        if (fabs(c->centre_m[0]) > tile_half || fabs(c->centre_m[1]) > tile_half)
            continue;
        (*in_view)++;
        const double R = c->d_m / 2;
        double x, y;
        struct nc_vec3 dc = nc_mat_tmul_v(&Rc, nc_v3_sub(nc_v3(c->centre_m[0], c->centre_m[1], c->centre_m[2]), cam));
        CHECK(nc_camera_project(&s.camera, dc, &x, &y) == 0, "crater %zu projects", k);
        const int r_px = (int)ceil(1.2 * R * F / (H - c->centre_m[2])) + 2;
        double in = 0, rim = 0;
        int n_in = 0, n_rim = 0;
        for (int py = (int)y - r_px; py <= (int)y + r_px; py++)
            for (int px = (int)x - r_px; px <= (int)x + r_px; px++) {
                const size_t i = (size_t)py * W + (size_t)px;
                if (px < 0 || py < 0 || px >= W || py >= W || !(f.coverage[i] > 0))
                    continue;
                struct nc_vec3 d = nc_v3_unit(nc_mat_mul_v(&Rc, nc_camera_dir(&s.camera, px, py)));
                struct nc_vec3 q = nc_v3_add(cam, nc_v3_scale(d, f.range_m[i]));
                const double rho = hypot(q.x - c->centre_m[0], q.y - c->centre_m[1]) / R;
                if (rho < 0.35)
                    in += q.z, n_in++;
                else if (rho > 0.9 && rho < 1.1)
                    rim += q.z, n_rim++;
            }
        const double depth = cf->params.depth_ratio * c->d_m * (1 - cf->params.degradation * c->age);
        if (n_in && n_rim && rim / n_rim - in / n_in >= 0.25 * depth)
            seen[(*nseen)++] = c->d_m;
    }
    nc_frame_free(&f);
    nc_scene_free(&s);
}

static void check_frame_count(void)
{
    enum { DEM = 1024 };
    float *h = calloc(DEM * DEM, sizeof *h);
    const char *dem = nc_test_path("flat_tile.fits");
    CHECK(nc_image_write(dem, h, DEM, DEM, NULL, 0, NULL) == 0, "%s", nc_errmsg());
    free(h);
    double *seen = malloc(TILES * 4 * TILE_COUNT * sizeof *seen);
    size_t nseen = 0, in_view = 0;
    for (int t = 0; t < TILES; t++)
        frame_tile(dem, 5 + t, seen, &nseen, &in_view);
    const double b = nc_test_fit_slope(seen, nseen, tile_d_lo, tile_d_hi);
    /* the configured density: the mean count over a tile's area, per m^2 */
    const double tile_m2 = (DEM * tile_post) * (DEM * tile_post);
    const double want = TILES * TILE_COUNT / tile_m2 * (2 * tile_half) * (2 * tile_half);
    printf("frame: %zu of %zu craters with centres in the central %g m squares of %d tiles seen (cavity below the "
           "rim); slope %.3f from their diameters (configured %g, 1-sigma %.1f %%); %zu seen against %.0f "
           "configured there (1-sigma %.1f %%)\n",
           nseen, in_view, 2 * tile_half, TILES, b, tile_slope, 100 / sqrt((double)nseen), nseen, want,
           100 / sqrt(want));
    CHECK(nseen > 1000, "only %zu craters seen", nseen);
    CHECK(fabs(b / tile_slope - 1) < 0.05, "slope %.3f from the frames, configured %g", b, tile_slope);
    CHECK(fabs((double)nseen / want - 1) < 0.05, "%zu craters seen, %.0f configured", nseen, want);
    free(seen);
}

/* Faces of m whose normal points against the direction the relief and the
 * craters displaced their corners along (dir): folded over. */
static size_t folded(const struct nc_mesh *m, const double *dir)
{
    size_t n = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *f = m->tri + 3 * t;
        const double *a = m->v + 3 * f[0], *b = m->v + 3 * f[1], *c = m->v + 3 * f[2];
        double u[3], v[3], dot = 0;
        for (int k = 0; k < 3; k++)
            u[k] = b[k] - a[k], v[k] = c[k] - a[k];
        const double nrm[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        for (int k = 0; k < 3; k++)
            dot += nrm[k] * (dir[3 * f[0] + k] + dir[3 * f[1] + k] + dir[3 * f[2] + k]);
        n += dot <= 0;
    }
    return n;
}

/* A rough model (an icosphere of 100 m with its vertices moved along their
 * radii by up to +-1.5 m), relief to a quarter of its edge continuing that
 * roughness, and a crater 60 m across (12 m deep) on it. Carved along the
 * normals under the relief it adds no folded face; along the relief's own
 * vertex normals (the old way) it folded some, which a camera sees as holes
 * (the faces' backs, unlit). */
static void check_relief_fold(void)
{
    long fold[2]; /* faces the crater folded over, net */
    for (int way = 0; way < 2; way++) {
        struct nc_mesh m;
        struct nc_asteroid_params ap = {.radii_m = {100, 100, 100}, .subdivisions = 4}; /* no lumps, no craters */
        CHECK(nc_mesh_asteroid(&ap, &m) == 0, "%s", nc_errmsg());
        if (nc_test_failed)
            return;
        for (size_t i = 0; i < m.nv; i++) {
            double *p = m.v + 3 * i, r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
            double k = (100 + 3 * ((double)(nc_rng_seed(7, 0, i) >> 11) * 0x1.0p-53 - 0.5)) / r;
            p[0] *= k, p[1] *= k, p[2] *= k;
        }
        const double edge_m = 0.25 * nc_mesh_mean_edge_m(&m);
        struct nc_relief_params rp = {.edge_m = edge_m, .hurst = 0.8, .amplitude = 1, .seed = 3};
        struct nc_relief_info info;
        double *under = NULL;
        CHECK(nc_mesh_relief(&m, &rp, NC_RELIEF_MAX_TRIANGLES, &info, &under) == 0 && under && info.levels == 2, "%s",
              nc_errmsg());
        double *own = malloc(3 * m.nv * sizeof *own);
        if (!own || !under) {
            free(own);
            free(under);
            nc_mesh_free(&m);
            return;
        }
        const size_t before = folded(&m, under);
        struct nc_crater c = {.centre_m = {0, 0, 100}, .normal = {0, 0, 1}, .d_m = 60, .age = 0};
        struct nc_crater_field f;
        memset(&f, 0, sizeof f);
        nc_crater_params_default(&m, &f.params);
        f.crater = &c;
        f.n = 1;
        nc_mesh_vertex_normals(&m, own);
        CHECK(nc_craters_apply(&f, &m, way ? own : under) == 0 && f.applied == 1, "%s", nc_errmsg());
        fold[way] = (long)folded(&m, under) - (long)before;
        printf("crater on rough relief (%zu faces, s %.3g), carved along %s: %ld faces folded over (%zu before)\n",
               m.nt, info.s, way ? "the relief's vertex normals" : "the normals under the relief", fold[way], before);
        free(own);
        free(under);
        nc_mesh_free(&m);
    }
    CHECK(fold[0] <= 0, "%ld faces folded over by the crater", fold[0]);
}

int main(void)
{
    check_relief_fold();
    check_population();
    check_frame_count();
    check_morphology();
    check_config();
    return nc_test_end();
}
