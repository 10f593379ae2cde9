/* bounce.c - the mixture of bounce.h: sampling and its density. */
#include "render/bounce.h"

#include <math.h>

void nc_bounce_init(struct nc_bounce_mix *m, struct nc_vec3 n, const struct nc_vec3 *centre_rel,
                    const double *radius_m, int nbodies, int self)
{
    m->n = n;
    nc_v3_basis(n, &m->e1, &m->e2);
    m->ncone = 0;
    for (int b = 0; b < nbodies; b++) {
        if (b == self)
            continue;
        double d = nc_v3_norm(centre_rel[b]), s = radius_m[b] / d;
        if (!(s < 1)) /* inside the sphere (or a degenerate one): the hemisphere covers it */
            continue;
        struct nc_vec3 a = nc_v3_scale(centre_rel[b], 1.0 / d);
        if (nc_v3_dot(a, n) <= -s) /* wholly below the horizon */
            continue;
        int k = m->ncone++;
        m->cone_axis[k] = a;
        nc_v3_basis(a, &m->cone_e1[k], &m->cone_e2[k]);
        double c = sqrt((1 - s) * (1 + s));
        m->cone_cos[k] = c;
        m->cone_omc[k] = s * s / (1 + c);
    }
    m->w_cone = m->ncone ? 0.5 / m->ncone : 0.0;
    m->w_cos = m->w_uni = m->ncone ? 0.25 : 0.5;
}

/* The direction (sin t cos p, sin t sin p, cos t) in the frame (e1, e2, z). */
static struct nc_vec3 polar(struct nc_vec3 e1, struct nc_vec3 e2, struct nc_vec3 z, double cos_t, double sin_t,
                            double phi)
{
    return nc_v3_add(nc_v3_scale(z, cos_t),
                     nc_v3_add(nc_v3_scale(e1, sin_t * cos(phi)), nc_v3_scale(e2, sin_t * sin(phi))));
}

struct nc_vec3 nc_bounce_sample(const struct nc_bounce_mix *m, double u0, double u1, double u2)
{
    const double phi = 2.0 * M_PI * u2;
    if (u0 < m->w_cos) /* cosine-weighted: sin^2 t uniform */
        return polar(m->e1, m->e2, m->n, sqrt(1.0 - u1), sqrt(u1), phi);
    if (u0 < m->w_cos + m->w_uni || m->ncone == 0) /* uniform: cos t uniform */
        return polar(m->e1, m->e2, m->n, u1, sqrt((1.0 - u1) * (1.0 + u1)), phi);
    int k = (int)((u0 - m->w_cos - m->w_uni) / m->w_cone);
    if (k >= m->ncone)
        k = m->ncone - 1;
    double x = u1 * m->cone_omc[k]; /* 1 - cos t, uniform over [0, 1 - cos theta_max] */
    return polar(m->cone_e1[k], m->cone_e2[k], m->cone_axis[k], 1.0 - x, sqrt(x * (2.0 - x)), phi);
}

double nc_bounce_pdf(const struct nc_bounce_mix *m, struct nc_vec3 w)
{
    double mu = nc_v3_dot(m->n, w), p = 0;
    if (mu > 0)
        p = m->w_cos * mu / M_PI + m->w_uni / (2.0 * M_PI);
    for (int k = 0; k < m->ncone; k++) {
        double c = nc_v3_dot(m->cone_axis[k], w);
        struct nc_vec3 x = nc_v3_cross(m->cone_axis[k], w);
        /* inside: within theta_max of the axis; the sine's square keeps
         * precision in cones far narrower than 1 - cos can resolve */
        double s2max = m->cone_omc[k] * (1 + m->cone_cos[k]);
        if (c > 0 && nc_v3_dot(x, x) <= s2max)
            p += m->w_cone / (2.0 * M_PI * m->cone_omc[k]);
    }
    return p;
}
