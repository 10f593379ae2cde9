/* mesh_procedural.c - the built-in procedural asteroid (mesh.h): a
 * subdivided icosahedron displaced by seeded random relief and craters.
 * Deterministic from its parameters; no file I/O. */
#include "render/mesh.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/rng.h"
#include "render/craters.h"

/* ---- procedural asteroid ---------------------------------------------- */

/* New vertices on the unit sphere. */
static void on_sphere(void *ctx, const struct nc_mesh *m, uint32_t a, uint32_t b, uint32_t index, double *p)
{
    (void)ctx, (void)m, (void)a, (void)b, (void)index;
    double n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int i = 0; i < 3; i++)
        p[i] /= n;
}

int nc_mesh_asteroid(const struct nc_asteroid_params *ap, struct nc_mesh *out)
{
    memset(out, 0, sizeof *out);
    if (ap->subdivisions < 0 || ap->subdivisions > 9)
        return nc_error(NC_ERANGE, "asteroid subdivisions must be 0..9, got %d", ap->subdivisions);
    struct nc_mesh m = {0};
    m.v = malloc(12 * 3 * sizeof *m.v);
    m.tri = malloc(20 * 3 * sizeof *m.tri);
    if (!m.v || !m.tri) {
        nc_mesh_free(&m);
        return nc_error(-ENOMEM, "asteroid: out of memory");
    }
    /* Icosahedron. */
    const double t = (1 + sqrt(5.0)) / 2;
    const double iv[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const uint32_t it[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    double n0 = sqrt(1 + t * t);
    for (int i = 0; i < 12; i++)
        for (int k = 0; k < 3; k++)
            m.v[3 * i + k] = iv[i][k] / n0;
    memcpy(m.tri, it, sizeof it);
    m.nv = 12;
    m.nt = 20;
    for (int s = 0; s < ap->subdivisions; s++) {
        int rc = nc_mesh_subdivide(&m, on_sphere, NULL);
        if (rc < 0) {
            nc_mesh_free(&m);
            return rc;
        }
    }

    /* Lumps: centre direction, angular radius (rad), relative amplitude. */
    uint64_t rng = ap->seed ^ 0x4e6176436d417374ull;
    enum { NLUMP = 24 };
    struct { struct nc_vec3 c; double a, amp, cos_reach; } ft[NLUMP];
    for (int i = 0; i < NLUMP; i++) {
        ft[i].c = nc_rng_dir(&rng);
        ft[i].a = 0.35 + 0.65 * nc_rng_uniform(&rng);
        ft[i].amp = ap->lump_amplitude * (2 * nc_rng_uniform(&rng) - 1);
        ft[i].cos_reach = cos(fmin(M_PI, 3 * ft[i].a));
    }
    for (size_t v = 0; v < m.nv; v++) {
        struct nc_vec3 d = nc_v3(m.v[3 * v], m.v[3 * v + 1], m.v[3 * v + 2]);
        double h = 0;
        for (int i = 0; i < NLUMP; i++) {
            double cs = nc_v3_dot(d, ft[i].c);
            if (cs < ft[i].cos_reach)
                continue;
            double x = acos(fmin(1.0, cs)) / ft[i].a;
            h += ft[i].amp * exp(-x * x);
        }
        /* Radius of the ellipsoid along d, then the relative relief. */
        double q = d.x * d.x / (ap->radii_m.x * ap->radii_m.x) + d.y * d.y / (ap->radii_m.y * ap->radii_m.y) +
                   d.z * d.z / (ap->radii_m.z * ap->radii_m.z);
        double r = (1 + h) / sqrt(q);
        m.v[3 * v] = d.x * r;
        m.v[3 * v + 1] = d.y * r;
        m.v[3 * v + 2] = d.z * r;
    }
    /* Craters (craters.h): about `craters` of the default population. */
    struct nc_crater_params cp;
    nc_crater_params_default(&m, &cp);
    cp.seed = ap->seed;
    cp.c_per_km2 = nc_craters_density_for(&cp, 1e-6 * nc_mesh_area_m2(&m), ap->craters);
    struct nc_crater_field cf;
    int rc = nc_craters_generate(&m, &cp, NC_CRATERS_MAX, &cf);
    if (rc == 0)
        rc = nc_craters_apply(&cf, &m, NULL);
    nc_craters_free(&cf);
    if (rc < 0) {
        nc_mesh_free(&m);
        return rc;
    }
    *out = m;
    return 0;
}
