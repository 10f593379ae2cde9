/* test_sphere.c - a sphere and a rotated triaxial ellipsoid seen by a pinhole
 * camera at finite distance agree per pixel with the exact ray-quadric image
 * computed here in double precision (its own pinhole and rotations; the
 * reflectance through the model's interface, which test_brdf checks against
 * independent formulas), at phase angles 0..140 deg at the boresight:
 * Lambert, and Hapke (where emission and phase angles matter too, so every
 * hit's i, e and g must be right). The sphere is `type: sphere`, the
 * ellipsoid `type: ellipsoid`, turned, with the Sun turned into its frame so
 * that the phase is the one named. */
#include <math.h>
#include <stdio.h>

#include "testutil.h"

static const char yaml[] =
    "bodies:\n"
    "  - shape: {type: sphere, radius_m: 1000}\n"
    "    material: {model: lambert, A: 0.3}\n"
    "sun: {direction: [0, 0, -1], distance_au: 1.0}\n"
    "camera:\n"
    "  width_px: 160\n"
    "  height_px: 120\n"
    "  fx_px: 200\n"
    "  fy_px: 210\n"
    "  cx_px: 81.3\n"
    "  cy_px: 58.6\n"
    "  position_m: [0, 0, -4000]\n"
    "  attitude_q: [1, 0, 0, 0]\n";

/* The body's semi-axes, m (set per case in main). */
static double radii[3];

/* v turned by the unit quaternion q = [w, x, y, z] (or by its inverse),
 * written out here from v' = v + 2w (u x v) + 2 u x (u x v), u = (x, y, z),
 * so that the reference shares no code with the renderer's rotations. */
static struct nc_vec3 turn(struct nc_quat q, int inverse, struct nc_vec3 v)
{
    const double w = q.w, ux = inverse ? -q.x : q.x, uy = inverse ? -q.y : q.y, uz = inverse ? -q.z : q.z;
    const double cx = uy * v.z - uz * v.y, cy = uz * v.x - ux * v.z, cz = ux * v.y - uy * v.x;
    return nc_v3(v.x + 2 * (w * cx + uy * cz - uz * cy), v.y + 2 * (w * cy + uz * cx - ux * cz),
                 v.z + 2 * (w * cz + ux * cy - uy * cx));
}

/* Exact reference: ray from camera through pixel (x, y) against the ellipsoid
 * with semi-axes radii; returns radiance or -1 for a miss, and mu (cos
 * emission). The pinhole as docs/config.md states it: pixel centres at
 * whole coordinates, x right, y down, z along the boresight. */
static double exact(const struct nc_scene *s, double x, double y, double *mu_out)
{
    const struct nc_camera *c = &s->camera;
    const double *r = radii;
    /* Work in the body frame: the Sun is given there. */
    struct nc_vec3 dc = nc_v3((x - c->cx_px) / c->fx_px, (y - c->cy_px) / c->fy_px, 1.0);
    struct nc_vec3 d = turn(s->body[0].attitude_q, 1, nc_v3_unit(turn(c->attitude_q, 0, dc)));
    struct nc_vec3 o = turn(s->body[0].attitude_q, 1, nc_v3_sub(c->position_m, s->body[0].position_m));
    double op[3] = {o.x / r[0], o.y / r[1], o.z / r[2]}, dp[3] = {d.x / r[0], d.y / r[1], d.z / r[2]};
    double A = 0, B = 0, C = -1;
    for (int k = 0; k < 3; k++) {
        A += dp[k] * dp[k];
        B += op[k] * dp[k];
        C += op[k] * op[k];
    }
    double disc = B * B - A * C;
    if (disc < 0)
        return -1;
    double t = (-B - sqrt(disc)) / A;
    struct nc_vec3 p = nc_v3_add(o, nc_v3_scale(d, t));
    struct nc_vec3 n = nc_v3_unit(nc_v3(p.x / (r[0] * r[0]), p.y / (r[1] * r[1]), p.z / (r[2] * r[2])));
    double mu0 = nc_v3_dot(n, s->sun.direction), mu = -nc_v3_dot(n, d);
    *mu_out = mu;
    if (!(mu0 > 0 && mu > 0))
        return 0.0;
    /* The model through its own interface, at the exact i, e and g. */
    struct nc_photometry geo = {mu0, mu, -nc_v3_dot(s->sun.direction, d), 1.0};
    double refl;
    nc_material_eval(&s->body[0].material, 1, &geo, &refl);
    return refl * s->sun.irradiance_w_m2;
}

static void compare(const char *label, const struct nc_scene *s)
{
    struct nc_frame f;
    nc_test_render(s, 2, &f);
    int W = f.width_px, H = f.height_px, compared = 0, lit = 0, bad_hit = 0;
    double worst = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double mu, L = exact(s, x, y, &mu);
            float got = f.radiance[y * W + x];
            if (L < 0) {
                bad_hit += got != 0.0f || f.coverage[y * W + x] != 0.0f;
                continue;
            }
            if (mu < 0.02) /* the limb: a pixel footprint straddles the edge */
                continue;
            bad_hit += f.coverage[y * W + x] != 1.0f;
            if (L == 0) {
                bad_hit += got != 0.0f;
                continue;
            }
            double rel = fabs(got - L) / L;
            if (rel > worst)
                worst = rel;
            compared++;
            lit++;
        }
    CHECK(lit > 50, "%s: only %d lit pixels compared", label, lit);
    /* the float32 image rounds at 6e-8 */
    CHECK(worst < 2e-7, "%s: worst relative error %.3g over %d pixels", label, worst, compared);
    CHECK(bad_hit == 0, "%s: %d pixels disagree on hit/miss or shadow", label, bad_hit);
    printf("%-34s lit pixels %5d  worst rel. error %.2e\n", label, lit, worst);
    nc_frame_free(&f);
}

/* the rotated body's attitude (body -> scene), as set below */
static const struct nc_quat body_q = {0.9238795325112867, 0.0, 0.3826834323650898, 0.0};

int main(void)
{
    const double phases_deg[] = {0, 30, 90, 140};
    for (int shape = 0; shape < 4; shape++)
        for (size_t k = 0; k < sizeof phases_deg / sizeof phases_deg[0]; k++) {
            double g = phases_deg[k] * M_PI / 180;
            char sun[128], label[64];
            /* The Sun turns about the scene's y axis away from the camera
             * direction (-z), by the phase angle at the boresight. The Sun
             * is given in the body frame: for the rotated body, that
             * direction turned into it. */
            struct nc_vec3 sun_scene = nc_v3(sin(g), 0, -cos(g)), sb = sun_scene;
            if (shape == 1 || shape == 3)
                sb = turn(body_q, 1, sun_scene);
            snprintf(sun, sizeof sun, "sun.direction=[%.17g, %.17g, %.17g]", sb.x, sb.y, sb.z);
            const char *sets[5] = {sun};
            int nsets = 1;
            if (shape >= 2) /* a model in which e and g matter: Hapke, rough, with opposition surge */
                sets[nsets++] = shape == 2 ? "bodies.0.material={preset: comet_67p}"
                                           : "bodies.0.material={preset: moon, B_C0: 0.5, h_C: 0.02}";
            radii[0] = radii[1] = radii[2] = 1000;
            if (shape == 1 || shape == 3) {
                sets[nsets++] = "bodies.0.shape={type: ellipsoid, radii_m: [1300, 800, 600]}";
                radii[0] = 1300, radii[1] = 800, radii[2] = 600;
                /* A rotated body and an off-axis camera pose. */
                sets[nsets++] = "bodies.0.attitude_q=[0.9238795325112867, 0.0, 0.3826834323650898, 0.0]";
                sets[nsets++] = "camera.attitude_q=[0.99984769515639127, 0.0, 0.0, 0.017452406437283512]";
            }
            struct nc_scene s;
            nc_test_scene(yaml, sets, nsets, &s);
            static const char *const names[] = {"Lambert sphere", "Lambert ellipsoid", "Hapke 67P sphere",
                                                "Hapke Moon+CBOE ellipsoid"};
            snprintf(label, sizeof label, "%s, phase %3.0f deg", names[shape], phases_deg[k]);
            compare(label, &s);
            nc_scene_free(&s);
        }
    return nc_test_end();
}
