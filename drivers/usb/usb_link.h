/* usb_link.h - the USB trigger driver's link to its adapter
 * (drivers/trigger_usb.c): the session with one adapter through libusb -
 * finding and claiming it, the queued transfers, the protocol's messages
 * (proto/usb_trigger.h) and the clock map. Shared by the driver's two
 * files only; callbacks run on the driver's event thread.
 */
#ifndef NC_USB_LINK_H
#define NC_USB_LINK_H

#include <libusb.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "core/clock_map.h"
#include "emulator/trigger.h"
#include "proto/usb_trigger.h"

#define NC__USB_N_IN 8          /* IN transfers kept queued */
#define NC__USB_MAX_PACKET 1024 /* the largest bulk packet (SuperSpeed) */
#define NC__USB_N_REQ 16        /* clock exchanges in flight */
#define NC__USB_N_UNSYNCED 256  /* edges held until the first clock exchange */
#define NC__USB_BURST 8         /* exchanges 20 ms apart when a session starts */
#define NC__USB_N_ARRIVED 8     /* devices plugged in, waiting to be looked at */

enum nc__usb_state { NC__USB_ABSENT, NC__USB_HELLO_SENT, NC__USB_READY };

struct nc__usb_trig {
    struct nc_trigger_ctx ctx;
    int vid, pid, input, strobe_out;
    char serial[128]; /* "": any */
    int64_t sync_ns;
    libusb_context *usb;
    libusb_hotplug_callback_handle hotplug;
    int have_hotplug;
    pthread_t thread;
    int running;
    atomic_int stop, started;
    pthread_mutex_t lock; /* everything below; control() comes from other threads */
    enum nc__usb_state state;
    libusb_device_handle *h;
    libusb_device *dev; /* the open adapter */
    libusb_device *arrived[NC__USB_N_ARRIVED]; /* plugged in since the loop last looked (oldest first) */
    int narrived;
    int session_error;    /* the status of a transfer that ended the session (0: none, or NO_DEVICE) */
    int verdict;          /* a closed session's session_error, until known to be an unplug or not */
    libusb_device *retry; /* that adapter, opened again at retry_at_ns (unless it leaves first) */
    int64_t retry_at_ns, retry_wait_ns, session_start_ns;
    unsigned long retry_failures; /* attempts since the last session that did not open it */
    int iface, gone, inflight, maxpkt;
    uint8_t ep_in, ep_out;
    struct libusb_transfer *in[NC__USB_N_IN];
    char desc[96];
    uint32_t tag, hello_tag, next_seq;
    struct { uint32_t tag; int64_t t1; } req[NC__USB_N_REQ];
    unsigned nreq; /* exchanges sent; wraps (16 divides 2^32: the slots go on in turn) */
    int burst;
    int64_t next_sync_ns, unplugged_at_ns;
    uint64_t dither;
    struct nc_clock_map map;
    int64_t unsynced[NC__USB_N_UNSYNCED];
    uint8_t unsynced_level[NC__USB_N_UNSYNCED];
    int nunsynced;
    struct nc_trigger_edge fire[NC__USB_N_UNSYNCED + NC__USB_MAX_PACKET / NC_UT_MSG_BYTES]; /* event thread only */
    int nfire;
    unsigned long messages, edges, lost, missed, level_repeats, other_line, unknown, unplugged, session_errors,
        reopened, strobes, strobes_skipped;
    double edge_bound_max_ns;
};

/* The whole messages of buf[0 .. len) from the adapter: counted, edges
 * queued in fire[] (nfire), clock replies added. A message of a type this
 * host does not know is counted as unknown and skipped, its sequence
 * number taken (not a gap). Lock held. */
void nc__usb_receive(struct nc__usb_trig *u, const uint8_t *buf, int len, int64_t now);

/* Queue one message to the adapter. Lock held. */
int nc__usb_send_msg(struct nc__usb_trig *u, const struct nc_ut_msg *m);
/* The next request tag (HELLO, TIME_REQ): the last plus one, never 0. Lock held. */
uint32_t nc__usb_next_tag(struct nc__usb_trig *u);
/* Send a clock exchange's request. Lock held. */
void nc__usb_send_time_req(struct nc__usb_trig *u);
/* Open dev if it is the adapter asked for and start a session (HELLO
 * sent): 1 opened, 0 not it, -ENODEV gone (unplugged), < 0 another error
 * (nc_errmsg). Event thread. */
int nc__usb_try_open(struct nc__usb_trig *u, libusb_device *dev);
/* End the session: wait for every transfer, release the adapter. Event thread. */
void nc__usb_close_session(struct nc__usb_trig *u);

#endif
