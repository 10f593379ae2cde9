/* test_usb_trigger.c - the USB trigger adapter's messages (proto/usb_trigger.h)
 * against the byte layout docs/usb-trigger.md specifies: a check written
 * from that table must read what NavCam writes. */
#include <stdint.h>
#include <string.h>

#include "proto/usb_trigger.h"
#include "testutil.h"

int main(void)
{
    struct nc_ut_msg m = {.type = NC_UT_EDGE, .line = 3, .level = 1, .flags = NC_UT_EDGE_AFTER_MISSED,
                          .seq = 0x04030201u, .tag = 0xa1b2c3d4u, .arg = 7, .t0_ns = 1000500000000123ll,
                          .t1_ns = -2};
    uint8_t b[NC_UT_MSG_BYTES];
    memset(b, 0xee, sizeof b);
    nc_ut_encode(b, &m);
    /* The table: type, line, level, flags, seq u32, tag u32, arg u32, t0 i64, t1 i64, little-endian. */
    const uint8_t want[NC_UT_MSG_BYTES] = {0x01, 3, 1, 0x01, 0x01, 0x02, 0x03, 0x04, 0xd4, 0xc3, 0xb2, 0xa1,
                                           7, 0, 0, 0, 0x7b, 0x08, 0x19, 0x0f, 0xf3, 0x8d, 0x03, 0x00,
                                           0xfe, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
    CHECK(!memcmp(b, want, sizeof b), "EDGE bytes differ from the documented layout");
    struct nc_ut_msg back;
    CHECK(nc_ut_decode(b, &back) == 0 && !memcmp(&back, &m, sizeof m), "round trip");
    /* Every documented type decodes; others are reported for skipping. */
    const int types[] = {NC_UT_EDGE, NC_UT_TIME, NC_UT_INFO, NC_UT_HELLO, NC_UT_TIME_REQ, NC_UT_STROBE};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++) {
        b[0] = (uint8_t)types[i];
        CHECK(nc_ut_decode(b, &back) == 0 && back.type == types[i], "type 0x%02x", types[i]);
    }
    b[0] = 0x7f;
    CHECK(nc_ut_decode(b, &back) == -1, "an unknown type is reported");
    return nc_test_end();
}
