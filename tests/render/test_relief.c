/* test_relief.c - relief below a mesh's resolution (nc_mesh_relief): the
 * model's facets keep their mean heights, the same seed gives the same surface,
 * the relief's roughness falls with scale as the stated Hurst exponent
 * says, and its amplitude continues the model's own roughness; the config
 * form and its errors. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/rng.h"
#include "testutil.h"

/* A 640 m square of 10 m cells in z = 0 with Gaussian heights of 1 m RMS:
 * a model rough at its own resolution. */
static void rough_grid(struct nc_mesh *m)
{
    const int n = 64;
    m->nv = (size_t)(n + 1) * (n + 1);
    m->nt = 2 * (size_t)n * n;
    m->v = malloc(3 * m->nv * sizeof *m->v);
    m->tri = malloc(3 * m->nt * sizeof *m->tri);
    uint64_t s = 5;
    for (int y = 0; y <= n; y++)
        for (int x = 0; x <= n; x++) {
            double *v = m->v + 3 * (size_t)(y * (n + 1) + x), u = nc_rng_uniform(&s), w = nc_rng_uniform(&s);
            v[0] = 10.0 * x;
            v[1] = 10.0 * y;
            v[2] = sqrt(-2 * log(1 - u)) * cos(2 * M_PI * w);
        }
    size_t t = 0;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++, t += 2) {
            uint32_t a = (uint32_t)(y * (n + 1) + x), b = a + 1, c = a + (uint32_t)(n + 1), d = c + 1;
            const uint32_t q[6] = {a, b, d, a, d, c};
            memcpy(m->tri + 3 * t, q, sizeof q);
        }
}

/* Whether a point is away from the square's border (whose normals lean). */
static int inner(const double *p) { return p[0] >= 100 && p[0] <= 540 && p[1] >= 100 && p[1] <= 540; }

/* RMS height of the vertices the last subdivision added over the mean of
 * their edge's ends (the midpoint deviation at that scale), away from the
 * border. Subdivision makes coarse face f into fine faces 4f..4f+3, the
 * last one made of the midpoints of edges (t0 t1), (t1 t2), (t2 t0); the
 * coarse vertices keep their indices, and the fine mesh's are read. */
static double midpoint_rms(const struct nc_mesh *fine, const struct nc_mesh *coarse)
{
    double s2 = 0;
    size_t n = 0;
    for (size_t f = 0; f < coarse->nt; f++)
        for (int e = 0; e < 3; e++) {
            const double *pa = fine->v + 3 * coarse->tri[3 * f + e];
            const double *pb = fine->v + 3 * coarse->tri[3 * f + (e + 1) % 3];
            const double *p = fine->v + 3 * fine->tri[12 * f + 9 + e];
            if (!inner(p))
                continue;
            double d = p[2] - 0.5 * (pa[2] + pb[2]);
            s2 += d * d;
            n++;
        }
    return n ? sqrt(s2 / (double)n) : 0;
}

/* What the model resolves: each model facet's mean height over its plane
 * (the mean over its fine faces, of equal area: after 4 levels face f is
 * fine faces 256 f .. 256 f + 255, of the mean of their corners' heights),
 * RMS over the facets away from the border, and the RMS of the heights. */
static void facet_means(const struct nc_mesh *fine, const struct nc_mesh *model, double *mean_rms, double *rms)
{
    double m2 = 0, h2 = 0;
    size_t nf = 0, nh = 0;
    for (size_t f = 0; f < model->nt; f++) {
        const double *A = model->v + 3 * model->tri[3 * f], *B = model->v + 3 * model->tri[3 * f + 1],
                     *C = model->v + 3 * model->tri[3 * f + 2];
        if (!inner(A) || !inner(B) || !inner(C))
            continue;
        const double det = (B[0] - A[0]) * (C[1] - A[1]) - (C[0] - A[0]) * (B[1] - A[1]), *v = fine->v;
        double sum = 0;
        for (size_t t = 256 * f; t < 256 * (f + 1); t++)
            for (int c = 0; c < 3; c++) {
                const double *p = v + 3 * fine->tri[3 * t + c];
                const double u = ((p[0] - A[0]) * (C[1] - A[1]) - (C[0] - A[0]) * (p[1] - A[1])) / det,
                             w = ((B[0] - A[0]) * (p[1] - A[1]) - (p[0] - A[0]) * (B[1] - A[1])) / det;
                const double h = p[2] - (A[2] + u * (B[2] - A[2]) + w * (C[2] - A[2]));
                sum += h / (3 * 256);
                h2 += h * h;
                nh++;
            }
        m2 += sum * sum;
        nf++;
    }
    *mean_rms = sqrt(m2 / (double)nf);
    *rms = sqrt(h2 / (double)nh);
}

static void copy_mesh(const struct nc_mesh *from, struct nc_mesh *to)
{
    to->nv = from->nv, to->nt = from->nt;
    to->v = malloc(3 * from->nv * sizeof *to->v);
    to->tri = malloc(3 * from->nt * sizeof *to->tri);
    memcpy(to->v, from->v, 3 * from->nv * sizeof *to->v);
    memcpy(to->tri, from->tri, 3 * from->nt * sizeof *to->tri);
}

int main(void)
{
    struct nc_mesh model;
    rough_grid(&model);
    /* Flat model faces: the fine vertices keep their x, y only if the
     * normals are z; make the grid's heights tiny for the slope test. */
    for (size_t i = 0; i < model.nv; i++)
        model.v[3 * i + 2] *= 1e-3;
    const double hurst = 0.7;
    /* mean edge of the grid: (10 + 10 + 10 sqrt 2) / 3 m; four halvings */
    const double edge0 = (20 + 10 * M_SQRT2) / 3;
    struct nc_relief_params p = {.edge_m = edge0 / 16 * 1.001, .hurst = hurst, .amplitude = 1000, .seed = 9};
    struct nc_mesh a = {0}, b = {0};
    struct nc_relief_info ia, ib;
    for (int k = 0; k < 2; k++) {
        struct nc_mesh *m = k ? &b : &a;
        copy_mesh(&model, m);
        CHECK(nc_mesh_relief(m, &p, NC_RELIEF_MAX_TRIANGLES, k ? &ib : &ia, NULL) == 0, "%s", nc_errmsg());
    }
    CHECK(ia.levels == 4 && a.nt == 256 * model.nt, "4 levels: %d, %zu triangles", ia.levels, a.nt);
    { /* nothing the model resolves moves: its facets' mean heights move by little of the relief */
        double mean_rms, rms;
        facet_means(&a, &model, &mean_rms, &rms);
        printf("relief %.4g m RMS, the model's facets' means %.4g m RMS (%.3f of it)\n", rms, mean_rms, mean_rms / rms);
        CHECK(mean_rms < 0.45 * rms, "the facets' means moved by %.3f of the relief's RMS", mean_rms / rms);
    }
    CHECK(a.nv == b.nv && !memcmp(a.v, b.v, 3 * a.nv * sizeof *a.v), "same seed, same relief");
    /* Scale by scale: the midpoint deviations of levels 1..4, whose log
     * against the log of the edge length has slope H. */
    double lx[4], ly[4];
    struct nc_mesh prev;
    copy_mesh(&model, &prev);
    for (int level = 1; level <= 4; level++) {
        struct nc_mesh m;
        struct nc_relief_info info;
        copy_mesh(&model, &m);
        struct nc_relief_params q = p;
        q.edge_m = edge0 / exp2(level) * 1.001;
        CHECK(nc_mesh_relief(&m, &q, NC_RELIEF_MAX_TRIANGLES, &info, NULL) == 0 && info.levels == level, "level %d",
              level);
        lx[level - 1] = log(10.0 / exp2(level - 1)); /* the parent edge */
        ly[level - 1] = log(midpoint_rms(&m, &prev));
        printf("level %d: parent edge %.4g m, midpoint RMS %.4g m\n", level, exp(lx[level - 1]), exp(ly[level - 1]));
        nc_mesh_free(&prev);
        prev = m;
    }
    nc_mesh_free(&prev);
    double mx = 0, my = 0, sxy = 0, sxx = 0;
    for (int i = 1; i < 4; i++)
        mx += lx[i] / 3, my += ly[i] / 3;
    for (int i = 1; i < 4; i++)
        sxy += (lx[i] - mx) * (ly[i] - my), sxx += (lx[i] - mx) * (lx[i] - mx);
    printf("Hurst %.3f fitted over levels 2-4, %.3f stated\n", sxy / sxx, hurst);
    CHECK(fabs(sxy / sxx - hurst) < 0.1, "Hurst %.3f fitted, %.3f stated", sxy / sxx, hurst);
    nc_mesh_free(&a);
    nc_mesh_free(&b);

    /* Too fine is an error that names edge_m. */
    struct nc_relief_params tiny = p;
    tiny.edge_m = 1e-4;
    struct nc_relief_info info;
    CHECK(nc_mesh_relief(&model, &tiny, NC_RELIEF_MAX_TRIANGLES, &info, NULL) == NC_ERANGE &&
              nc_test_contains(nc_errmsg(), "edge_m"), "refused: %s", nc_errmsg());
    nc_mesh_free(&model);
    return nc_test_end();
}
