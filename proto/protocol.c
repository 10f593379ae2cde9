/* protocol.c - encoding and validating pose protocol messages. */
#include "navcam/protocol.h"

#include "core/le.h"
#include "core/vec.h"

#include <math.h>
#include <string.h>
#include <zlib.h>

const char *nc_reject_name(enum nc_reject r)
{
    switch (r) {
#define NC__XNAME(name, key, text) case NC_REJECT_##name: return text;
        NC_REJECT_REASONS(NC__XNAME)
#undef NC__XNAME
    default:
        return "accepted";
    }
}

const char *nc_reject_key(enum nc_reject r)
{
    switch (r) {
#define NC__XKEY(name, key, text) case NC_REJECT_##name: return key;
        NC_REJECT_REASONS(NC__XKEY)
#undef NC__XKEY
    default:
        return "accepted";
    }
}

size_t nc_msg_size(enum nc_msg_type type, uint32_t flags)
{
    size_t n = NC_PROTO_HEADER_BYTES;
    if (type == NC_MSG_POSE) {
        n += 8 + 3 * 8 + 4 * 8 + 3 * 8; /* time, camera position, attitude, Sun */
        if (flags & NC_MSG_BODY_POSE)
            n += 7 * 8;
        if (flags & NC_MSG_CAMERA_RATES)
            n += 6 * 8;
        if (flags & NC_MSG_BODY_RATES)
            n += 6 * 8;
    } else if (type == NC_MSG_FRAME) {
        n += 8 + 8 + 4 + 4; /* request time, frame number, status, reserved */
    } else {
        n += 8; /* a trigger carries its simulation time */
    }
    if (flags & NC_MSG_EXPOSURE)
        n += 8;
    if (flags & NC_MSG_GAIN)
        n += 8;
    return n + 4; /* CRC */
}

static uint8_t *put_vec(uint8_t *p, struct nc_vec3 v)
{
    nc_le_put_f64(p, v.x), nc_le_put_f64(p + 8, v.y), nc_le_put_f64(p + 16, v.z);
    return p + 24;
}

static uint8_t *put_quat(uint8_t *p, struct nc_quat q)
{
    nc_le_put_f64(p, q.w), nc_le_put_f64(p + 8, q.x), nc_le_put_f64(p + 16, q.y), nc_le_put_f64(p + 24, q.z);
    return p + 32;
}

size_t nc_msg_encode(const struct nc_pose_msg *m, uint8_t *buf, size_t cap)
{
    size_t n = nc_msg_size(m->type, m->flags);
    if ((m->type != NC_MSG_POSE && m->type != NC_MSG_TRIGGER && m->type != NC_MSG_FRAME) || n > cap ||
        (m->flags & ~NC_MSG_KNOWN_FLAGS) || (m->type != NC_MSG_POSE && (m->flags & NC_MSG_POSE_ONLY_FLAGS)))
        return 0;
    nc_le_put_u32(buf, NC_PROTO_MAGIC);
    nc_le_put_u16(buf + 4, NC_PROTO_VERSION);
    nc_le_put_u16(buf + 6, (uint16_t)m->type);
    nc_le_put_u32(buf + 8, (uint32_t)n);
    nc_le_put_u32(buf + 12, m->sequence);
    nc_le_put_u32(buf + 16, m->flags);
    nc_le_put_u32(buf + 20, 0); /* reserved */
    uint8_t *p = buf + NC_PROTO_HEADER_BYTES;
    nc_le_put_u64(p, (uint64_t)m->sim_time_ns);
    p += 8;
    if (m->type == NC_MSG_POSE) {
        p = put_vec(p, m->cam_position_m);
        p = put_quat(p, m->cam_attitude_q);
        p = put_vec(p, m->sun);
        if (m->flags & NC_MSG_BODY_POSE) {
            p = put_vec(p, m->body_position_m);
            p = put_quat(p, m->body_attitude_q);
        }
        if (m->flags & NC_MSG_CAMERA_RATES) {
            p = put_vec(p, m->cam_velocity_m_s);
            p = put_vec(p, m->cam_angular_velocity_rad_s);
        }
        if (m->flags & NC_MSG_BODY_RATES) {
            p = put_vec(p, m->body_velocity_m_s);
            p = put_vec(p, m->body_angular_velocity_rad_s);
        }
    } else if (m->type == NC_MSG_FRAME) {
        nc_le_put_u64(p, m->frame);
        nc_le_put_u32(p + 8, m->status);
        nc_le_put_u32(p + 12, 0);
        p += 16;
    }
    if (m->flags & NC_MSG_EXPOSURE) {
        nc_le_put_f64(p, m->exposure_s);
        p += 8;
    }
    if (m->flags & NC_MSG_GAIN) {
        nc_le_put_f64(p, m->gain_db);
        p += 8;
    }
    nc_le_put_u32(p, (uint32_t)crc32(0L, buf, (uInt)(p - buf)));
    return n;
}

static const uint8_t *get_vec(const uint8_t *p, struct nc_vec3 *v)
{
    *v = nc_v3(nc_le_get_f64(p), nc_le_get_f64(p + 8), nc_le_get_f64(p + 16));
    return p + 24;
}

static const uint8_t *get_quat(const uint8_t *p, struct nc_quat *q)
{
    *q = (struct nc_quat){nc_le_get_f64(p), nc_le_get_f64(p + 8), nc_le_get_f64(p + 16), nc_le_get_f64(p + 24)};
    return p + 32;
}


/* Unit within tolerance, then normalised. */
static int unit_quat(struct nc_quat *q)
{
    double n = nc_quat_norm(*q);
    if (!(fabs(n - 1.0) <= NC_PROTO_QUAT_TOL))
        return 0;
    *q = (struct nc_quat){q->w / n, q->x / n, q->y / n, q->z / n};
    return 1;
}

enum nc_reject nc_msg_decode(const uint8_t *buf, size_t len, struct nc_pose_msg *m)
{
    if (len < NC_PROTO_HEADER_BYTES + 4)
        return NC_REJECT_TRUNCATED;
    if (len > NC_PROTO_MAX_BYTES)
        return NC_REJECT_OVERSIZED;
    if (nc_le_get_u32(buf) != NC_PROTO_MAGIC)
        return NC_REJECT_BAD_MAGIC;
    if (nc_le_get_u16(buf + 4) != NC_PROTO_VERSION)
        return NC_REJECT_BAD_VERSION;
    uint16_t type = nc_le_get_u16(buf + 6);
    if (type != NC_MSG_POSE && type != NC_MSG_TRIGGER && type != NC_MSG_FRAME)
        return NC_REJECT_BAD_TYPE;
    uint32_t flags = nc_le_get_u32(buf + 16);
    /* Bits no version-1 message has, a pose's blocks on another type, or
     * a reserved word not 0 (a sender that wrote its flags there, say):
     * what the sender meant cannot be known. */
    if ((flags & ~NC_MSG_KNOWN_FLAGS) || (type != NC_MSG_POSE && (flags & NC_MSG_POSE_ONLY_FLAGS)) ||
        nc_le_get_u32(buf + 20))
        return NC_REJECT_BAD_FLAGS;
    size_t want = nc_msg_size((enum nc_msg_type)type, flags);
    if (nc_le_get_u32(buf + 8) != want)
        return NC_REJECT_BAD_LENGTH;
    if (len < want)
        return NC_REJECT_TRUNCATED;
    if (len > want)
        return NC_REJECT_BAD_LENGTH;
    if (nc_le_get_u32(buf + want - 4) != (uint32_t)crc32(0L, buf, (uInt)(want - 4)))
        return NC_REJECT_BAD_CRC;

    memset(m, 0, sizeof *m);
    m->type = (enum nc_msg_type)type;
    m->sequence = nc_le_get_u32(buf + 12);
    m->flags = flags;
    const uint8_t *p = buf + NC_PROTO_HEADER_BYTES;
    m->sim_time_ns = (int64_t)nc_le_get_u64(p);
    p += 8;
    m->cam_attitude_q = m->body_attitude_q = (struct nc_quat){1, 0, 0, 0};
    if (type == NC_MSG_POSE) {
        p = get_vec(p, &m->cam_position_m);
        p = get_quat(p, &m->cam_attitude_q);
        p = get_vec(p, &m->sun);
        if (flags & NC_MSG_BODY_POSE) {
            p = get_vec(p, &m->body_position_m);
            p = get_quat(p, &m->body_attitude_q);
        }
        if (flags & NC_MSG_CAMERA_RATES) {
            p = get_vec(p, &m->cam_velocity_m_s);
            p = get_vec(p, &m->cam_angular_velocity_rad_s);
        }
        if (flags & NC_MSG_BODY_RATES) {
            p = get_vec(p, &m->body_velocity_m_s);
            p = get_vec(p, &m->body_angular_velocity_rad_s);
        }
    } else if (type == NC_MSG_FRAME) {
        m->frame = nc_le_get_u64(p);
        m->status = nc_le_get_u32(p + 8);
        p += 16;
    }
    if (flags & NC_MSG_EXPOSURE) {
        m->exposure_s = nc_le_get_f64(p);
        p += 8;
    }
    if (flags & NC_MSG_GAIN) {
        m->gain_db = nc_le_get_f64(p);
        p += 8;
    }
    /* Values: all finite, quaternions unit, the rest in physical range. */
    if (!nc_v3_isfinite(m->cam_position_m) || !nc_quat_isfinite(m->cam_attitude_q) || !nc_v3_isfinite(m->sun) ||
        !nc_v3_isfinite(m->body_position_m) || !nc_quat_isfinite(m->body_attitude_q) ||
        !nc_v3_isfinite(m->cam_velocity_m_s) || !nc_v3_isfinite(m->cam_angular_velocity_rad_s) ||
        !nc_v3_isfinite(m->body_velocity_m_s) || !nc_v3_isfinite(m->body_angular_velocity_rad_s) ||
        !isfinite(m->exposure_s) || !isfinite(m->gain_db))
        return NC_REJECT_NOT_FINITE;
    if (!unit_quat(&m->cam_attitude_q) || !unit_quat(&m->body_attitude_q))
        return NC_REJECT_BAD_QUATERNION;
    if (type == NC_MSG_POSE && nc_v3_is_zero(m->sun))
        return NC_REJECT_BAD_VALUE;
    /* (a FRAME echoes its request's time, which may be the value that had it refused) */
    if (type != NC_MSG_FRAME && (m->sim_time_ns < -NC_PROTO_TIME_MAX_NS || m->sim_time_ns > NC_PROTO_TIME_MAX_NS))
        return NC_REJECT_BAD_VALUE;
    if (!(nc_v3_norm(m->cam_position_m) <= NC_PROTO_POSITION_MAX_M) ||
        !(nc_v3_norm(m->body_position_m) <= NC_PROTO_POSITION_MAX_M) ||
        !(nc_v3_norm(m->cam_velocity_m_s) <= NC_PROTO_SPEED_MAX_M_S) ||
        !(nc_v3_norm(m->body_velocity_m_s) <= NC_PROTO_SPEED_MAX_M_S))
        return NC_REJECT_BAD_VALUE;
    const double sun_m = nc_v3_norm(m->sun); /* (a frame took no light from 1e300 m, NaN from 1e-300) */
    if ((flags & NC_MSG_SUN_POSITION) && !(sun_m > NC_PROTO_SUN_RADIUS_M && sun_m <= NC_PROTO_POSITION_MAX_M))
        return NC_REJECT_BAD_VALUE;
    if ((flags & NC_MSG_EXPOSURE) && !(m->exposure_s >= 0 && m->exposure_s <= NC_PROTO_EXPOSURE_MAX_S))
        return NC_REJECT_BAD_VALUE;
    if ((flags & NC_MSG_GAIN) && !(m->gain_db >= -NC_PROTO_GAIN_MAX_DB && m->gain_db <= NC_PROTO_GAIN_MAX_DB))
        return NC_REJECT_BAD_VALUE;
    return NC_REJECT_NONE;
}
