/* vec.h - double-precision 3-vectors and unit quaternions for poses.
 *
 * Quaternion convention used everywhere in NavCam: scalar first, q = [w, x, y, z],
 * Hamilton product. An attitude quaternion q_a_b rotates vectors expressed in
 * frame b into frame a: v_a = q v_b q*. The columns of nc_quat_to_mat(q) are the
 * axes of frame b expressed in frame a. Positions are metres, always double.
 */
#ifndef NC_VEC_H
#define NC_VEC_H

#include <float.h>
#include <math.h>

#include "navcam/types.h"

/* Row-major 3x3 rotation: m[r][c]. */
struct nc_mat3 { double m[3][3]; };

static inline struct nc_vec3 nc_v3(double x, double y, double z) { return (struct nc_vec3){x, y, z}; }
static inline struct nc_vec3 nc_v3_add(struct nc_vec3 a, struct nc_vec3 b) { return nc_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline struct nc_vec3 nc_v3_sub(struct nc_vec3 a, struct nc_vec3 b) { return nc_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline struct nc_vec3 nc_v3_scale(struct nc_vec3 a, double s) { return nc_v3(a.x * s, a.y * s, a.z * s); }
static inline double nc_v3_dot(struct nc_vec3 a, struct nc_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline double nc_v3_norm(struct nc_vec3 a) { return sqrt(nc_v3_dot(a, a)); }
static inline struct nc_vec3 nc_v3_cross(struct nc_vec3 a, struct nc_vec3 b)
{
    return nc_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline int nc_v3_is_zero(struct nc_vec3 a) { return a.x == 0 && a.y == 0 && a.z == 0; }
/* a over its length; a zero (or not finite) a as it is. Components whose
 * squares would overflow or underflow (beyond about 1e150, below 1e-150)
 * are scaled by the largest first, so [1e200, 1e200, 0] is a direction. */
static inline struct nc_vec3 nc_v3_unit(struct nc_vec3 a)
{
    double n = nc_v3_norm(a);
    if (!(n > 1e-150 && n < 1e150)) {
        const double m = fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
        if (!(m > 0 && m <= DBL_MAX))
            return a;
        a = nc_v3(a.x / m, a.y / m, a.z / m);
        n = nc_v3_norm(a);
    }
    return nc_v3_scale(a, 1.0 / n);
}
static inline int nc_v3_isfinite(struct nc_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* Two unit axes across the unit vector a: (e1, e2, a) is right-handed. */
static inline void nc_v3_basis(struct nc_vec3 a, struct nc_vec3 *e1, struct nc_vec3 *e2)
{
    *e1 = nc_v3_unit(fabs(a.x) < 0.9 ? nc_v3_cross(a, nc_v3(1, 0, 0)) : nc_v3_cross(a, nc_v3(0, 1, 0)));
    *e2 = nc_v3_cross(a, *e1);
}

static inline int nc_quat_isfinite(struct nc_quat q)
{
    return isfinite(q.w) && isfinite(q.x) && isfinite(q.y) && isfinite(q.z);
}
static inline double nc_quat_norm(struct nc_quat q) { return sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z); }

static inline struct nc_quat nc_quat_mul(struct nc_quat a, struct nc_quat b)
{
    return (struct nc_quat){
        a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
        a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
        a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
        a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
    };
}

static inline struct nc_quat nc_quat_conj(struct nc_quat q) { return (struct nc_quat){q.w, -q.x, -q.y, -q.z}; }

static inline struct nc_mat3 nc_quat_to_mat(struct nc_quat q)
{
    double w = q.w, x = q.x, y = q.y, z = q.z;
    struct nc_mat3 r = {{
        {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
        {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
        {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
    }};
    return r;
}

static inline struct nc_vec3 nc_mat_mul_v(const struct nc_mat3 *r, struct nc_vec3 v)
{
    return nc_v3(r->m[0][0] * v.x + r->m[0][1] * v.y + r->m[0][2] * v.z,
                 r->m[1][0] * v.x + r->m[1][1] * v.y + r->m[1][2] * v.z,
                 r->m[2][0] * v.x + r->m[2][1] * v.y + r->m[2][2] * v.z);
}

/* Transpose times vector: the inverse rotation. */
static inline struct nc_vec3 nc_mat_tmul_v(const struct nc_mat3 *r, struct nc_vec3 v)
{
    return nc_v3(r->m[0][0] * v.x + r->m[1][0] * v.y + r->m[2][0] * v.z,
                 r->m[0][1] * v.x + r->m[1][1] * v.y + r->m[2][1] * v.z,
                 r->m[0][2] * v.x + r->m[1][2] * v.y + r->m[2][2] * v.z);
}

static inline struct nc_vec3 nc_quat_rotate(struct nc_quat q, struct nc_vec3 v)
{
    struct nc_mat3 r = nc_quat_to_mat(q);
    return nc_mat_mul_v(&r, v);
}

/* Rotation matrix (columns = frame axes in the parent frame) to quaternion. */
struct nc_quat nc_quat_from_mat(const struct nc_mat3 *r);

/* Attitude of a camera (+Z boresight, +Y down in the image) at `eye` looking at
 * `target`, with the scene vector `up` appearing up (-Y) in the image. */
int nc_quat_look_at(struct nc_vec3 eye, struct nc_vec3 target, struct nc_vec3 up, struct nc_quat *out);

#endif
