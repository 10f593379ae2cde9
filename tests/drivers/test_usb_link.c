/* test_usb_link.c - what NavCam makes of the adapter's messages
 * (drivers/usb/usb_link.h, docs/usb-trigger.md): a message of a type this
 * host does not know is skipped and counted as unknown, and its sequence
 * number is taken like any other's, so it is not a gap (lost); a real gap
 * is. A request whose OUT transfer ends on a stall ends the session (the
 * adapter is opened again, its halts cleared), and a STROBE counts as sent
 * only once its transfer is done. The USB path itself is tested against the
 * kernel's gadget drivers in tests/vm. */
#include <string.h>

#include "drivers/usb/usb_link.h"
#include "testutil.h"

/* libusb's submission, taken here (the executable's symbol comes first):
 * the transfer is kept, and ended by the test as libusb would end it. */
static struct libusb_transfer *submitted;
int libusb_submit_transfer(struct libusb_transfer *t)
{
    submitted = t;
    return 0;
}

static void end_transfer(enum libusb_transfer_status status)
{
    submitted->status = status;
    submitted->callback(submitted);
    libusb_free_transfer(submitted); /* libusb would, by its flags */
}

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

    static struct nc__usb_trig o;
    pthread_mutex_init(&o.lock, NULL);
    o.state = NC__USB_READY, o.ep_out = 0x02;
    const struct nc_ut_msg strobe = {.type = NC_UT_STROBE, .t0_ns = 1000, .t1_ns = 2000};
    CHECK(nc__usb_send_msg(&o, &strobe) == 0, "send");
    end_transfer(LIBUSB_TRANSFER_COMPLETED);
    CHECK(o.strobes == 1 && o.strobes_skipped == 0 && !o.gone, "a STROBE delivered: strobes %lu, skipped %lu, gone %d",
          o.strobes, o.strobes_skipped, o.gone);
    CHECK(nc__usb_send_msg(&o, &strobe) == 0, "send");
    end_transfer(LIBUSB_TRANSFER_TIMED_OUT);
    CHECK(o.strobes == 1 && o.strobes_skipped == 1 && !o.gone, "a STROBE timed out: strobes %lu, skipped %lu, gone %d",
          o.strobes, o.strobes_skipped, o.gone);
    CHECK(nc__usb_send_msg(&o, &strobe) == 0, "send");
    end_transfer(LIBUSB_TRANSFER_STALL);
    CHECK(o.strobes == 1 && o.strobes_skipped == 2 && o.gone && o.session_error == LIBUSB_TRANSFER_STALL,
          "a STROBE stalled: strobes %lu, skipped %lu, gone %d, session error %d (want 1, 2, 1, stall)", o.strobes,
          o.strobes_skipped, o.gone, o.session_error);
    CHECK(o.inflight == 0, "transfers in flight: %d", o.inflight);
    o.tag = UINT32_MAX; /* tags start at random: the wrap skips 0, which no reply matches */
    CHECK(nc__usb_next_tag(&o) == 1, "the tag after 2^32 - 1: %u", o.tag);
    pthread_mutex_destroy(&o.lock);
    return nc_test_end();
}
