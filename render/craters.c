/* craters.c - crater populations and their carving into a mesh (craters.h).
 * Deterministic from the mesh, the parameters and the seed; no I/O. */
#include "render/craters.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/rng.h"

#define TAG_COUNT 0x434f554e54ull
#define TAG_CRATER 0x435241544552ull
#define EJECTA_REACH 3.0 /* the blanket ends at this many radii */

void nc_crater_params_default(const struct nc_mesh *m, struct nc_crater_params *p)
{
    /* Pike (1977): fresh simple lunar craters, d = 0.196 D^1.010 and rim
     * height h = 0.036 D^1.014 (D in km); taken as proportional here. */
    double area_m2 = nc_mesh_area_m2(m);
    double edge_m = m->nt ? sqrt(4 * area_m2 / ((double)m->nt * sqrt(3.0))) : 1; /* equilateral faces */
    *p = (struct nc_crater_params){.c_per_km2 = 0, .slope = 2.0, .d_min_m = 4 * edge_m,
                                   .d_max_m = fmax(sqrt(area_m2 / (4 * M_PI)), 8 * edge_m),
                                   .depth_ratio = 0.196, .rim_ratio = 0.036, .degradation = 0.5, .seed = 1};
}

double nc_craters_expected(const struct nc_crater_params *p, double area_km2)
{
    return area_km2 * p->c_per_km2 * (pow(p->d_min_m, -p->slope) - pow(p->d_max_m, -p->slope));
}

double nc_craters_density_for(const struct nc_crater_params *p, double area_km2, double count)
{
    double span = area_km2 * (pow(p->d_min_m, -p->slope) - pow(p->d_max_m, -p->slope));
    return span > 0 ? count / span : 0;
}

/* Oldest first; ties (vanishingly rare) by size, then position. */
static int cmp_age(const void *a, const void *b)
{
    const struct nc_crater *x = a, *y = b;
    if (x->age != y->age)
        return x->age > y->age ? -1 : 1;
    if (x->d_m != y->d_m)
        return x->d_m > y->d_m ? -1 : 1;
    return memcmp(x->centre_m, y->centre_m, sizeof x->centre_m);
}

int nc_craters_generate(const struct nc_mesh *m, const struct nc_crater_params *p, size_t max_craters,
                        struct nc_crater_field *out)
{
    memset(out, 0, sizeof *out);
    if (!(p->slope > 0) || !(p->c_per_km2 >= 0) || !(p->d_min_m > 0) || !(p->d_max_m > p->d_min_m) ||
        !(p->depth_ratio >= 0 && p->depth_ratio <= 1) || !(p->rim_ratio >= 0 && p->rim_ratio <= 1) ||
        !(p->degradation >= 0 && p->degradation <= 1))
        return nc_error(NC_ERANGE, "craters: need slope > 0, density >= 0, 0 < min diameter < max diameter, "
                                   "depth and rim ratios and degradation in [0, 1]");
    out->params = *p;
    double *cum = malloc((m->nt + 1) * sizeof *cum);
    if (!cum)
        return nc_error(-ENOMEM, "out of memory");
    cum[0] = 0;
    for (size_t t = 0; t < m->nt; t++)
        cum[t + 1] = cum[t] + nc_mesh_face(m, t, NULL);
    out->area_km2 = 1e-6 * cum[m->nt];
    double lambda = nc_craters_expected(p, out->area_km2);
    if (lambda > 1.01 * (double)max_craters) {
        free(cum);
        return nc_error(NC_ERANGE, "about %.3g craters expected on %.4g km^2, more than %zu: raise min_diameter_m or "
                                   "lower the density", lambda, out->area_km2, max_craters);
    }
    uint64_t s = nc_rng_seed(p->seed, TAG_COUNT, 0);
    size_t n = (size_t)nc_rng_poisson(&s, lambda);
    if (n && !(out->crater = calloc(n, sizeof *out->crater))) {
        free(cum);
        return nc_error(-ENOMEM, "out of memory for %zu craters", n);
    }
    const double a = pow(p->d_min_m, -p->slope), span = a - pow(p->d_max_m, -p->slope);
    for (size_t i = 0; i < n && cum[m->nt] > 0; i++) {
        struct nc_crater *c = &out->crater[out->n];
        s = nc_rng_seed(p->seed, TAG_CRATER, i);
        /* A face by area, then a uniform point on it. */
        double u = nc_rng_uniform(&s) * cum[m->nt];
        size_t lo = 0, hi = m->nt - 1;
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (cum[mid + 1] <= u)
                lo = mid + 1;
            else
                hi = mid;
        }
        struct nc_vec3 nrm;
        nc_mesh_face(m, lo, &nrm);
        double r1 = sqrt(nc_rng_uniform(&s)), r2 = nc_rng_uniform(&s);
        double w[3] = {1 - r1, r1 * (1 - r2), r1 * r2};
        for (int k = 0; k < 3; k++) {
            c->centre_m[k] = 0;
            for (int j = 0; j < 3; j++)
                c->centre_m[k] += w[j] * m->v[3 * m->tri[3 * lo + j] + k];
        }
        c->normal[0] = nrm.x, c->normal[1] = nrm.y, c->normal[2] = nrm.z;
        /* Inverse of the truncated power law's cumulative distribution. */
        c->d_m = pow(a - nc_rng_uniform(&s) * span, -1 / p->slope);
        c->age = nc_rng_uniform(&s);
        out->n++;
    }
    free(cum);
    if (out->n)
        qsort(out->crater, out->n, sizeof *out->crater, cmp_age);
    return 0;
}

/* Height of a crater's profile above the pre-impact surface at r = distance
 * / radius, metres, and the weight (0..1) with which it replaces the older
 * relief there. */
static double profile(const struct nc_crater_params *p, const struct nc_crater *c, double r, double *erase)
{
    /* Degradation: the depth falls linearly with age and the rim, the most
     * exposed part, as its square (a stated model, not a fitted one). */
    double k = 1 - p->degradation * c->age;
    double depth = p->depth_ratio * c->d_m * k, rim = p->rim_ratio * c->d_m * k * k;
    if (r < 1) { /* parabolic cavity, rim crest at r = 1 */
        *erase = 1;
        return rim - depth * (1 - r * r);
    }
    if (r < EJECTA_REACH) {
        /* Ejecta thickness ~ (r/R)^-3 (McGetchin, Settle & Head 1973),
         * tapered to zero with zero slope at the reach; it buries the older
         * relief in the same proportion. */
        double x = (r - 1) / (EJECTA_REACH - 1), f = (1 - x * x) / (r * r * r);
        *erase = f;
        return rim * f;
    }
    *erase = 0;
    return 0;
}

/* Vertices binned in a uniform grid of cubic cells, CSR. */
struct grid {
    double lo[3], cell;
    int dim[3];
    size_t *start; /* dim^3 + 1 */
    uint32_t *idx;
};

static int cell_of(const struct grid *g, double x, int k)
{
    int c = (int)floor((x - g->lo[k]) / g->cell);
    return c < 0 ? 0 : c >= g->dim[k] ? g->dim[k] - 1 : c;
}

static int grid_build(const struct nc_mesh *m, struct grid *g)
{
    double hi[3];
    for (int k = 0; k < 3; k++)
        g->lo[k] = INFINITY, hi[k] = -INFINITY;
    for (size_t i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            g->lo[k] = fmin(g->lo[k], m->v[3 * i + k]);
            hi[k] = fmax(hi[k], m->v[3 * i + k]);
        }
    double ext = fmax(hi[0] - g->lo[0], fmax(hi[1] - g->lo[1], hi[2] - g->lo[2]));
    g->cell = ext > 0 ? ext / 96 : 1;
    size_t cells = 1;
    for (int k = 0; k < 3; k++) {
        g->dim[k] = (int)((hi[k] - g->lo[k]) / g->cell) + 1;
        cells *= (size_t)g->dim[k];
    }
    g->start = calloc(cells + 1, sizeof *g->start);
    g->idx = malloc(m->nv * sizeof *g->idx);
    if (!g->start || !g->idx)
        return nc_error(-ENOMEM, "out of memory for the crater grid");
    size_t *key = malloc(m->nv * sizeof *key);
    if (!key)
        return nc_error(-ENOMEM, "out of memory for the crater grid");
    for (size_t i = 0; i < m->nv; i++) {
        const double *v = m->v + 3 * i;
        key[i] = ((size_t)cell_of(g, v[2], 2) * (size_t)g->dim[1] + (size_t)cell_of(g, v[1], 1)) * (size_t)g->dim[0] +
                 (size_t)cell_of(g, v[0], 0);
        g->start[key[i] + 1]++;
    }
    for (size_t c = 0; c < cells; c++)
        g->start[c + 1] += g->start[c];
    size_t *fill = key; /* reuse: cell of i, then each cell's next slot */
    for (size_t i = 0; i < m->nv; i++)
        g->idx[g->start[fill[i]]++] = (uint32_t)i;
    for (size_t c = cells; c > 0; c--) /* the increments moved each start to the next cell's */
        g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    free(key);
    return 0;
}

/* The vertices within reach of c whose normals face the crater's side of
 * the surface (a crater never reaches through a thin body to its far
 * side), with their distances from its centre, gathered into near. */
struct near {
    uint32_t *v;
    double *dist;
    size_t n, cap;
};

static int gather(const struct grid *g, const struct nc_mesh *m, const double *nrm, const struct nc_crater *c,
                  double reach, struct near *out)
{
    int lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = cell_of(g, c->centre_m[k] - reach, k);
        hi[k] = cell_of(g, c->centre_m[k] + reach, k);
    }
    out->n = 0;
    for (int z = lo[2]; z <= hi[2]; z++)
        for (int y = lo[1]; y <= hi[1]; y++)
            for (int x = lo[0]; x <= hi[0]; x++) {
                size_t cell = ((size_t)z * (size_t)g->dim[1] + (size_t)y) * (size_t)g->dim[0] + (size_t)x;
                for (size_t j = g->start[cell]; j < g->start[cell + 1]; j++) {
                    uint32_t v = g->idx[j];
                    const double *p = m->v + 3 * v, *n = nrm + 3 * v;
                    double d[3] = {p[0] - c->centre_m[0], p[1] - c->centre_m[1], p[2] - c->centre_m[2]};
                    double dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    if (dist >= reach || n[0] * c->normal[0] + n[1] * c->normal[1] + n[2] * c->normal[2] <= 0)
                        continue;
                    if (out->n == out->cap) {
                        size_t cap = out->cap ? 2 * out->cap : 1024;
                        uint32_t *nv = realloc(out->v, cap * sizeof *nv);
                        if (nv)
                            out->v = nv;
                        double *nd = realloc(out->dist, cap * sizeof *nd);
                        if (nd)
                            out->dist = nd;
                        if (!nv || !nd)
                            return nc_error(-ENOMEM, "out of memory");
                        out->cap = cap;
                    }
                    out->v[out->n] = v;
                    out->dist[out->n++] = dist;
                }
            }
    return 0;
}

int nc_craters_apply(struct nc_crater_field *f, struct nc_mesh *m, const double *dir)
{
    f->applied = 0;
    if (!f->n || !m->nv)
        return 0;
    struct grid g = {0};
    struct near nb = {0};
    double *own = dir ? NULL : malloc(3 * m->nv * sizeof *own), *h = calloc(m->nv, sizeof *h);
    const double *nrm = dir ? dir : own;
    int rc = nrm && h ? grid_build(m, &g) : nc_error(-ENOMEM, "out of memory for %zu vertices", m->nv);
    if (rc == 0 && own)
        nc_mesh_vertex_normals(m, own);
    for (size_t i = 0; i < f->n && rc == 0; i++) {
        const struct nc_crater *c = &f->crater[i];
        double R = 0.5 * c->d_m, ref = 0;
        size_t inside = 0;
        if ((rc = gather(&g, m, nrm, c, EJECTA_REACH * R, &nb)) < 0)
            break;
        /* The pre-impact level: the mean height over the cavity. */
        for (size_t j = 0; j < nb.n; j++)
            if (nb.dist[j] < R) {
                ref += h[nb.v[j]];
                inside++;
            }
        if (!inside)
            continue; /* below the mesh's resolution */
        ref /= (double)inside;
        f->applied++;
        for (size_t j = 0; j < nb.n; j++) {
            double erase, dh = profile(&f->params, c, nb.dist[j] / R, &erase);
            double *hv = &h[nb.v[j]];
            *hv += erase * (ref - *hv) + dh;
        }
    }
    if (rc == 0)
        for (size_t i = 0; i < m->nv; i++)
            for (int k = 0; k < 3; k++)
                m->v[3 * i + k] += h[i] * nrm[3 * i + k];
    free(g.start);
    free(g.idx);
    free(nb.v);
    free(nb.dist);
    free(own);
    free(h);
    return rc;
}

void nc_craters_free(struct nc_crater_field *f)
{
    free(f->crater);
    memset(f, 0, sizeof *f);
}
