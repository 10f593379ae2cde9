/* traj.h - trajectories for `navcam replay` and `navcam batch`: one pose
 * per row of a CSV file, in one of two layouts told apart by the header.
 *
 * Pose rows (the header optional):
 *   t_s, cam_x_m, cam_y_m, cam_z_m, q_w, q_x, q_y, q_z, sun_x, sun_y, sun_z[, capture]
 * the camera position in the scene frame (m), its attitude (scalar-first
 * quaternion, camera -> scene), the Sun direction in bodies[0]'s frame;
 * capture 0 skips the row's frame (default 1).
 * SUM-like rows (the header required: its first two names t_s,scobj_x_km,
 * or every column named):
 *   t_s, scobj_x_km, scobj_y_km, scobj_z_km, cx_x, cx_y, cx_z, cy_x, cy_y,
 *   cy_z, cz_x, cz_y, cz_z, sz_x, sz_y, sz_z[, capture]
 * an SPC SUM file's geometry (core/sumfile.h) per row: SCOBJ (km,
 * spacecraft -> body centre), the camera axes CX, CY, CZ and the Sun
 * direction SZ, all in bodies[0]'s body-fixed frame (body_frame set: a
 * user that knows the scene moves the pose with bodies[0], as
 * camera.sumfile does). The intrinsics are the scene's camera.
 * A header whose names are a layout's own, each once, with every column
 * but capture, in any order, has the columns taken by name (SUM-like when
 * one is a SUM-like column); one with no such name, or each at its own
 * place, leaves them in order; any other header is an error.
 * "builtin:approach" names the default scene's built-in approach.
 */
#ifndef NC_TRAJ_H
#define NC_TRAJ_H

#include "core/vec.h"

struct nc_traj_row {
    double t_s;
    struct nc_vec3 p; /* camera position, scene frame, m */
    struct nc_quat q; /* camera -> scene */
    struct nc_vec3 sun; /* toward the Sun, bodies[0] frame */
    int capture;
    int line;         /* in the file (0: built in) */
    int body_frame;   /* 1: p and q are in bodies[0]'s body-fixed frame (SUM-like rows) */
};

/* Rows of path into *out (caller frees); the count, or < 0 with a message
 * naming the file, line and what was expected. */
int nc_traj_read(const char *path, struct nc_traj_row **out);

#endif
