/* test_usb_link.c - what NavCam makes of the adapter's messages
 * (drivers/usb/usb_link.h, docs/usb-trigger.md): a message of a type this
 * host does not know is skipped and counted as unknown, and its sequence
 * number is taken like any other's, so it is not a gap (lost); a real gap
 * is. The USB path itself is tested against the kernel's gadget drivers in
 * tests/vm. */
#include <string.h>

#include "drivers/usb/usb_link.h"
#include "testutil.h"

static void put(uint8_t *buf, int type, uint32_t seq)
{
    struct nc_ut_msg m = {.type = (uint8_t)type, .line = 0, .level = seq & 1, .seq = seq, .t0_ns = 1000 + seq};
    nc_ut_encode(buf, &m);
}

int main(void)
{
    static struct nc__usb_trig u;
    u.state = NC__USB_READY;
    u.next_seq = 10;
    uint8_t buf[4 * NC_UT_MSG_BYTES];
    put(buf, NC_UT_EDGE, 10);
    put(buf + NC_UT_MSG_BYTES, 0x04, 11); /* a type a later adapter may send */
    put(buf + 2 * NC_UT_MSG_BYTES, NC_UT_EDGE, 12);
    nc__usb_receive(&u, buf, 3 * NC_UT_MSG_BYTES, 0);
    CHECK(u.messages == 3 && u.edges == 2 && u.unknown == 1 && u.lost == 0,
          "EDGE, an unknown type, EDGE in sequence: messages %lu, edges %lu, unknown %lu, lost %lu (want 3, 2, 1, 0)",
          u.messages, u.edges, u.unknown, u.lost);
    put(buf, NC_UT_EDGE, 15); /* 13 and 14 never arrived */
    nc__usb_receive(&u, buf, NC_UT_MSG_BYTES, 0);
    CHECK(u.edges == 3 && u.lost == 2, "a gap of two: edges %lu, lost %lu (want 3, 2)", u.edges, u.lost);
    CHECK(u.nunsynced == 3, "edges before the first clock exchange are held: %d (want 3)", u.nunsynced);
    return nc_test_end();
}
