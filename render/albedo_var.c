/* albedo_var.c - procedural albedo variation (albedo_var.h). */
#include "render/albedo_var.h"

#include <errno.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/noise.h"

int nc_albedo_var_vertices(const struct nc_mesh *m, const struct nc_albedo_var_params *p, float **out,
                           double *smallest_m)
{
    *out = NULL;
    double wl_min = 2 * nc_mesh_mean_edge_m(m);
    *smallest_m = wl_min;
    float *f = malloc((m->nv ? m->nv : 1) * sizeof *f);
    if (!f)
        return nc_error(-ENOMEM, "out of memory for %zu vertex albedos", m->nv);
    /* Octaves from the largest wavelength down; the sum, over its RMS, is
     * near a standard normal (many independent lattice cells). */
    enum { MAX_OCTAVES = 40 };
    double amp[MAX_OCTAVES], wl[MAX_OCTAVES], var = 0;
    int n = 0;
    for (double w = p->largest_m; n < MAX_OCTAVES && (n == 0 || w >= wl_min * 0.999); w /= 2, n++) {
        wl[n] = w;
        amp[n] = pow(w / p->largest_m, p->hurst);
        var += amp[n] * amp[n] * NC_NOISE_RMS * NC_NOISE_RMS;
    }
    const double s2 = log1p(p->rms * p->rms), s = sqrt(s2), inv = 1 / sqrt(var);
    for (size_t i = 0; i < m->nv; i++) {
        const double *v = m->v + 3 * i;
        double z = 0;
        for (int k = 0; k < n; k++)
            z += amp[k] * nc_noise3(p->seed * 64 + (uint64_t)k, v[0] / wl[k], v[1] / wl[k], v[2] / wl[k]);
        f[i] = (float)exp(s * z * inv - 0.5 * s2);
    }
    /* Mean 1 over the surface exactly (each vertex weighted by a third of
     * its faces' area): the variation moves no light on average. */
    double sum = 0, area = 0;
    for (size_t t = 0; t < m->nt; t++) {
        double a = nc_mesh_face(m, t, NULL);
        for (int e = 0; e < 3; e++)
            sum += a / 3 * f[m->tri[3 * t + e]];
        area += a;
    }
    for (size_t i = 0; i < m->nv && sum > 0; i++)
        f[i] = (float)(f[i] * (area / sum));
    *out = f;
    return 0;
}
