/* boulders.c - boulder populations and rock shapes (boulders.h). */
#include "render/boulders.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/noise.h"
#include "core/rng.h"

/* Stream tags, so that shapes and faces never share a stream. */
#define TAG_SHAPE 0x5348415045ull
#define TAG_RELIEF 0x52454c49454full
#define TAG_MESH 0x4d455348ull
#define OCTAVE_MIN NC_BOULDER_OCTAVE_MIN
#define OCTAVE_MAX NC_BOULDER_OCTAVE_MAX

int nc_boulder_preset(const char *name, struct nc_boulder_params *p)
{
    /* C = N(>D0) D0^b from a published density at D0 (docs/terrain.md). */
    static const struct {
        const char *name;
        double slope, d0_m, n_per_km2;
    } presets[] = {
        /* Tricarico et al. 2021 (index about -2.9); density: Ryugu's N(>20 m),
         * about 50 per km^2, is "twice as large as on ... Bennu"
         * (Michikami et al. 2019). */
        {"bennu", 2.9, 20, 25},
        /* about 4400 boulders over 5 m on about 2.7 km^2, index -2.65
         * (Michikami et al. 2019; Michikami & Hagermann 2021). */
        {"ryugu", 2.65, 5, 4400 / 2.7},
        /* 373 boulders over 5 m on 0.393 km^2, index -3.1 (Michikami et al. 2008). */
        {"itokawa", 3.1, 5, 373 / 0.393},
    };
    for (size_t i = 0; i < sizeof presets / sizeof presets[0]; i++)
        if (!strcmp(name, presets[i].name)) {
            p->slope = presets[i].slope;
            p->c_per_km2 = presets[i].n_per_km2 * pow(presets[i].d0_m, presets[i].slope);
            return 0;
        }
    return nc_error(NC_ECONFIG, "unknown boulder preset '%s' (bennu, ryugu, itokawa)", name);
}

double nc_boulders_expected(const struct nc_boulder_params *p, double area_km2)
{
    return area_km2 * p->c_per_km2 * (pow(p->d_min_m, -p->slope) - pow(p->d_max_m, -p->slope));
}

int nc_rock_shape_corners(const struct nc_rock_shape *sh, float (*v)[3], int max)
{
    int n = 0, P = sh->nplanes;
    for (int a = 0; a < P; a++)
        for (int b = a + 1; b < P; b++)
            for (int c = b + 1; c < P && n < max; c++) {
                const int id[3] = {a, b, c};
                double m[3][4];
                for (int i = 0; i < 3; i++)
                    m[i][0] = sh->nx[id[i]], m[i][1] = sh->ny[id[i]], m[i][2] = sh->nz[id[i]], m[i][3] = sh->d[id[i]];
                double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                             m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                             m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
                if (fabs(det) < 1e-9)
                    continue;
                double x[3]; /* Cramer's rule */
                for (int k = 0; k < 3; k++) {
                    double q[3][3];
                    for (int i = 0; i < 3; i++)
                        for (int j = 0; j < 3; j++)
                            q[i][j] = j == k ? m[i][3] : m[i][j];
                    x[k] = (q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) -
                            q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
                            q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0])) / det;
                }
                int inside = 1;
                for (int k = 0; k < P && inside; k++)
                    inside = sh->nx[k] * x[0] + sh->ny[k] * x[1] + sh->nz[k] * x[2] <= sh->d[k] + 1e-5;
                if (inside) {
                    for (int k = 0; k < 3; k++)
                        v[n][k] = (float)x[k];
                    n++;
                }
            }
    return n;
}

/* Shape i: an ellipsoid of half-axes 1 >= b >= c, cut by its three pairs of
 * axis planes and by planes tangent to it in random directions pushed in by
 * up to 20 %: faceted, flat-sided rocks of distinct outlines. */
static void rock_shape(uint64_t seed, int i, struct nc_rock_shape *r)
{
    uint64_t s = nc_rng_seed(seed, TAG_SHAPE, (uint64_t)i);
    /* around 2 : sqrt(2) : 1, spread by +-20 % */
    double ax[3] = {1, M_SQRT1_2 * (0.8 + 0.4 * nc_rng_uniform(&s)), 0};
    ax[2] = fmin(ax[1], 0.5 * (0.8 + 0.4 * nc_rng_uniform(&s)));
    int n = 0;
    for (int k = 0; k < 3; k++)
        for (int sg = -1; sg <= 1; sg += 2, n++) {
            r->nx[n] = k == 0 ? (float)sg : 0;
            r->ny[n] = k == 1 ? (float)sg : 0;
            r->nz[n] = k == 2 ? (float)sg : 0;
            r->d[n] = (float)(ax[k] * (k == 0 ? 1 : 0.9 + 0.1 * nc_rng_uniform(&s)));
        }
    r->nplanes = 16 + (int)(nc_rng_uniform(&s) * (NC_ROCK_PLANES - 16 + 1));
    if (r->nplanes > NC_ROCK_PLANES)
        r->nplanes = NC_ROCK_PLANES;
    for (; n < r->nplanes; n++) {
        struct nc_vec3 d = nc_rng_dir(&s);
        double t = sqrt(ax[0] * ax[0] * d.x * d.x + ax[1] * ax[1] * d.y * d.y + ax[2] * ax[2] * d.z * d.z);
        r->nx[n] = (float)d.x, r->ny[n] = (float)d.y, r->nz[n] = (float)d.z;
        r->d[n] = (float)(t * (0.8 + 0.2 * nc_rng_uniform(&s)));
    }
    for (; n < NC_ROCK_PLANES; n++) /* padding: plane 0 again */
        r->nx[n] = r->nx[0], r->ny[n] = r->ny[0], r->nz[n] = r->nz[0], r->d[n] = r->d[0];
    /* The tangent planes' corners reach past the ellipsoid: the solid is
     * scaled so that its two farthest corners are 2 units (D) apart. */
    float v[NC_ROCK_CORNERS_MAX][3];
    const int nv = nc_rock_shape_corners(r, v, NC_ROCK_CORNERS_MAX);
    double far2 = 0;
    for (int a = 0; a < nv; a++)
        for (int b = a + 1; b < nv; b++) {
            const double dx = v[a][0] - v[b][0], dy = v[a][1] - v[b][1], dz = v[a][2] - v[b][2];
            far2 = fmax(far2, dx * dx + dy * dy + dz * dz);
        }
    const double scale = far2 > 0 ? 2 / sqrt(far2) : 1;
    for (n = 0; n < NC_ROCK_PLANES; n++)
        r->d[n] = (float)(r->d[n] * scale);
    for (int k = 0; k < 3; k++) /* the farther of the two axis planes */
        r->half[k] = fmaxf(r->d[2 * k], r->d[2 * k + 1]);
}

/* A uniformly random rotation (Shoemake). */
static struct nc_quat random_rotation(uint64_t *s)
{
    double u1 = nc_rng_uniform(s), u2 = 2 * M_PI * nc_rng_uniform(s), u3 = 2 * M_PI * nc_rng_uniform(s);
    double a = sqrt(1 - u1), b = sqrt(u1);
    return (struct nc_quat){a * sin(u2), a * cos(u2), b * sin(u3), b * cos(u3)};
}

/* How far below its centre shape r, rotated by q and scaled by half_m,
 * reaches along -n (n unit): the nearest plane crossed going down. */
static double depth_below(const struct nc_rock_shape *r, struct nc_quat q, double half_m, struct nc_vec3 n)
{
    struct nc_vec3 l = nc_quat_rotate(nc_quat_conj(q), n);
    double t = INFINITY;
    for (int k = 0; k < r->nplanes; k++) {
        double down = -(r->nx[k] * l.x + r->ny[k] * l.y + r->nz[k] * l.z);
        if (down > 0)
            t = fmin(t, r->d[k] / down);
    }
    return half_m * (isfinite(t) ? t : 0);
}

static int grow(struct nc_boulder_field *f, size_t *cap, size_t max_rocks)
{
    if (f->n < *cap)
        return 0;
    if (*cap >= max_rocks)
        return nc_error(NC_ERANGE, "more than %zu boulders: raise min_diameter_m or lower the density", max_rocks);
    size_t nc = *cap ? 2 * *cap : 4096;
    if (nc > max_rocks)
        nc = max_rocks;
    struct nc_boulder *r = realloc(f->rock, nc * sizeof *r);
    if (!r)
        return nc_error(-ENOMEM, "out of memory for %zu boulders", nc);
    f->rock = r;
    *cap = nc;
    return 0;
}

/* The rocks of octave j on face t (area_km2, unit normal nrm, corners v0-v2). */
static int face_octave(struct nc_boulder_field *f, size_t *cap, size_t max_rocks, size_t t, int j,
                       const double *v0, const double *v1, const double *v2, struct nc_vec3 nrm, double area_km2)
{
    const struct nc_boulder_params *p = &f->params;
    double lo = exp2(j), hi = exp2(j + 1);
    double plo = pow(lo, -p->slope), phi = pow(hi, -p->slope);
    uint64_t s = nc_rng_seed(p->seed, (uint64_t)t, (uint64_t)(j - OCTAVE_MIN));
    size_t k = nc_rng_poisson(&s, area_km2 * p->c_per_km2 * (plo - phi));
    for (size_t i = 0; i < k; i++) {
        /* every draw is made whatever the cut, so each rock stays the same */
        double d = pow(plo - nc_rng_uniform(&s) * (plo - phi), -1 / p->slope);
        double a = sqrt(nc_rng_uniform(&s)), b = nc_rng_uniform(&s);
        double w0 = 1 - a, w1 = a * (1 - b), w2 = a * b;
        struct nc_quat q = random_rotation(&s);
        int shape = (int)(nc_rng_uniform(&s) * f->nshapes);
        double burial = p->burial_min + (p->burial_max - p->burial_min) * nc_rng_uniform(&s);
        if (d < p->d_min_m || d >= p->d_max_m)
            continue;
        int rc = grow(f, cap, max_rocks);
        if (rc < 0)
            return rc;
        struct nc_boulder *r = &f->rock[f->n++];
        r->half_m = (float)(d / 2);
        r->shape = (uint16_t)(shape < f->nshapes ? shape : f->nshapes - 1);
        r->pad = 0;
        r->q[0] = (float)q.w, r->q[1] = (float)q.x, r->q[2] = (float)q.y, r->q[3] = (float)q.z;
        /* the rock's float rotation, renormalised, is what the tracer uses */
        struct nc_quat qf = {r->q[0], r->q[1], r->q[2], r->q[3]};
        double qn = nc_quat_norm(qf);
        qf = (struct nc_quat){qf.w / qn, qf.x / qn, qf.y / qn, qf.z / qn};
        /* the point under the centre sits (1 - 2 burial) of the way down: 0 rests on the face */
        double h = (1 - 2 * burial) * depth_below(&f->shape[r->shape], qf, r->half_m, nrm);
        for (int c = 0; c < 3; c++)
            r->centre_m[c] = w0 * v0[c] + w1 * v1[c] + w2 * v2[c] + h * (&nrm.x)[c];
    }
    return 0;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Rocks r[0 .. n) largest first, equal sizes in the order drawn. */
static int sort_octave(struct nc_boulder *r, size_t n)
{
    if (n > UINT32_MAX)
        return nc_error(NC_ERANGE, "more than %lu boulders in one octave", (unsigned long)UINT32_MAX);
    uint64_t *key = malloc(n * sizeof *key);
    struct nc_boulder *copy = malloc(n * sizeof *copy);
    if (!key || !copy) {
        free(key);
        free(copy);
        return nc_error(-ENOMEM, "out of memory sorting %zu boulders", n);
    }
    for (size_t i = 0; i < n; i++) {
        uint32_t bits; /* a positive float's bits order as its value */
        memcpy(&bits, &r[i].half_m, sizeof bits);
        key[i] = (uint64_t)(UINT32_MAX - bits) << 32 | (uint64_t)i;
    }
    qsort(key, n, sizeof *key, cmp_u64);
    memcpy(copy, r, n * sizeof *r);
    for (size_t i = 0; i < n; i++)
        r[i] = copy[key[i] & UINT32_MAX];
    free(key);
    free(copy);
    return 0;
}

/* Octave o of the relief: frequency 2^(o+1) per rock unit (wavelength
 * D/4, D/8, ... with D = 2 units), amplitude wavelength^H. */
static double relief_freq(int o) { return (double)(2 << o); }
static double relief_weight(int o) { return pow(1 / relief_freq(o), NC_ROCK_RELIEF_HURST); }

/* Each octave's gradient scale, so that the sum's gradient along a face has
 * RMS magnitude tan(deg): the octaves are independent, and a plane keeps
 * two of the gradient's three components (each of RMS NC_NOISE_GRAD_RMS
 * per period). */
static void relief_scales(double deg, double *a)
{
    double s2 = 0;
    for (int o = 0; o < NC_ROCK_RELIEF_OCTAVES; o++)
        s2 += pow(relief_weight(o) * relief_freq(o), 2);
    for (int o = 0; o < NC_ROCK_RELIEF_OCTAVES; o++)
        a[o] = tan(deg * M_PI / 180) / (M_SQRT2 * NC_NOISE_GRAD_RMS * sqrt(s2)) * relief_weight(o) * relief_freq(o);
}

void nc_boulder_relief(const struct nc_boulder_field *f, size_t k, const double p[3], double footprint, int first,
                       double g[3])
{
    g[0] = g[1] = g[2] = 0;
    if (!(f->relief[0] > 0))
        return;
    uint64_t seed = 0;
    for (int o = first; o < NC_ROCK_RELIEF_OCTAVES; o++) {
        const double fr = relief_freq(o), span = footprint > 0 ? 1 / (fr * footprint) : INFINITY; /* a wavelength */
        const double fade = span >= 4 ? 1 : 0.5 * (span - 2);
        if (!(fade > 0))
            break; /* the finer octaves fade sooner */
        if (o == first)
            seed = nc_rng_seed(f->params.seed, TAG_RELIEF, (uint64_t)k);
        const double a = fade * f->relief[o];
        double go[3];
        nc_noise3_grad(seed + (uint64_t)o, fr * p[0], fr * p[1], fr * p[2], go);
        g[0] += a * go[0], g[1] += a * go[1], g[2] += a * go[2];
    }
}

int nc_rock_shape_mesh(const struct nc_boulder_field *f, int s, int subdivisions, struct nc_mesh *out)
{
    if (s < 0 || s >= f->nshapes || !(f->relief[0] > 0))
        return nc_error(NC_ERANGE, "rock shape %d: no such shape, or flat faces (roughness_deg 0)", s);
    const struct nc_asteroid_params ap = {.radii_m = {1, 1, 1}, .subdivisions = subdivisions};
    int rc = nc_mesh_asteroid(&ap, out); /* no lumps, no craters: an icosphere */
    if (rc < 0)
        return rc;
    const struct nc_rock_shape *sh = &f->shape[s];
    const uint64_t seed = nc_rng_seed(f->params.seed, TAG_MESH, (uint64_t)s);
    for (size_t i = 0; i < out->nv; i++) {
        double *v = out->v + 3 * i, n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), u[3], t = INFINITY;
        for (int k = 0; k < 3; k++)
            u[k] = v[k] / n;
        for (int g = 0; g < sh->nplanes; g++) { /* the nearest plane along u (the centre is inside all) */
            double c = sh->nx[g] * u[0] + sh->ny[g] * u[1] + sh->nz[g] * u[2];
            if (c > 0)
                t = fmin(t, sh->d[g] / c);
        }
        double p[3] = {t * u[0], t * u[1], t * u[2]}, h = 0;
        for (int o = 0; o < NC_ROCK_MESH_OCTAVES; o++) {
            const double fr = relief_freq(o); /* height (a / fr) noise: gradient a grad(noise), as the shading's */
            h += f->relief[o] / fr * nc_noise3(seed + (uint64_t)o, fr * p[0], fr * p[1], fr * p[2]);
        }
        for (int k = 0; k < 3; k++) /* only inward: the surface stays within the planes */
            v[k] = p[k] + fmin(h, 0) * u[k];
    }
    return 0;
}

int nc_boulders_generate(const struct nc_mesh *m, const struct nc_boulder_params *p, size_t max_rocks,
                         struct nc_boulder_field *out)
{
    memset(out, 0, sizeof *out);
    if (!(p->slope > 0) || !(p->c_per_km2 >= 0) || !(p->d_min_m > 0) || !(p->d_max_m > p->d_min_m) ||
        p->shapes < 1 || p->shapes > NC_ROCK_SHAPES_MAX || !(p->burial_min >= 0) ||
        !(p->burial_max >= p->burial_min) || !(p->burial_max <= 1) || !(p->roughness_deg >= 0) ||
        !(p->roughness_deg <= 45))
        return nc_error(NC_ERANGE, "boulders: need slope > 0, density >= 0, 0 < min diameter < max diameter, "
                                   "1..%d shapes, 0 <= burial <= 1, 0 <= roughness <= 45 deg", NC_ROCK_SHAPES_MAX);
    if (p->d_min_m < exp2(OCTAVE_MIN) || p->d_max_m > exp2(OCTAVE_MAX + 1))
        return nc_error(NC_ERANGE, "boulders: diameters from %g to %g m", exp2(OCTAVE_MIN), exp2(OCTAVE_MAX + 1));
    out->params = *p;
    relief_scales(p->roughness_deg, out->relief);
    out->nshapes = p->shapes;
    if (!(out->shape = calloc((size_t)p->shapes, sizeof *out->shape)))
        return nc_error(-ENOMEM, "out of memory");
    for (int i = 0; i < p->shapes; i++)
        rock_shape(p->seed, i, &out->shape[i]);
    out->area_m2 = nc_mesh_area_m2(m);
    double area_km2 = 1e-6 * out->area_m2; /* refuse an absurd population before drawing it */
    if (nc_boulders_expected(p, area_km2) > 1.01 * (double)max_rocks) {
        nc_boulders_free(out);
        return nc_error(NC_ERANGE, "about %.3g boulders expected on %.4g km^2, more than %zu: raise min_diameter_m or "
                                   "lower the density", nc_boulders_expected(p, area_km2), area_km2, max_rocks);
    }
    const int j0 = (int)floor(log2(p->d_min_m)), j1 = (int)floor(log2(p->d_max_m));
    size_t cap = 0;
    int rc = 0;
    for (int j = j1; j >= j0 && rc == 0; j--) { /* the largest octave first */
        size_t first = out->n;
        for (size_t t = 0; t < m->nt && rc == 0; t++) {
            const double *v0 = m->v + 3 * m->tri[3 * t], *v1 = m->v + 3 * m->tri[3 * t + 1],
                         *v2 = m->v + 3 * m->tri[3 * t + 2];
            struct nc_vec3 nrm;
            double a = nc_mesh_face(m, t, &nrm);
            if (a > 0) /* a degenerate face holds no rock */
                rc = face_octave(out, &cap, max_rocks, t, j, v0, v1, v2, nrm, a * 1e-6);
        }
        if (rc == 0 && out->n > first) {
            rc = sort_octave(out->rock + first, out->n - first);
            out->octave[out->noctaves++] = (struct nc_boulder_octave){.j = j, .first = first, .n = out->n - first};
        }
    }
    if (rc < 0) {
        nc_boulders_free(out);
        return rc;
    }
    struct nc_boulder *fit = out->n ? realloc(out->rock, out->n * sizeof *fit) : NULL;
    if (fit)
        out->rock = fit; /* the list at its size, not its last doubling */
    return 0;
}

size_t nc_boulders_at_least(const struct nc_boulder_field *f, double d_m)
{
    size_t lo = 0, hi = f->n; /* the list is sorted by size, largest first */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (2.0 * f->rock[mid].half_m >= d_m)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

double nc_boulders_cover(const struct nc_boulder_field *f, size_t from)
{
    double sum = 0; /* in list order: the same bits on every call */
    for (size_t i = from; i < f->n; i++)
        sum += (double)f->rock[i].half_m * f->rock[i].half_m;
    return f->area_m2 > 0 ? M_PI * sum / f->area_m2 : 0.0;
}

double nc_boulders_bounding_radius(const struct nc_boulder_field *f)
{
    double r = 0;
    for (size_t i = 0; i < f->n; i++) {
        const struct nc_boulder *b = &f->rock[i];
        const float *h = f->shape[b->shape].half;
        double c = sqrt(b->centre_m[0] * b->centre_m[0] + b->centre_m[1] * b->centre_m[1] +
                        b->centre_m[2] * b->centre_m[2]);
        r = fmax(r, c + b->half_m * sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]));
    }
    return r;
}

void nc_boulders_free(struct nc_boulder_field *f)
{
    free(f->rock);
    free(f->shape);
    memset(f, 0, sizeof *f);
}
