/* protocol.h - the NavCam pose protocol, version 1 (docs/protocol.md): the
 * binary messages a dynamics simulator sends. Little-endian, fixed header,
 * optional blocks selected by flags, CRC-32 trailer. UDP carries one message
 * per datagram; TCP prefixes each message with its length (u32).
 *
 * This module only encodes and decodes; it keeps no state and does no I/O.
 * Decoding never trusts the input: every way a message can be wrong has its
 * own reason code, so that the emulator can count and log rejections.
 */
#ifndef NC_PROTOCOL_H
#define NC_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#include "navcam/types.h"

#ifdef __cplusplus
extern "C" { /* C linkage, for simulators written in C++ */
#endif

#define NC_PROTO_MAGIC 0x4D41434Eu /* bytes "NCAM" */
#define NC_PROTO_VERSION 1
#define NC_PROTO_HEADER_BYTES 24
#define NC_PROTO_MAX_BYTES 1024 /* any valid message is smaller */
#define NC_PROTO_QUAT_TOL 1e-6  /* | |q| - 1 | allowed, then normalised */
#define NC_PROTO_EXPOSURE_MAX_S 3600.0 /* EXPOSURE: 0 to this */
#define NC_PROTO_GAIN_MAX_DB 60.0      /* GAIN: -this to this */
/* sim_time_ns: -this to this (about 146 years either side of the
 * simulation's epoch; a Unix time in ns fits until 2115), so that a time
 * plus an exposure, and the difference of two times, fit in 64 bits. */
#define NC_PROTO_TIME_MAX_NS 4600000000000000000LL
#define NC_PROTO_POSITION_MAX_M 1e15 /* camera and body positions: |p| up to this (6700 au) */
#define NC_PROTO_SUN_RADIUS_M 6.957e8 /* a Sun position (SUN_POSITION): farther than this, and no farther than
                                       * NC_PROTO_POSITION_MAX_M, from bodies[0]'s origin */
#define NC_PROTO_SPEED_MAX_M_S 299792458.0 /* camera and body velocities: |v| up to the speed of light */

/* POSE and TRIGGER: simulator -> NavCam. FRAME: NavCam -> simulator over
 * TCP, one per captured request, once the frame is with every output. */
enum nc_msg_type { NC_MSG_POSE = 1, NC_MSG_TRIGGER = 2, NC_MSG_FRAME = 3 };
/* FRAME status. REFUSED answers no request (sequence 0): NavCam sends it on
 * a TCP connection it will not serve (all serve.max_clients slots in use;
 * the frame field holds that limit) and closes the connection. */
enum nc_frame_status { NC_FRAME_DELIVERED = 0, NC_FRAME_DROPPED = 1, NC_FRAME_REFUSED = 2 };

enum nc_msg_flags {
    NC_MSG_SUN_POSITION = 1u << 0, /* sun vector is a position (m), else a direction */
    NC_MSG_BODY_POSE = 1u << 1,    /* body position and attitude follow */
    NC_MSG_CAMERA_RATES = 1u << 2, /* camera velocity (m/s, scene) and angular velocity (rad/s, camera) */
    NC_MSG_BODY_RATES = 1u << 3,   /* body velocity (m/s, scene) and angular velocity (rad/s, body) */
    NC_MSG_CAPTURE = 1u << 4,      /* capture a frame with this pose (lock-step, software trigger) */
    NC_MSG_EXPOSURE = 1u << 5,     /* exposure time (s) for the requested frame */
    NC_MSG_GAIN = 1u << 6,         /* analog gain (dB) for the requested frame */
};
#define NC_MSG_KNOWN_FLAGS 0x7Fu
/* The flags of a POSE's blocks, which no other type takes. */
#define NC_MSG_POSE_ONLY_FLAGS 0x0Fu

/* Why a message was rejected: one counter each in the emulator. Each reason has a key (the name of its
 * counter in the emulator's statistics JSON) and a phrase (its log lines). */
#define NC_REJECT_REASONS(X)                                                                                   \
    X(TRUNCATED, "truncated", "truncated")                                                                     \
    X(OVERSIZED, "oversized", "oversized")                                                                     \
    X(BAD_MAGIC, "bad_magic", "bad magic")                                                                     \
    X(BAD_VERSION, "bad_version", "unsupported version")                                                       \
    X(BAD_TYPE, "bad_type", "unknown message type")                                                            \
    X(BAD_LENGTH, "bad_length", "length field disagrees with the message")                                     \
    X(BAD_FLAGS, "bad_flags", "unknown flags")                                                                 \
    X(BAD_CRC, "bad_crc", "bad CRC")                                                                           \
    X(NOT_FINITE, "not_finite", "NaN or infinite value")                                                       \
    X(BAD_QUATERNION, "bad_quaternion", "quaternion not of unit length")                                       \
    X(BAD_VALUE, "out_of_range", "value out of range")                                                         \
    X(TIME_BACKWARDS, "time_backwards", "simulation time went backwards")

enum nc_reject {
    NC_REJECT_NONE = 0,
#define NC__XREJ(name, key, text) NC_REJECT_##name,
    NC_REJECT_REASONS(NC__XREJ)
#undef NC__XREJ
        NC_REJECT_COUNT
};

/* The phrase ("quaternion not of unit length"); "accepted" for NC_REJECT_NONE. */
const char *nc_reject_name(enum nc_reject r);
/* The key ("bad_quaternion"), as in the statistics JSON's "rejected" object; "accepted" for NC_REJECT_NONE. */
const char *nc_reject_key(enum nc_reject r);

struct nc_pose_msg {
    enum nc_msg_type type;
    uint32_t sequence;
    uint32_t flags;
    int64_t sim_time_ns;
    struct nc_vec3 cam_position_m;    /* scene frame */
    struct nc_quat cam_attitude_q;    /* camera -> scene */
    struct nc_vec3 sun;               /* body-fixed frame of bodies[0]: direction, or position (m) */
    struct nc_vec3 body_position_m;   /* bodies[0], scene frame */
    struct nc_quat body_attitude_q;   /* bodies[0], body -> scene */
    struct nc_vec3 cam_velocity_m_s, cam_angular_velocity_rad_s;
    struct nc_vec3 body_velocity_m_s, body_angular_velocity_rad_s;
    double exposure_s;
    double gain_db;
    uint64_t frame;    /* FRAME: frame number */
    uint32_t status;   /* FRAME: enum nc_frame_status */
};

/* Bytes of an encoded message with these flags. */
size_t nc_msg_size(enum nc_msg_type type, uint32_t flags);
/* Encode into buf (cap bytes); returns the size, or 0 if cap is too small
 * or the flags are not the type's (unknown bits; a pose's block flags on a
 * TRIGGER or FRAME): what the decoder would refuse is not encoded. */
size_t nc_msg_encode(const struct nc_pose_msg *m, uint8_t *buf, size_t cap);
/* Decode and validate one message of exactly len bytes. Returns
 * NC_REJECT_NONE and fills *m, or the reason of the rejection. */
enum nc_reject nc_msg_decode(const uint8_t *buf, size_t len, struct nc_pose_msg *m);

#ifdef __cplusplus
}
#endif

#endif
