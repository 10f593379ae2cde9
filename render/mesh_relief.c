/* mesh_relief.c - relief below a mesh's resolution (mesh.h): the mesh is
 * subdivided and every vertex is displaced along its normal by fractional
 * Brownian motion of wavelengths below the model's resolution, with an
 * amplitude measured on the mesh itself, so that the finer relief
 * continues the model's own roughness. Deterministic from the mesh and the
 * parameters; no I/O. */
#include "render/mesh.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/noise.h"
#include "core/rng.h"

/* For fBm with E[(h(x + l) - h(x))^2] = s^2 l^(2H), the midpoint of a
 * segment of length l departs from the mean of its ends by a Gaussian of
 * variance s^2 l^(2H) (2^(-2H) - 1/4) (from the increments' covariance). */
static double midpoint_factor(double hurst) { return sqrt(pow(2.0, -2 * hurst) - 0.25); }

/* s of the mesh: each used vertex's height above the mean of its edge
 * neighbours, along its normal, taken as the midpoint deviation of a
 * segment two mean edges long; its variance (the mean, which curvature
 * gives, removed) sets s. Also the mean edge length. */
static int measure(const struct nc_mesh *m, const double *nrm, double hurst, double *s, double *edge_m)
{
    double *sum = calloc(3 * m->nv, sizeof *sum);
    uint32_t *cnt = calloc(m->nv, sizeof *cnt);
    if (!sum || !cnt) {
        free(sum);
        free(cnt);
        return nc_error(-ENOMEM, "out of memory for %zu vertices", m->nv);
    }
    for (size_t t = 0; t < m->nt; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = m->tri[3 * t + e], b = m->tri[3 * t + (e + 1) % 3];
            for (int k = 0; k < 3; k++) {
                sum[3 * a + k] += m->v[3 * b + k];
                sum[3 * b + k] += m->v[3 * a + k];
            }
            cnt[a]++, cnt[b]++;
        }
    double m1 = 0, m2 = 0;
    size_t n = 0;
    for (size_t i = 0; i < m->nv; i++) {
        if (!cnt[i])
            continue;
        double dev = 0;
        for (int k = 0; k < 3; k++)
            dev += nrm[3 * i + k] * (m->v[3 * i + k] - sum[3 * i + k] / cnt[i]);
        m1 += dev;
        m2 += dev * dev;
        n++;
    }
    free(sum);
    free(cnt);
    *edge_m = nc_mesh_mean_edge_m(m);
    double var = n ? m2 / (double)n - (m1 / (double)n) * (m1 / (double)n) : 0;
    *s = *edge_m > 0 ? sqrt(fmax(var, 0)) / (pow(2 * *edge_m, hurst) * midpoint_factor(hurst)) : 0;
    return 0;
}

struct relief {
    double *base; /* per vertex: the point under it on the model's own faces */
    double *nrm;  /* its normal there, interpolated from the model's vertices */
    double s, hurst, factor, wl_max_m, wl_min_m;
    uint64_t seed;
    double amp[64]; /* per octave: s wl^H factor / NC_NOISE_RMS, as fbm() multiplies it out */
    int noct;
};

/* The fBm height at body point p: octaves of wavelength wl_max_m down to
 * wl_min_m, each of RMS s wl^H (2^(-2H) - 1/4)^(1/2), the midpoint
 * deviation fBm gives at that scale. */
static double fbm(const struct relief *r, const double *p)
{
    double h = 0, wl = r->wl_max_m;
    for (int k = 0; k < r->noct; k++, wl /= 2)
        h += r->amp[k] * nc_noise3(r->seed + (uint64_t)k, p[0] / wl, p[1] / wl, p[2] / wl);
    return h;
}

/* The octaves' amplitudes, once (a pow() per octave and vertex was 6 % of
 * the samples of bennu_rubble.yaml's start, perf). */
static void octaves(struct relief *r)
{
    r->noct = 0;
    for (double wl = r->wl_max_m; wl >= r->wl_min_m * 0.999 && r->noct < 64; wl /= 2)
        r->amp[r->noct++] = r->s * pow(wl, r->hurst) * r->factor / NC_NOISE_RMS;
}

/* A new vertex: its base and normal from its edge's ends (the model's
 * faces are flat, so the base stays on them), then displaced by the relief
 * there, as the model's own vertices are. The relief has no octave longer
 * than half the model's edge, so what the model resolves stays (the
 * gradient noise's leakage below its lowest octave aside: docs/terrain.md).
 * Until session 67 each vertex took the relief minus its linear
 * interpolation between the model's vertices, which kept those still but
 * moved each facet's mean height by about 0.6 of the relief's RMS. */
static void displace(void *ctx, const struct nc_mesh *m, uint32_t a, uint32_t b, uint32_t index, double *p)
{
    (void)m;
    struct relief *r = ctx;
    double *B = r->base + 3 * (size_t)index, *n = r->nrm + 3 * (size_t)index;
    double nl = 0;
    for (int k = 0; k < 3; k++) {
        B[k] = 0.5 * (r->base[3 * (size_t)a + k] + r->base[3 * (size_t)b + k]);
        n[k] = r->nrm[3 * (size_t)a + k] + r->nrm[3 * (size_t)b + k];
        nl += n[k] * n[k];
    }
    nl = sqrt(nl);
    const double d = fbm(r, B);
    for (int k = 0; k < 3; k++) {
        n[k] = nl > 0 ? n[k] / nl : 0;
        p[k] = B[k] + d * n[k];
    }
}

int nc_mesh_relief(struct nc_mesh *m, const struct nc_relief_params *p, size_t max_triangles,
                   struct nc_relief_info *info, double **base_normals)
{
    memset(info, 0, sizeof *info);
    if (base_normals)
        *base_normals = NULL;
    if (!(p->edge_m > 0) || !(p->hurst > 0 && p->hurst < 1) || !(p->amplitude >= 0))
        return nc_error(NC_ERANGE, "relief: need edge_m > 0, 0 < hurst < 1, amplitude >= 0");
    struct relief r = {.hurst = p->hurst, .factor = midpoint_factor(p->hurst), .seed = p->seed};
    double *n0 = malloc(3 * m->nv * sizeof *n0);
    if (!n0)
        return nc_error(-ENOMEM, "out of memory for %zu vertices", m->nv);
    nc_mesh_vertex_normals(m, n0);
    int rc = measure(m, n0, p->hurst, &r.s, &info->model_edge_m);
    free(n0);
    info->s = r.s *= p->amplitude;
    info->edge_m = info->model_edge_m;
    size_t nt = m->nt, nv = m->nv;
    int levels = 0;
    for (double e = info->model_edge_m; e > p->edge_m; e /= 2, nt *= 4, nv += 3 * nt / 2)
        levels++;
    if (rc == 0 && nt > max_triangles)
        rc = nc_error(NC_ERANGE, "relief: edges of %g m on this mesh (mean edge %.4g m, %zu triangles) need %zu "
                                 "triangles, more than %zu: raise edge_m", p->edge_m, info->model_edge_m, m->nt, nt,
                      max_triangles);
    if (rc < 0 || !levels)
        return rc;
    /* Wavelengths from half the model's edge (what it cannot resolve) to
     * the final edge. */
    r.wl_max_m = 0.5 * info->model_edge_m;
    r.wl_min_m = info->model_edge_m / exp2(levels);
    octaves(&r);
    size_t cap = nv + 3 * nt; /* generous: a closed mesh adds 3/2 vertex per face per level */
    r.base = malloc(3 * cap * sizeof *r.base);
    r.nrm = malloc(3 * cap * sizeof *r.nrm);
    if (!r.base || !r.nrm)
        rc = nc_error(-ENOMEM, "out of memory for the relief of %zu vertices", cap);
    if (rc == 0) {
        memcpy(r.base, m->v, 3 * m->nv * sizeof *m->v);
        nc_mesh_vertex_normals(m, r.nrm);
        for (size_t i = 0; i < m->nv; i++) {
            const double d = fbm(&r, r.base + 3 * i);
            for (int k = 0; k < 3; k++)
                m->v[3 * i + k] = r.base[3 * i + k] + d * r.nrm[3 * i + k];
        }
    }
    for (int k = 0; k < levels && rc == 0; k++) {
        if (m->nv + 3 * m->nt > cap) {
            rc = nc_error(NC_ERANGE, "relief: the mesh grew past %zu vertices (not a surface of triangles?)", cap);
            break;
        }
        rc = nc_mesh_subdivide(m, &displace, &r);
        info->edge_m /= 2;
        info->levels = k + 1;
    }
    if (rc == 0 && base_normals) { /* the model's own vertices keep their vertex normals */
        *base_normals = r.nrm;
        r.nrm = NULL;
    }
    free(r.base);
    free(r.nrm);
    return rc;
}
