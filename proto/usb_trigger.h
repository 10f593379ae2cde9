/* usb_trigger.h - the wire protocol of NavCam's USB trigger adapter
 * (docs/usb-trigger.md is its specification): the USB identity of the
 * adapter's interface and the 32-byte messages on its two bulk endpoints.
 * Shared by the host driver (drivers/trigger_usb.c) and the reference
 * adapter (adapters/usb-trigger); encoding only, no I/O.
 */
#ifndef NC_USB_TRIGGER_H
#define NC_USB_TRIGGER_H

#include <stdint.h>

#define NC_UT_VERSION 1
/* The reference adapter's default IDs: pid.codes' test VID:PID. Hosts
 * find adapters by their interface (class, subclass, protocol below), so
 * a build with other IDs is found just the same. */
#define NC_UT_VID 0x1209
#define NC_UT_PID 0x0001
#define NC_UT_CLASS 0xff    /* vendor specific */
#define NC_UT_SUBCLASS 0x4e /* 'N' */
#define NC_UT_PROTOCOL 0x54 /* 'T' */
#define NC_UT_INTERFACE_NAME "NavCam trigger adapter"

#define NC_UT_MSG_BYTES 32
/* Lines an adapter may have, inputs and outputs each. */
#define NC_UT_MAX_LINES 8

enum nc_ut_type {
    /* device to host (bulk IN) */
    NC_UT_EDGE = 0x01, /* an input changed level */
    NC_UT_TIME = 0x02, /* reply to TIME_REQ */
    NC_UT_INFO = 0x03, /* reply to HELLO */
    /* host to device (bulk OUT) */
    NC_UT_HELLO = 0x81,    /* start a session: the device drops what it queued and replies INFO */
    NC_UT_TIME_REQ = 0x82, /* a clock exchange */
    NC_UT_STROBE = 0x83,   /* drive an output active over [t0, t1] (device clock) */
};

/* EDGE flags */
#define NC_UT_EDGE_AFTER_MISSED 0x01 /* the adapter dropped edges of this line just before this one (arg: how many) */
#define NC_UT_EDGE_LEVEL_REPEAT 0x02 /* this edge goes to the level its line already had: edges came faster than
                                      * the adapter could tell them apart, so its level may be wrong */

/* One message; which fields mean what depends on the type (the table in
 * docs/usb-trigger.md). Device-to-host messages carry seq, which goes up by
 * one for every message the device makes, so the host counts the lost ones
 * from the gaps. */
struct nc_ut_msg {
    uint8_t type;
    uint8_t line;  /* EDGE, STROBE: the line; INFO: number of inputs */
    uint8_t level; /* EDGE: the new level (1 high, 0 low); INFO: number of outputs */
    uint8_t flags;
    uint32_t seq;
    uint32_t tag; /* a request's tag, echoed by its reply */
    uint32_t arg; /* EDGE: edges of this line missed just before it; INFO: protocol version */
    int64_t t0_ns, t1_ns;
};

void nc_ut_encode(uint8_t out[NC_UT_MSG_BYTES], const struct nc_ut_msg *m);
/* 0, or -1 for a message of an unknown type (which the receiver skips). */
int nc_ut_decode(const uint8_t in[NC_UT_MSG_BYTES], struct nc_ut_msg *m);

#endif
