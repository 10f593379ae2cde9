/* test_timeline.c - pose interpolation against analytic motion: a camera on
 * a straight line at constant speed, turning at a constant rate about a fixed
 * axis, sampled every 100 ms; interpolated at arbitrary instants, positions
 * are exact (linear) and attitudes exact (slerp of a constant rotation).
 * Extrapolation with the rates, staleness, time going backwards, overflow;
 * Sun directions of unequal lengths along their great circle. */
#include <math.h>
#include <stdio.h>

#include "core/le.h"
#include "emulator/output.h"
#include "emulator/timeline.h"
#include "render/scene.h"
#include "testutil.h"

static const struct nc_vec3 V = {12.5, -3.0, 0.75}, W_AXIS = {0.267261241912424, 0.534522483824849, 0.801783725737273};
static const double OMEGA = 0.3; /* rad/s */

static struct nc_pose truth(double t)
{
    struct nc_pose p = {0};
    p.t_ns = (int64_t)llround(t * 1e9);
    p.cam_position_m = nc_v3_add(nc_v3(1e6, 2e6, -3e5), nc_v3_scale(V, t));
    double h = 0.5 * OMEGA * t;
    struct nc_quat r = {cos(h), W_AXIS.x * sin(h), W_AXIS.y * sin(h), W_AXIS.z * sin(h)};
    p.cam_attitude_q = nc_quat_mul((struct nc_quat){0.9, 0.1, -0.3, 0.3}, r);
    double n = nc_quat_norm(p.cam_attitude_q);
    p.cam_attitude_q = (struct nc_quat){p.cam_attitude_q.w / n, p.cam_attitude_q.x / n, p.cam_attitude_q.y / n,
                                        p.cam_attitude_q.z / n};
    p.cam_velocity_m_s = V;
    p.cam_angular_velocity_rad_s = nc_v3_scale(W_AXIS, OMEGA); /* body rate: right multiplication */
    p.sun = nc_v3(1, 0, 0);
    return p;
}

/* Rotation angle between two attitudes, well conditioned near zero. */
static double qdiff(struct nc_quat a, struct nc_quat b)
{
    struct nc_quat d = nc_quat_mul(a, nc_quat_conj(b));
    return 2 * atan2(sqrt(d.x * d.x + d.y * d.y + d.z * d.z), fabs(d.w));
}

int main(void)
{
    struct nc_timeline tl;
    nc_timeline_init(&tl, 64, 50000000); /* 50 ms extrapolation limit */
    struct nc_pose out;
    CHECK(nc_timeline_at(&tl, 0, &out, NULL) == NC_POSE_NONE, "empty timeline");
    for (int k = 0; k <= 20; k++) {
        struct nc_pose p = truth(0.1 * k);
        CHECK(nc_timeline_push(&tl, &p) == NC_REJECT_NONE, "push %d", k);
    }
    double worst_p = 0, worst_q = 0;
    for (double t = 0.0; t <= 2.0; t += 0.00731) {
        struct nc_pose want = truth(t);
        int64_t gap;
        CHECK(nc_timeline_at(&tl, want.t_ns, &out, &gap) == NC_POSE_INTERPOLATED && gap == 0, "inside at %g", t);
        worst_p = fmax(worst_p, nc_v3_norm(nc_v3_sub(out.cam_position_m, want.cam_position_m)));
        worst_q = fmax(worst_q, qdiff(out.cam_attitude_q, want.cam_attitude_q));
    }
    printf("interpolation: worst position error %.3g m at 2e6 m, worst attitude error %.3g rad\n", worst_p, worst_q);
    CHECK(worst_p < 1e-8, "position error %.3g m", worst_p);
    CHECK(worst_q < 1e-9, "attitude error %.3g rad", worst_q);
    /* Extrapolation with the rates, exact for this motion, then stale. */
    struct nc_pose want = truth(2.03);
    int64_t gap;
    CHECK(nc_timeline_at(&tl, want.t_ns, &out, &gap) == NC_POSE_EXTRAPOLATED && gap == 30000000, "30 ms ahead");
    CHECK(nc_v3_norm(nc_v3_sub(out.cam_position_m, want.cam_position_m)) < 1e-8 &&
              qdiff(out.cam_attitude_q, want.cam_attitude_q) < 1e-9,
          "extrapolation with rates");
    CHECK(nc_timeline_at(&tl, truth(2.2).t_ns, &out, &gap) == NC_POSE_STALE && gap == 200000000, "200 ms ahead is stale");
    CHECK(nc_timeline_at(&tl, truth(-0.01).t_ns, &out, &gap) == NC_POSE_EXTRAPOLATED && gap == 10000000,
          "before the oldest pose");
    /* Time going backwards is rejected; the same time replaces. */
    struct nc_pose old = truth(1.5);
    CHECK(nc_timeline_push(&tl, &old) == NC_REJECT_TIME_BACKWARDS, "backwards");
    struct nc_pose same = truth(2.0);
    same.cam_position_m.x += 1;
    CHECK(nc_timeline_push(&tl, &same) == NC_REJECT_NONE && tl.n == 21, "same time replaces");
    nc_timeline_at(&tl, same.t_ns, &out, NULL);
    CHECK(out.cam_position_m.x == same.cam_position_m.x, "replaced pose is used");
    /* Overflow drops the oldest. */
    for (int k = 21; k < 100; k++) {
        struct nc_pose p = truth(0.1 * k);
        nc_timeline_push(&tl, &p);
    }
    CHECK(tl.n == 64, "capacity %zu", tl.n);
    CHECK(nc_timeline_at(&tl, truth(0.5).t_ns, &out, &gap) == NC_POSE_STALE, "dropped poses are gone");
    /* Slerp takes the shorter arc between q and -q. */
    struct nc_quat a = {1, 0, 0, 0}, b = {-cos(0.1), 0, 0, -sin(0.1)};
    struct nc_quat mid = nc_quat_slerp(a, b, 0.5);
    CHECK(fabs(qdiff(mid, (struct nc_quat){cos(0.05), 0, 0, sin(0.05)})) < 1e-12, "shorter arc");
    nc_timeline_free(&tl);
    /* Sun directions of unequal lengths: along the great circle, the angle
     * in proportion to the time (a straight line between (1000, 0, 0) and
     * (0, 1, 0) was 0.06 deg from the first at mid-time, not 45) */
    nc_timeline_init(&tl, 4, 0);
    struct nc_pose s0 = truth(0), s1 = truth(1);
    s0.sun = nc_v3(1000, 0, 0);
    s1.sun = nc_v3(0, 1, 0);
    nc_timeline_push(&tl, &s0);
    nc_timeline_push(&tl, &s1);
    double worst_s = 0;
    for (int k = 0; k <= 8; k++) {
        nc_timeline_at(&tl, 125000000LL * k, &out, NULL);
        const struct nc_vec3 u = nc_v3_unit(out.sun); /* at a pose: its own vector, as sent */
        const double want_rad = k * M_PI / 16, got = atan2(u.y, u.x);
        worst_s = fmax(worst_s, fabs(got - want_rad) + fabs(u.z));
    }
    CHECK(worst_s < 1e-12, "Sun directions of unequal lengths: worst error %.3g rad", worst_s);
    nc_timeline_free(&tl);
    /* A pose without BODY_POSE stands for the configured body pose (nc_scene_pose_body): between a pose with
     * the body 3 km off and one without, the body moves from there to the configured place, and the result
     * says a body pose took part (an outside client found the record interpolated toward [0, 0, 0] while the
     * configured pose was rendered) */
    struct nc_scene sc = {.nbodies = 1};
    sc.body[0].position_m = nc_v3(100, 0, 0), sc.body[0].attitude_q = (struct nc_quat){0, 0, 0, 1};
    nc_timeline_init(&tl, 4, 0);
    struct nc_pose b0 = truth(0), b1 = truth(1);
    b0.has_body = 1, b0.body_position_m = nc_v3(3000, 0, 0), b0.body_attitude_q = (struct nc_quat){1, 0, 0, 0};
    nc_scene_pose_body(&sc, &b0);
    nc_scene_pose_body(&sc, &b1);
    CHECK(b0.body_position_m.x == 3000 && b1.body_position_m.x == 100 && b1.body_attitude_q.z == 1 && !b1.has_body,
          "the configured body pose filled in only where none was sent");
    nc_timeline_push(&tl, &b0);
    nc_timeline_push(&tl, &b1);
    nc_timeline_at(&tl, 500000000, &out, NULL);
    CHECK(out.has_body && out.body_position_m.x == 1550 && fabs(qdiff(out.body_attitude_q, (struct nc_quat){
                                                                    cos(M_PI / 4), 0, 0, sin(M_PI / 4)})) < 1e-12,
          "half way to the configured body pose: %g m, has_body %d", out.body_position_m.x, out.has_body);
    nc_timeline_at(&tl, 1000000000, &out, NULL);
    CHECK(!out.has_body && out.body_position_m.x == 100, "at the pose without a body: the configured one");
    nc_timeline_free(&tl);
    /* The metadata row (GigE, V4L2) gives the Sun as the record does: a direction made a unit vector, a
     * position as it is (the row held the vector as sent, (3, -4, 0), as an outside check found) */
    for (int pos = 0; pos < 2; pos++) {
        struct nc_frame_record rec = {.pose = truth(0)};
        rec.pose.sun = nc_v3(3, -4, 0), rec.pose.sun_is_position = pos;
        uint8_t row[NC_FRAME_META_BYTES];
        nc_frame_metadata_row(&rec, row, sizeof row);
        const double sx = nc_le_get_f64(row + 128), sy = nc_le_get_f64(row + 136);
        CHECK(pos ? sx == 3 && sy == -4 : fabs(sx - 0.6) < 1e-15 && fabs(sy + 0.8) < 1e-15,
              "the metadata row's Sun %s: (%g, %g)", pos ? "position" : "direction", sx, sy);
    }
    return nc_test_end();
}
