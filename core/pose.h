/* pose.h - the pose of a camera and its target body at one instant: what a
 * simulator sends, what the timeline interpolates, what a frame was rendered
 * with. A plain value type (double precision, SI units); no behaviour here.
 * The renderer applies it to a scene (render/scene.h: nc_scene_apply_pose).
 */
#ifndef NC_POSE_H
#define NC_POSE_H

#include <stdint.h>

#include "core/vec.h"

/* The camera every input may describe (camera.* keys, SUM files,
 * trajectories): within 1e15 m (6700 au, beyond any mission) of the scene's
 * origin on each axis (a camera at 1e200 m left the render no image axes),
 * focal lengths of 1e-3 to 1e9 pixels, a principal point within 1e6 pixels.
 * Bodies' positions have the same limit, cameras' and bodies' speeds the
 * speed of light (as the pose protocol's, include/navcam/protocol.h). */
#define NC_CAMERA_MAX_M 1e15
#define NC_CAMERA_MAX_TEXT "1e+15 m"
#define NC_SPEED_MAX_M_S 299792458.0
#define NC_SPEED_MAX_TEXT "the speed of light, 299792458 m/s"
#define NC_FOCAL_MIN_PX 1e-3
#define NC_FOCAL_MAX_PX 1e9
#define NC_PRINCIPAL_MAX_PX 1e6

struct nc_pose {
    int64_t t_ns;                  /* simulation time */
    struct nc_vec3 cam_position_m; /* scene frame */
    struct nc_quat cam_attitude_q; /* camera -> scene */
    struct nc_vec3 sun;            /* body frame of bodies[0]: a direction, or a position (m) */
    int sun_is_position;
    int has_body;
    struct nc_vec3 body_position_m; /* bodies[0], scene frame */
    struct nc_quat body_attitude_q; /* bodies[0], body -> scene */
    struct nc_vec3 cam_velocity_m_s, cam_angular_velocity_rad_s;
    struct nc_vec3 body_velocity_m_s, body_angular_velocity_rad_s;
};

/* Where a frame's pose came from. */
enum nc_pose_quality {
    NC_POSE_INTERPOLATED = 0, /* between two buffered poses (or exactly on one) */
    NC_POSE_EXTRAPOLATED = 1, /* beyond the newest (or before the oldest), within the limit */
    NC_POSE_STALE = 2,        /* beyond the limit: the pose is filled, the caller decides */
    NC_POSE_NONE = 3,         /* nothing buffered yet */
    NC_POSE_SCENE = 4,        /* nothing received yet: the scene's configured pose (serve.no_pose: scene) */
};

#endif
