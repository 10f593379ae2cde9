/* navcam/types.h - the plain value types of NavCam's public interface: a
 * double-precision 3-vector and a unit quaternion (scalar first, [w, x, y, z],
 * rotating frame b vectors into frame a: v_a = q v_b q*). Public: it must not
 * include any internal header. core/vec.h adds the arithmetic on them.
 */
#ifndef NAVCAM_TYPES_H
#define NAVCAM_TYPES_H

struct nc_vec3 { double x, y, z; };
struct nc_quat { double w, x, y, z; };

#endif
