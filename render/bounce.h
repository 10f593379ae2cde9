/* bounce.h - the directions indirect light is gathered from.
 *
 * At a path vertex the next direction w is drawn from a mixture of
 * strategies and weighted by r / pdf(w), with pdf the mixture's density
 * (one-sample multiple importance sampling with the balance heuristic):
 *   - cosine-weighted over the hemisphere of the normal, pdf = mu / pi:
 *     exact importance sampling of a Lambert surface (r / pdf = A);
 *   - uniform over the hemisphere, pdf = 1 / (2 pi): keeps r / pdf bounded
 *     where r does not vanish with the cosine, as Lommel-Seeliger and Hapke
 *     do not at grazing emission (r ~ mu0 / (mu0 + mu));
 *   - uniform over the cone of each other body's bounding sphere seen
 *     above the horizon, pdf = 1 / (2 pi (1 - cos theta_max)) inside it:
 *     light from a moon subtending a small solid angle (inter-body light).
 * Mixture weights: half to the cones when there are any, the rest split
 * evenly between cosine and uniform. Directions are unit vectors in the
 * scene frame; densities are per steradian.
 */
#ifndef NC_BOUNCE_H
#define NC_BOUNCE_H

#include "core/vec.h"
#include "render/scene.h"

struct nc_bounce_mix {
    struct nc_vec3 n, e1, e2; /* the normal, and two axes across it */
    double w_cos, w_uni;      /* mixture weights; each cone has w_cone */
    double w_cone;
    int ncone;
    struct nc_vec3 cone_axis[NC_MAX_BODIES], cone_e1[NC_MAX_BODIES], cone_e2[NC_MAX_BODIES];
    double cone_cos[NC_MAX_BODIES];  /* cos theta_max */
    double cone_omc[NC_MAX_BODIES];  /* 1 - cos theta_max, without cancellation */
};

/* The mixture at a point with unit normal n: centre_rel[b] is body b's
 * centre relative to the point (m) and radius_m[b] its bounding radius;
 * body self (the point's own) gets no cone, nor does a body whose sphere
 * holds the point or lies wholly below the horizon. */
void nc_bounce_init(struct nc_bounce_mix *m, struct nc_vec3 n, const struct nc_vec3 *centre_rel,
                    const double *radius_m, int nbodies, int self);
/* A direction from three uniform numbers in [0, 1); it may point below the
 * horizon (a cone's edge), where the caller's r is 0. */
struct nc_vec3 nc_bounce_sample(const struct nc_bounce_mix *m, double u0, double u1, double u2);
/* The mixture's density at unit direction w, 1/sr. */
double nc_bounce_pdf(const struct nc_bounce_mix *m, struct nc_vec3 w);

#endif
