/* scene_pose.c - a scene's pose as a value (core/pose.h) and back: what the
 * emulator renders a timeline pose with, and what it renders before any
 * pose has arrived (scene.h). */
#include "render/scene.h"

void nc_scene_pose(const struct nc_scene *s, int64_t t_ns, struct nc_pose *p)
{
    *p = (struct nc_pose){.t_ns = t_ns,
                          .cam_position_m = s->camera.position_m,
                          .cam_attitude_q = s->camera.attitude_q,
                          .cam_velocity_m_s = s->camera.velocity_m_s,
                          .cam_angular_velocity_rad_s = s->camera.angular_velocity_rad_s,
                          .sun = s->sun.has_position ? s->sun.position_m : s->sun.direction,
                          .sun_is_position = s->sun.has_position,
                          .has_body = 1,
                          .body_position_m = s->body[0].position_m,
                          .body_attitude_q = s->body[0].attitude_q,
                          .body_velocity_m_s = s->body[0].velocity_m_s,
                          .body_angular_velocity_rad_s = s->body[0].angular_velocity_rad_s};
}

void nc_scene_pose_body(const struct nc_scene *s, struct nc_pose *p)
{
    if (!p->has_body) {
        p->body_position_m = s->body[0].position_m;
        p->body_attitude_q = s->body[0].attitude_q;
    }
}

void nc_scene_apply_pose(struct nc_scene *s, const struct nc_pose *p)
{
    s->camera.position_m = p->cam_position_m;
    s->camera.attitude_q = p->cam_attitude_q;
    s->camera.velocity_m_s = p->cam_velocity_m_s;
    s->camera.angular_velocity_rad_s = p->cam_angular_velocity_rad_s;
    if (p->sun_is_position) {
        s->sun.has_position = 1;
        s->sun.position_m = p->sun;
    } else {
        s->sun.has_position = 0;
        s->sun.direction = nc_v3_unit(p->sun);
    }
    if (p->has_body) {
        s->body[0].position_m = p->body_position_m;
        s->body[0].attitude_q = p->body_attitude_q;
    }
    s->body[0].velocity_m_s = p->body_velocity_m_s;
    s->body[0].angular_velocity_rad_s = p->body_angular_velocity_rad_s;
}
