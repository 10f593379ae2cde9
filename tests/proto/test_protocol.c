/* test_protocol.c - pose protocol v1: round trips with every optional block,
 * the documented example bytes, and every rejection reason provoked on
 * purpose. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <zlib.h>

#include "core/le.h"
#include "navcam/protocol.h"
#include "testutil.h"

static struct nc_pose_msg sample(uint32_t flags)
{
    struct nc_pose_msg m = {.type = NC_MSG_POSE, .sequence = 77, .flags = flags, .sim_time_ns = 123456789012LL};
    m.cam_position_m = nc_v3(1000.5, -2000.25, 3e7);
    m.cam_attitude_q = (struct nc_quat){0.5, 0.5, -0.5, 0.5};
    /* 1.5e11 m, or a direction */
    m.sun = flags & NC_MSG_SUN_POSITION ? nc_v3(0.9e11, 0.0, -1.2e11) : nc_v3(0.6, 0.0, -0.8);
    m.body_position_m = nc_v3(1, 2, 3);
    m.body_attitude_q = (struct nc_quat){1, 0, 0, 0};
    m.cam_velocity_m_s = nc_v3(0.1, 0.2, 0.3);
    m.cam_angular_velocity_rad_s = nc_v3(-0.01, 0.02, 0.03);
    m.body_velocity_m_s = nc_v3(4, 5, 6);
    m.body_angular_velocity_rad_s = nc_v3(0, 0, 1e-4);
    m.exposure_s = 0.0125;
    m.gain_db = 6.0;
    return m;
}

/* Re-seal a modified message with a correct CRC. */
static void reseal(uint8_t *buf, size_t len)
{
    uint32_t c = (uint32_t)crc32(0L, buf, (uInt)(len - 4));
    for (int i = 0; i < 4; i++)
        buf[len - 4 + i] = (uint8_t)(c >> (8 * i));
}

static void put_f64(uint8_t *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(u >> (8 * i));
}

int main(void)
{
    uint8_t buf[NC_PROTO_MAX_BYTES + 16];
    struct nc_pose_msg out;
    /* Round trips over every flag combination. */
    int bad = 0;
    for (uint32_t f = 0; f <= NC_MSG_KNOWN_FLAGS; f++) {
        struct nc_pose_msg m = sample(f);
        size_t n = nc_msg_encode(&m, buf, sizeof buf);
        enum nc_reject r = nc_msg_decode(buf, n, &out);
        bad += n != nc_msg_size(NC_MSG_POSE, f) || r != NC_REJECT_NONE || out.sequence != 77 ||
               out.sim_time_ns != m.sim_time_ns || out.cam_position_m.z != 3e7 || out.cam_attitude_q.y != -0.5 ||
               ((f & NC_MSG_EXPOSURE) && out.exposure_s != 0.0125) || ((f & NC_MSG_BODY_RATES) && out.body_velocity_m_s.y != 5);
    }
    CHECK(bad == 0, "%d flag combinations do not round-trip", bad);
    struct nc_pose_msg trig = {.type = NC_MSG_TRIGGER, .sequence = 9, .flags = NC_MSG_CAPTURE | NC_MSG_EXPOSURE,
                               .sim_time_ns = 5, .exposure_s = 0.001};
    size_t tn = nc_msg_encode(&trig, buf, sizeof buf);
    CHECK(tn == 44 && nc_msg_decode(buf, tn, &out) == NC_REJECT_NONE && out.type == NC_MSG_TRIGGER &&
              out.exposure_s == 0.001,
          "trigger message (%zu bytes)", tn);

    /* A pose's block flags on a trigger: the length agrees with them (the
     * trigger has no blocks) but they cannot mean anything. */
    buf[16] |= NC_MSG_BODY_POSE;
    reseal(buf, tn);
    CHECK(nc_msg_decode(buf, tn, &out) == NC_REJECT_BAD_FLAGS, "a trigger flagged BODY_POSE is rejected");
    /* ... and not encoded: what the decoder refuses is never sent */
    struct nc_pose_msg sun_trig = trig;
    sun_trig.flags |= NC_MSG_SUN_POSITION;
    CHECK(nc_msg_encode(&sun_trig, buf, sizeof buf) == 0, "a trigger flagged SUN_POSITION was encoded");
    struct nc_pose_msg odd = trig;
    for (int t = 0; t <= 8; t += t == 0 ? 4 : 1) { /* 0 and 4..8: no such type (the decoder: bad_type) */
        odd.type = (enum nc_msg_type)t;
        CHECK(nc_msg_encode(&odd, buf, sizeof buf) == 0, "a message of type %d was encoded", t);
    }

    /* The minimal pose message of docs/protocol.md, byte for byte. */
    struct nc_pose_msg ex = {.type = NC_MSG_POSE, .sequence = 1, .flags = NC_MSG_CAPTURE, .sim_time_ns = 1000000000};
    ex.cam_position_m = nc_v3(0, -6000, 0);
    ex.cam_attitude_q = (struct nc_quat){1, 0, 0, 0};
    ex.sun = nc_v3(1, 0, 0);
    size_t en = nc_msg_encode(&ex, buf, sizeof buf);
    CHECK(en == 116, "minimal pose message is %zu bytes, want 116", en);
    char hex[300] = "";
    for (int i = 0; i < 24; i++)
        sprintf(hex + 2 * i, "%02x", buf[i]);
    CHECK(!strcmp(hex, "4e43414d0100010074000000010000001000000000000000"), "header bytes %s", hex);
    printf("example message: %zu bytes, header %s, crc %02x%02x%02x%02x\n", en, hex, buf[en - 4], buf[en - 3],
           buf[en - 2], buf[en - 1]);

    /* Every rejection reason, on purpose. */
    struct nc_pose_msg m = sample(NC_MSG_BODY_POSE | NC_MSG_CAPTURE | NC_MSG_EXPOSURE);
    size_t n = nc_msg_encode(&m, buf, sizeof buf);
    uint8_t t[sizeof buf];
#define EXPECT(reason, len, ...)                                                                               \
    do {                                                                                                       \
        memcpy(t, buf, n);                                                                                     \
        __VA_ARGS__;                                                                                           \
        enum nc_reject got = nc_msg_decode(t, (len), &out);                                                    \
        CHECK(got == NC_REJECT_##reason, "%s: got '%s'", #reason, nc_reject_name(got));                       \
        printf("rejected as expected: %s\n", nc_reject_name(got));                                             \
    } while (0)
    EXPECT(TRUNCATED, 10);
    EXPECT(TRUNCATED, n - 1);
    EXPECT(OVERSIZED, NC_PROTO_MAX_BYTES + 1);
    EXPECT(BAD_MAGIC, n, t[0] ^= 1);
    EXPECT(BAD_VERSION, n, t[4] = 2, reseal(t, n));
    EXPECT(BAD_TYPE, n, t[6] = 9, reseal(t, n));
    EXPECT(BAD_LENGTH, n, t[8] += 8, reseal(t, n));
    EXPECT(BAD_LENGTH, n + 8, memset(t + n, 0, 8));
    EXPECT(BAD_FLAGS, n, t[18] = 0x40, reseal(t, n));
    EXPECT(BAD_FLAGS, n, t[20] = 0x12, reseal(t, n)); /* flags written into the reserved word */
    EXPECT(BAD_CRC, n, t[40] ^= 0x10);
    EXPECT(NOT_FINITE, n, put_f64(t + 32, NAN), reseal(t, n));
    EXPECT(NOT_FINITE, n, put_f64(t + 88, INFINITY), reseal(t, n));
    EXPECT(BAD_QUATERNION, n, put_f64(t + 56, 0.9), reseal(t, n));
    EXPECT(BAD_VALUE, n, memset(t + 88, 0, 24), reseal(t, n)); /* a zero Sun vector */
    EXPECT(BAD_VALUE, n, put_f64(t + n - 12, -1.0), reseal(t, n)); /* negative exposure */
    /* Times within +-4.6e18 ns (a time plus an exposure, and two times'
     * difference, fit 64 bits), positions within 1e15 m, speeds up to c. */
    EXPECT(BAD_VALUE, n, nc_le_put_u64(t + 24, (uint64_t)INT64_MAX - 1000000), reseal(t, n));
    EXPECT(BAD_VALUE, n, nc_le_put_u64(t + 24, (uint64_t)(-NC_PROTO_TIME_MAX_NS - 1)), reseal(t, n));
    EXPECT(NONE, n, nc_le_put_u64(t + 24, (uint64_t)-NC_PROTO_TIME_MAX_NS), reseal(t, n));
    EXPECT(NONE, n, nc_le_put_u64(t + 24, (uint64_t)NC_PROTO_TIME_MAX_NS), reseal(t, n));
    { /* but a FRAME echoes its request's time: the answer to a capture refused for it is one (the client library
       * dropped it, and the capture was never answered) */
        struct nc_pose_msg f = {.type = NC_MSG_FRAME, .sequence = 7, .sim_time_ns = NC_PROTO_TIME_MAX_NS + 1,
                                .frame = UINT64_MAX, .status = NC_FRAME_DROPPED},
                           g;
        uint8_t fb[NC_PROTO_MAX_BYTES];
        const size_t fn = nc_msg_encode(&f, fb, sizeof fb);
        CHECK(fn > 0 && nc_msg_decode(fb, fn, &g) == NC_REJECT_NONE && g.sequence == 7 &&
                  g.sim_time_ns == f.sim_time_ns && g.status == NC_FRAME_DROPPED,
              "a FRAME with its request's time out of range: %s", nc_reject_name(nc_msg_decode(fb, fn, &g)));
    }
    EXPECT(BAD_VALUE, n, put_f64(t + 32, 2e15), reseal(t, n));   /* the camera 2e15 m out */
    EXPECT(BAD_VALUE, n, put_f64(t + 120, 1e300), reseal(t, n)); /* the body 1e300 m out */
    { /* a Sun position: beyond the Sun's radius of bodies[0]'s origin, within 1e15 m */
        const double r[] = {1e-300, 4e8, 1.5e11, 1e16, 1e300};
        for (int k = 0; k < 5; k++) {
            struct nc_pose_msg v = sample(NC_MSG_SUN_POSITION);
            v.sun = nc_v3(r[k], -r[k], 0);
            size_t vn = nc_msg_encode(&v, t, sizeof t);
            CHECK(vn && nc_msg_decode(t, vn, &out) == (k == 2 ? NC_REJECT_NONE : NC_REJECT_BAD_VALUE),
                  "a Sun position of [%g, %g, 0] m %s", r[k], -r[k], k == 2 ? "refused" : "accepted");
        }
    }
    for (int who = 0; who < 2; who++) {
        struct nc_pose_msg v = sample(NC_MSG_CAMERA_RATES | NC_MSG_BODY_RATES);
        *(who ? &v.body_velocity_m_s : &v.cam_velocity_m_s) = nc_v3(0, 3e8, 0);
        size_t vn = nc_msg_encode(&v, t, sizeof t);
        CHECK(vn && nc_msg_decode(t, vn, &out) == NC_REJECT_BAD_VALUE, "a %s faster than light accepted",
              who ? "body" : "camera");
    }
    /* Nearly unit quaternions are accepted and normalised. */
    memcpy(t, buf, n);
    put_f64(t + 56, 0.5 * (1 + 5e-7));
    reseal(t, n);
    CHECK(nc_msg_decode(t, n, &out) == NC_REJECT_NONE && fabs(nc_quat_norm(out.cam_attitude_q) - 1) < 1e-15,
          "a quaternion within tolerance is accepted and normalised");
    CHECK(!strcmp(nc_reject_name(NC_REJECT_TIME_BACKWARDS), "simulation time went backwards"), "reason names");
    CHECK(!strcmp(nc_reject_key(NC_REJECT_BAD_VALUE), "out_of_range") && !strcmp(nc_reject_key(NC_REJECT_NONE), "accepted"),
          "reason keys");
    for (int r = NC_REJECT_NONE + 1; r < NC_REJECT_COUNT; r++) { /* keys are identifiers: lower case, digits, '_' */
        const char *k = nc_reject_key((enum nc_reject)r);
        CHECK(k[0] && strspn(k, "abcdefghijklmnopqrstuvwxyz0123456789_") == strlen(k), "key '%s'", k);
    }
    return nc_test_end();
}
