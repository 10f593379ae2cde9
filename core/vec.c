/* vec.c - the non-inline pose helpers of vec.h. */
#include "vec.h"

#include "error.h"

struct nc_quat nc_quat_from_mat(const struct nc_mat3 *r)
{
    /* Shepperd's method: pick the largest diagonal term for stability. */
    const double (*m)[3] = r->m;
    double tr = m[0][0] + m[1][1] + m[2][2];
    struct nc_quat q;
    if (tr > m[0][0] && tr > m[1][1] && tr > m[2][2]) {
        double s = 2.0 * sqrt(1.0 + tr);
        q = (struct nc_quat){0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s};
    } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
        double s = 2.0 * sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]);
        q = (struct nc_quat){(m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s};
    } else if (m[1][1] > m[2][2]) {
        double s = 2.0 * sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]);
        q = (struct nc_quat){(m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s};
    } else {
        double s = 2.0 * sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]);
        q = (struct nc_quat){(m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s};
    }
    if (q.w < 0)
        q = (struct nc_quat){-q.w, -q.x, -q.y, -q.z};
    double n = nc_quat_norm(q);
    return (struct nc_quat){q.w / n, q.x / n, q.y / n, q.z / n};
}

int nc_quat_look_at(struct nc_vec3 eye, struct nc_vec3 target, struct nc_vec3 up, struct nc_quat *out)
{
    struct nc_vec3 z = nc_v3_sub(target, eye);
    if (nc_v3_is_zero(z))
        return nc_error(NC_ERANGE, "look-at target coincides with the camera position");
    z = nc_v3_unit(z);
    /* Image +Y is down, so the camera's -Y should lean toward `up`. */
    struct nc_vec3 x = nc_v3_cross(nc_v3_scale(up, -1.0), z);
    if (nc_v3_is_zero(up))
        return nc_error(NC_ERANGE, "look-at 'up' vector is zero");
    if (nc_v3_norm(nc_v3_cross(nc_v3_unit(up), z)) < 1e-9) /* of unit length: no overflow or underflow */
        return nc_error(NC_ERANGE, "look-at 'up' vector is parallel to the line of sight");
    x = nc_v3_unit(x);
    struct nc_vec3 y = nc_v3_cross(z, x);
    struct nc_mat3 r = {{{x.x, y.x, z.x}, {x.y, y.y, z.y}, {x.z, y.z, z.z}}};
    *out = nc_quat_from_mat(&r);
    return 0;
}
