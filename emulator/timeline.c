/* timeline.c - pose buffering and interpolation (timeline.h). */
#include "emulator/timeline.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/scene.h"

int nc_timeline_init(struct nc_timeline *tl, size_t cap, int64_t max_extrapolation_ns)
{
    memset(tl, 0, sizeof *tl);
    if (cap < 2)
        cap = 2;
    tl->ring = calloc(cap, sizeof *tl->ring);
    if (!tl->ring)
        return nc_error(-ENOMEM, "out of memory for %zu poses", cap);
    tl->cap = cap;
    tl->max_extrapolation_ns = max_extrapolation_ns;
    return 0;
}

void nc_timeline_free(struct nc_timeline *tl)
{
    free(tl->ring);
    memset(tl, 0, sizeof *tl);
}

void nc_pose_from_msg(const struct nc_pose_msg *m, struct nc_pose *p)
{
    memset(p, 0, sizeof *p);
    p->t_ns = m->sim_time_ns;
    p->cam_position_m = m->cam_position_m;
    p->cam_attitude_q = m->cam_attitude_q;
    p->sun = m->sun;
    p->sun_is_position = !!(m->flags & NC_MSG_SUN_POSITION);
    p->has_body = !!(m->flags & NC_MSG_BODY_POSE);
    p->body_position_m = m->body_position_m;
    p->body_attitude_q = m->body_attitude_q;
    p->cam_velocity_m_s = m->cam_velocity_m_s;
    p->cam_angular_velocity_rad_s = m->cam_angular_velocity_rad_s;
    p->body_velocity_m_s = m->body_velocity_m_s;
    p->body_angular_velocity_rad_s = m->body_angular_velocity_rad_s;
}

static const struct nc_pose *at_index(const struct nc_timeline *tl, size_t i)
{
    return &tl->ring[(tl->head + i) % tl->cap];
}

enum nc_reject nc_timeline_push(struct nc_timeline *tl, const struct nc_pose *p)
{
    if (tl->n > 0) {
        struct nc_pose *last = &tl->ring[(tl->head + tl->n - 1) % tl->cap];
        if (p->t_ns < last->t_ns)
            return NC_REJECT_TIME_BACKWARDS;
        if (p->t_ns == last->t_ns) {
            *last = *p;
            return NC_REJECT_NONE;
        }
    }
    if (tl->n == tl->cap) { /* drop the oldest */
        tl->head = (tl->head + 1) % tl->cap;
        tl->n--;
    }
    tl->ring[(tl->head + tl->n) % tl->cap] = *p;
    tl->n++;
    return NC_REJECT_NONE;
}

struct nc_quat nc_quat_slerp(struct nc_quat a, struct nc_quat b, double s)
{
    double d = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
    if (d < 0) { /* q and -q are one attitude: take the shorter arc */
        b = (struct nc_quat){-b.w, -b.x, -b.y, -b.z};
        d = -d;
    }
    double wa, wb;
    if (d > 0.9999999) { /* nearly equal: linear, then normalised */
        wa = 1 - s;
        wb = s;
    } else {
        double th = acos(d), sn = sin(th);
        wa = sin((1 - s) * th) / sn;
        wb = sin(s * th) / sn;
    }
    struct nc_quat q = {wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z};
    double n = nc_quat_norm(q);
    return (struct nc_quat){q.w / n, q.x / n, q.y / n, q.z / n};
}

static struct nc_vec3 lerp(struct nc_vec3 a, struct nc_vec3 b, double s)
{
    return nc_v3(a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), a.z + s * (b.z - a.z));
}

/* Directions a and b (of any lengths) interpolated along the great circle
 * between them: the angle from a grows in proportion to s, whatever the
 * lengths the simulator gave (a straight line between vectors of unequal
 * lengths is not). Opposite directions have no one circle: the nearer one. */
static struct nc_vec3 dir_slerp(struct nc_vec3 a, struct nc_vec3 b, double s)
{
    const struct nc_vec3 ua = nc_v3_unit(a), ub = nc_v3_unit(b);
    const double sn = nc_v3_norm(nc_v3_cross(ua, ub)), th = atan2(sn, nc_v3_dot(ua, ub));
    if (th < 1e-4) /* linear, then normalised: within 1e-13 rad of the arc */
        return nc_v3_unit(lerp(ua, ub, s));
    if (sn < 1e-12)
        return s < 0.5 ? ua : ub;
    const double wa = sin((1 - s) * th) / sn, wb = sin(s * th) / sn;
    return nc_v3_unit(nc_v3_add(nc_v3_scale(ua, wa), nc_v3_scale(ub, wb)));
}

/* Pose p moved by dt seconds with its own rates. */
static void propagate(const struct nc_pose *p, double dt, struct nc_pose *out)
{
    *out = *p;
    out->cam_position_m = nc_v3_add(p->cam_position_m, nc_v3_scale(p->cam_velocity_m_s, dt));
    out->cam_attitude_q = nc_quat_propagate(p->cam_attitude_q, p->cam_angular_velocity_rad_s, dt);
    out->body_position_m = nc_v3_add(p->body_position_m, nc_v3_scale(p->body_velocity_m_s, dt));
    out->body_attitude_q = nc_quat_propagate(p->body_attitude_q, p->body_angular_velocity_rad_s, dt);
}

enum nc_pose_quality nc_timeline_at(const struct nc_timeline *tl, int64_t t, struct nc_pose *out, int64_t *gap_ns)
{
    if (gap_ns)
        *gap_ns = 0;
    if (tl->n == 0)
        return NC_POSE_NONE;
    const struct nc_pose *first = at_index(tl, 0), *last = at_index(tl, tl->n - 1);
    if (t < first->t_ns || t > last->t_ns) {
        const struct nc_pose *end = t < first->t_ns ? first : last;
        int64_t gap = t < first->t_ns ? first->t_ns - t : t - last->t_ns;
        propagate(end, (double)(t - end->t_ns) * 1e-9, out);
        out->t_ns = t;
        if (gap_ns)
            *gap_ns = gap;
        return gap <= tl->max_extrapolation_ns ? NC_POSE_EXTRAPOLATED : NC_POSE_STALE;
    }
    /* Binary search for the last pose at or before t. */
    size_t lo = 0, hi = tl->n - 1;
    while (lo < hi) {
        size_t mid = (lo + hi + 1) / 2;
        if (at_index(tl, mid)->t_ns <= t)
            lo = mid;
        else
            hi = mid - 1;
    }
    const struct nc_pose *a = at_index(tl, lo);
    if (a->t_ns == t || lo + 1 == tl->n) {
        *out = *a;
        return NC_POSE_INTERPOLATED;
    }
    const struct nc_pose *b = at_index(tl, lo + 1);
    double s = (double)(t - a->t_ns) / (double)(b->t_ns - a->t_ns);
    *out = *a;
    out->t_ns = t;
    out->cam_position_m = lerp(a->cam_position_m, b->cam_position_m, s);
    out->cam_attitude_q = nc_quat_slerp(a->cam_attitude_q, b->cam_attitude_q, s);
    out->body_position_m = lerp(a->body_position_m, b->body_position_m, s);
    out->body_attitude_q = nc_quat_slerp(a->body_attitude_q, b->body_attitude_q, s);
    out->cam_velocity_m_s = lerp(a->cam_velocity_m_s, b->cam_velocity_m_s, s);
    out->cam_angular_velocity_rad_s = lerp(a->cam_angular_velocity_rad_s, b->cam_angular_velocity_rad_s, s);
    out->body_velocity_m_s = lerp(a->body_velocity_m_s, b->body_velocity_m_s, s);
    out->body_angular_velocity_rad_s = lerp(a->body_angular_velocity_rad_s, b->body_angular_velocity_rad_s, s);
    if (a->sun_is_position == b->sun_is_position)
        out->sun = a->sun_is_position ? lerp(a->sun, b->sun, s) : dir_slerp(a->sun, b->sun, s);
    out->has_body = a->has_body || b->has_body; /* the body as configured where a pose gave none */
    return NC_POSE_INTERPOLATED;
}
