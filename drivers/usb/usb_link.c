/* usb_link.c - the USB trigger driver's session with its adapter
 * (usb_link.h): transfers, messages, clock exchanges. Must not know the
 * emulator beyond the trigger context it fires edges into.
 */
#include "drivers/usb/usb_link.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"

#define LOG "trigger/usb"

/* ---- sending (any thread, lock held) ------------------------------------- */

static void LIBUSB_CALL out_done(struct libusb_transfer *t)
{
    struct nc__usb_trig *u = t->user_data;
    const int strobe = t->buffer[0] == NC_UT_STROBE; /* nc_ut_encode: the type first */
    pthread_mutex_lock(&u->lock);
    u->inflight--;
    if (strobe && t->status == LIBUSB_TRANSFER_COMPLETED)
        u->strobes++;
    else if (strobe)
        u->strobes_skipped++;
    if (t->status == LIBUSB_TRANSFER_NO_DEVICE) {
        u->gone = 1;
    } else if (t->status == LIBUSB_TRANSFER_TIMED_OUT) {
        nc_log_warn(LOG, "adapter %s: sending a request: %s", u->desc, libusb_error_name(t->status));
    } else if (t->status != LIBUSB_TRANSFER_COMPLETED && t->status != LIBUSB_TRANSFER_CANCELLED) {
        /* a stall, an I/O error: every request after it would fail as well (the clock map going stale), so the
         * session ends as on the IN side, and the adapter is opened again with its halts cleared */
        if (!u->gone)
            u->session_error = (int)t->status;
        u->gone = 1;
    }
    pthread_mutex_unlock(&u->lock);
}

int nc__usb_send_msg(struct nc__usb_trig *u, const struct nc_ut_msg *m)
{
    struct libusb_transfer *t = libusb_alloc_transfer(0);
    uint8_t *buf = malloc(NC_UT_MSG_BYTES);
    if (!t || !buf) {
        free(buf), libusb_free_transfer(t);
        return -ENOMEM;
    }
    nc_ut_encode(buf, m);
    libusb_fill_bulk_transfer(t, u->h, u->ep_out, buf, NC_UT_MSG_BYTES, out_done, u, 1000);
    t->flags = LIBUSB_TRANSFER_FREE_BUFFER | LIBUSB_TRANSFER_FREE_TRANSFER;
    int rc = libusb_submit_transfer(t);
    if (rc < 0) {
        libusb_free_transfer(t);
        if (rc == LIBUSB_ERROR_NO_DEVICE)
            u->gone = 1;
        return rc;
    }
    u->inflight++;
    return 0;
}

uint32_t nc__usb_next_tag(struct nc__usb_trig *u)
{
    if (!++u->tag) /* 0 is no request's (a reply of tag 0 matches none) */
        ++u->tag;
    return u->tag;
}

void nc__usb_send_time_req(struct nc__usb_trig *u)
{
    struct nc_ut_msg m = {.type = NC_UT_TIME_REQ, .tag = nc__usb_next_tag(u)};
    const unsigned k = u->nreq++ % NC__USB_N_REQ;
    u->req[k].tag = m.tag;
    u->req[k].t1 = nc_mono_ns();
    if (nc__usb_send_msg(u, &m) < 0)
        u->req[k].tag = 0;
}

/* ---- receiving (event thread) -------------------------------------------- */

static void queue_edge(struct nc__usb_trig *u, int64_t dev_ns, int level)
{
    int64_t host;
    if (nc_clock_map_to_host(&u->map, dev_ns, &host) < 0) {
        if (u->nunsynced == NC__USB_N_UNSYNCED) {
            u->lost++;
            return;
        }
        u->unsynced[u->nunsynced] = dev_ns;
        u->unsynced_level[u->nunsynced++] = (uint8_t)level;
        return;
    }
    double b = nc_clock_map_bound_ns(&u->map, dev_ns);
    u->edge_bound_max_ns = b > u->edge_bound_max_ns ? b : u->edge_bound_max_ns;
    u->fire[u->nfire++] = (struct nc_trigger_edge){.mono_ns = host, .rising = level};
}

static void on_message(struct nc__usb_trig *u, const struct nc_ut_msg *m, int64_t now)
{
    if (u->state == NC__USB_HELLO_SENT) { /* what the adapter queued before our HELLO is not ours */
        if (m->type != NC_UT_INFO || m->tag != u->hello_tag)
            return;
        u->next_seq = m->seq + 1;
        u->state = NC__USB_READY;
        nc_log_info(LOG, "adapter %s: protocol %u, %d inputs, %d outputs; trigger on input %d%s", u->desc, m->arg,
                    m->line, m->level, u->input, u->strobe_out >= 0 ? ", strobe on an output" : "");
        if (m->arg != NC_UT_VERSION)
            nc_log_warn(LOG, "adapter %s speaks protocol %u, NavCam %d", u->desc, m->arg, NC_UT_VERSION);
        if (u->input >= m->line)
            nc_log_error(LOG, "adapter %s has %d inputs, no input %d (serve.trigger.input): no edge will come",
                         u->desc, m->line, u->input);
        if (u->strobe_out >= m->level)
            nc_log_error(LOG, "adapter %s has %d outputs, no output %d (serve.trigger.strobe_output): no strobe "
                         "will be driven", u->desc, m->level, u->strobe_out);
        u->burst = NC__USB_BURST, u->next_sync_ns = now;
        return;
    }
    u->messages++;
    uint32_t gap = m->seq - u->next_seq;
    if (gap && gap < 0x80000000u) {
        if (u->lost == 0)
            nc_log_warn(LOG, "adapter %s: %u messages lost (sequence %u, expected %u); counted as `lost`", u->desc, gap,
                        m->seq, u->next_seq);
        u->lost += gap;
    }
    u->next_seq = m->seq + 1;
    if (m->type == NC_UT_EDGE) {
        if (m->line != u->input) {
            u->other_line++;
            return;
        }
        u->edges++;
        u->missed += m->arg;
        u->level_repeats += (m->flags & NC_UT_EDGE_LEVEL_REPEAT) != 0;
        queue_edge(u, m->t0_ns, m->level != 0);
    } else if (m->type == NC_UT_TIME) {
        for (int i = 0; i < NC__USB_N_REQ; i++)
            if (u->req[i].tag == m->tag && m->tag) {
                nc_clock_map_add(&u->map, u->req[i].t1, m->t0_ns, m->t1_ns, now);
                u->req[i].tag = 0;
                break;
            }
        int n = u->nunsynced;
        u->nunsynced = 0;
        for (int i = 0; i < n; i++)
            queue_edge(u, u->unsynced[i], u->unsynced_level[i]);
    }
}

void nc__usb_receive(struct nc__usb_trig *u, const uint8_t *buf, int len, int64_t now)
{
    for (int off = 0; off + NC_UT_MSG_BYTES <= len; off += NC_UT_MSG_BYTES) {
        struct nc_ut_msg m;
        if (nc_ut_decode(buf + off, &m) < 0) { /* skipped, but numbered like any: not a gap */
            u->unknown++;
            m.type = 0;
        }
        on_message(u, &m, now);
    }
}

static void LIBUSB_CALL in_done(struct libusb_transfer *t)
{
    struct nc__usb_trig *u = t->user_data;
    int64_t now = nc_mono_ns();
    pthread_mutex_lock(&u->lock);
    u->nfire = 0;
    if (t->status == LIBUSB_TRANSFER_COMPLETED) {
        nc__usb_receive(u, t->buffer, t->actual_length, now);
    } else if (t->status != LIBUSB_TRANSFER_CANCELLED && t->status != LIBUSB_TRANSFER_TIMED_OUT) {
        /* NO_DEVICE (unplugged), or an error the session does not survive (a STALL, an OVERFLOW): the adapter
         * is still there, and is opened again (trigger_usb.c) */
        if (t->status != LIBUSB_TRANSFER_NO_DEVICE && !u->gone)
            u->session_error = (int)t->status;
        u->gone = 1;
    }
    if (t->status == LIBUSB_TRANSFER_CANCELLED || u->gone || libusb_submit_transfer(t) < 0) {
        u->gone = u->gone || t->status != LIBUSB_TRANSFER_CANCELLED;
        u->inflight--;
    }
    int n = atomic_load(&u->started) ? u->nfire : 0;
    pthread_mutex_unlock(&u->lock);
    /* Outside the lock: the emulator's sink may call control(). */
    for (int i = 0; i < n; i++)
        u->ctx.fire(u->ctx.sink, &u->fire[i]);
}

/* ---- sessions (event thread) --------------------------------------------- */

/* The adapter's interface on dev: 0 and its endpoints, -1 if it has none,
 * -ENODEV if dev is gone (its configuration no longer readable). */
static int find_interface(struct nc__usb_trig *u, libusb_device *dev)
{
    struct libusb_device_descriptor dd;
    struct libusb_config_descriptor *cfg;
    if (libusb_get_device_descriptor(dev, &dd) < 0 || (u->vid >= 0 && (dd.idVendor != u->vid || dd.idProduct != u->pid)))
        return -1;
    snprintf(u->desc, sizeof u->desc, "%04x:%04x at bus %d device %d", dd.idVendor, dd.idProduct,
             libusb_get_bus_number(dev), libusb_get_device_address(dev));
    const int rc = libusb_get_active_config_descriptor(dev, &cfg);
    if (rc < 0)
        return rc == LIBUSB_ERROR_NO_DEVICE ? -ENODEV : -1;
    int found = -1;
    for (int i = 0; i < cfg->bNumInterfaces && found < 0; i++) {
        const struct libusb_interface_descriptor *d = &cfg->interface[i].altsetting[0];
        if (cfg->interface[i].num_altsetting < 1 || d->bInterfaceClass != NC_UT_CLASS ||
            d->bInterfaceSubClass != NC_UT_SUBCLASS || d->bInterfaceProtocol != NC_UT_PROTOCOL)
            continue;
        u->ep_in = u->ep_out = 0;
        for (int e = 0; e < d->bNumEndpoints; e++) {
            const struct libusb_endpoint_descriptor *ep = &d->endpoint[e];
            if ((ep->bmAttributes & 3) != LIBUSB_TRANSFER_TYPE_BULK)
                continue;
            if (ep->bEndpointAddress & LIBUSB_ENDPOINT_IN)
                u->ep_in = ep->bEndpointAddress, u->maxpkt = ep->wMaxPacketSize;
            else
                u->ep_out = ep->bEndpointAddress;
        }
        if (u->ep_in && u->ep_out && u->maxpkt >= NC_UT_MSG_BYTES && u->maxpkt <= NC__USB_MAX_PACKET)
            found = 0, u->iface = d->bInterfaceNumber;
    }
    libusb_free_config_descriptor(cfg);
    return found;
}

int nc__usb_try_open(struct nc__usb_trig *u, libusb_device *dev)
{
    int rc = find_interface(u, dev);
    if (rc == -ENODEV) /* unplugged: libusb reads the configuration from sysfs, gone with the device */
        return nc_error(-ENODEV, "usb trigger: adapter %s is gone", u->desc);
    if (rc < 0)
        return 0;
    libusb_device_handle *h;
    rc = libusb_open(dev, &h);
    if (rc == LIBUSB_ERROR_NO_DEVICE)
        return nc_error(-ENODEV, "usb trigger: adapter %s is gone", u->desc);
    if (rc < 0)
        return nc_error(NC_EUNSUPPORTED, "usb trigger: cannot open adapter %s: %s%s", u->desc, libusb_strerror(rc),
                        rc == LIBUSB_ERROR_ACCESS ? " (install udev/70-navcam-usb-trigger.rules and join group plugdev: "
                                                    "docs/usb-trigger.md)" : "");
    if (u->serial[0]) {
        struct libusb_device_descriptor dd;
        unsigned char s[128] = "";
        libusb_get_device_descriptor(dev, &dd);
        if (!dd.iSerialNumber || libusb_get_string_descriptor_ascii(h, dd.iSerialNumber, s, sizeof s) < 0 ||
            strcmp((char *)s, u->serial)) {
            libusb_close(h);
            return 0;
        }
    }
    libusb_set_auto_detach_kernel_driver(h, 1);
    if ((rc = libusb_claim_interface(h, u->iface)) < 0) {
        libusb_close(h);
        return nc_error(NC_EUNSUPPORTED, "usb trigger: adapter %s: cannot claim interface %d: %s", u->desc, u->iface,
                        libusb_strerror(rc));
    }
    /* an endpoint a session before left halted (a STALL ended it) works again; on a fresh one, a no-op */
    libusb_clear_halt(h, u->ep_in);
    libusb_clear_halt(h, u->ep_out);
    pthread_mutex_lock(&u->lock);
    u->h = h, u->dev = libusb_ref_device(dev), u->gone = 0, u->session_start_ns = nc_mono_ns();
    nc_clock_map_reset(&u->map);
    u->nunsynced = 0;
    for (int i = 0; i < NC__USB_N_IN; i++) {
        libusb_fill_bulk_transfer(u->in[i], h, u->ep_in, u->in[i]->buffer, u->maxpkt, in_done, u, 0);
        if (libusb_submit_transfer(u->in[i]) == 0)
            u->inflight++;
    }
    struct nc_ut_msg hello = {.type = NC_UT_HELLO, .tag = nc__usb_next_tag(u)};
    u->hello_tag = hello.tag;
    u->state = NC__USB_HELLO_SENT;
    u->next_sync_ns = nc_mono_ns() + 1000000000; /* when HELLO is sent again, unanswered */
    rc = nc__usb_send_msg(u, &hello);
    pthread_mutex_unlock(&u->lock);
    return rc < 0 ? nc_error(NC_EUNSUPPORTED, "usb trigger: adapter %s: sending HELLO: %s", u->desc,
                             libusb_strerror(rc)) : 1;
}

void nc__usb_close_session(struct nc__usb_trig *u)
{
    pthread_mutex_lock(&u->lock);
    u->gone = 1;
    for (int i = 0; i < NC__USB_N_IN; i++)
        libusb_cancel_transfer(u->in[i]);
    while (u->inflight > 0) {
        pthread_mutex_unlock(&u->lock);
        struct timeval tv = {0, 100000};
        libusb_handle_events_timeout_completed(u->usb, &tv, NULL);
        pthread_mutex_lock(&u->lock);
    }
    libusb_device_handle *h = u->h;
    libusb_device *dev = u->dev;
    u->h = NULL, u->dev = NULL, u->state = NC__USB_ABSENT;
    u->lost += (unsigned long)u->nunsynced;
    u->nunsynced = 0;
    pthread_mutex_unlock(&u->lock);
    libusb_release_interface(h, u->iface);
    libusb_close(h);
    libusb_unref_device(dev);
}

