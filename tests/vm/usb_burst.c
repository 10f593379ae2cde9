/* usb_burst.c - a host of the USB trigger protocol (docs/usb-trigger.md)
 * that sends a full OUT packet of TIME_REQs in one transfer, as the doc
 * allows ("a device must accept several per packet"), and waits for every
 * TIME reply. A full packet is ended by no short packet: an adapter that
 * reads more than a packet at a time keeps them until another transfer
 * comes (the reference adapter did, 1.5 s here, until session 65).
 * Usage (in the test guest, no navcam serve holding the adapter):
 *   usb_burst TIMEOUT_S
 * Prints "burst: N requests in one P-byte transfer, N replies in T ms";
 * exit status 0 when every reply came within TIMEOUT_S, 1 if not, 2 on an
 * error. */
#include <libusb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "proto/usb_trigger.h"

/* A bulk IN transfer of up to len bytes within timeout_ms: the bytes that
 * came, also when the call timed out as they came (libusb then reports the
 * timeout with the data in *got). */
static int read_in(libusb_device_handle *h, unsigned char ep, uint8_t *buf, int len, unsigned timeout_ms)
{
    int got = 0;
    const int rc = libusb_bulk_transfer(h, ep, buf, len, &got, timeout_ms);
    return rc == 0 || rc == LIBUSB_ERROR_TIMEOUT ? got : 0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The adapter's interface (class, subclass, protocol) on an open device:
 * its number and bulk endpoints, or -1. */
static int find_interface(libusb_device *dev, int *ifnum, unsigned char *ep_in, unsigned char *ep_out, int *pkt)
{
    struct libusb_config_descriptor *cfg;
    if (libusb_get_active_config_descriptor(dev, &cfg) != 0)
        return -1;
    int found = -1;
    for (int i = 0; i < cfg->bNumInterfaces && found < 0; i++) {
        const struct libusb_interface_descriptor *d = &cfg->interface[i].altsetting[0];
        if (d->bInterfaceClass != NC_UT_CLASS || d->bInterfaceSubClass != NC_UT_SUBCLASS ||
            d->bInterfaceProtocol != NC_UT_PROTOCOL)
            continue;
        for (int e = 0; e < d->bNumEndpoints; e++) {
            const struct libusb_endpoint_descriptor *ep = &d->endpoint[e];
            if ((ep->bmAttributes & 3) != LIBUSB_TRANSFER_TYPE_BULK)
                continue;
            if (ep->bEndpointAddress & LIBUSB_ENDPOINT_IN)
                *ep_in = ep->bEndpointAddress;
            else
                *ep_out = ep->bEndpointAddress, *pkt = ep->wMaxPacketSize & 0x7ff;
        }
        *ifnum = d->bInterfaceNumber;
        found = 0;
    }
    libusb_free_config_descriptor(cfg);
    return found;
}

int main(int argc, char **argv)
{
    const double timeout_s = argc > 1 ? atof(argv[1]) : 0.5;
    libusb_context *ctx;
    if (libusb_init(&ctx) != 0)
        return fprintf(stderr, "usb_burst: libusb_init failed\n"), 2;
    libusb_device **list;
    ssize_t n = libusb_get_device_list(ctx, &list);
    libusb_device_handle *h = NULL;
    int ifnum = -1, pkt = 0;
    unsigned char ep_in = 0, ep_out = 0;
    for (ssize_t i = 0; i < n && !h; i++)
        if (find_interface(list[i], &ifnum, &ep_in, &ep_out, &pkt) == 0 && libusb_open(list[i], &h) != 0)
            h = NULL;
    libusb_free_device_list(list, 1);
    if (!h || libusb_claim_interface(h, ifnum) != 0 || pkt < NC_UT_MSG_BYTES || !ep_in || !ep_out)
        return fprintf(stderr, "usb_burst: no adapter to claim (interface %d, packet %d)\n", ifnum, pkt), 2;
    /* a session, so that nothing queued before is taken for a reply */
    uint8_t msg[NC_UT_MSG_BYTES], in[1024], out[1024];
    nc_ut_encode(msg, &(struct nc_ut_msg){.type = NC_UT_HELLO, .tag = 7});
    int done = 0, got = 0;
    libusb_bulk_transfer(h, ep_out, msg, sizeof msg, &done, 1000);
    const double t_hello = now_s();
    for (int info = 0; !info && now_s() - t_hello < 2;) {
        got = read_in(h, ep_in, in, pkt, 200);
        for (int o = 0; o + NC_UT_MSG_BYTES <= got; o += NC_UT_MSG_BYTES) {
            struct nc_ut_msg m;
            info |= nc_ut_decode(in + o, &m) == 0 && m.type == NC_UT_INFO && m.tag == 7;
        }
    }
    /* one full packet of requests, tags 100.. */
    const int k = pkt / NC_UT_MSG_BYTES < (int)(sizeof out / NC_UT_MSG_BYTES) ? pkt / NC_UT_MSG_BYTES
                                                                                : (int)(sizeof out / NC_UT_MSG_BYTES);
    for (int i = 0; i < k; i++)
        nc_ut_encode(out + NC_UT_MSG_BYTES * i, &(struct nc_ut_msg){.type = NC_UT_TIME_REQ, .tag = 100u + (unsigned)i});
    const double t0 = now_s();
    if (libusb_bulk_transfer(h, ep_out, out, k * NC_UT_MSG_BYTES, &done, 1000) != 0 || done != k * NC_UT_MSG_BYTES)
        return fprintf(stderr, "usb_burst: the OUT transfer failed (%d bytes)\n", done), 2;
    int replies = 0;
    unsigned seen = 0;
    double t_last = t0;
    while (replies < k && now_s() - t0 < timeout_s) {
        got = read_in(h, ep_in, in, pkt, 50);
        for (int o = 0; o + NC_UT_MSG_BYTES <= got; o += NC_UT_MSG_BYTES) {
            struct nc_ut_msg m;
            if (nc_ut_decode(in + o, &m) == 0 && m.type == NC_UT_TIME && m.tag >= 100 && m.tag < 100u + k &&
                !(seen >> (m.tag - 100) & 1u))
                seen |= 1u << (m.tag - 100), replies++, t_last = now_s();
        }
    }
    printf("burst: %d requests in one %d-byte transfer, %d replies in %.1f ms\n", k, k * NC_UT_MSG_BYTES, replies,
           1e3 * (t_last - t0));
    libusb_release_interface(h, ifnum);
    libusb_close(h);
    libusb_exit(ctx);
    return replies == k ? 0 : 1;
}
