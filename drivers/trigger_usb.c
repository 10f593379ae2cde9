/* trigger_usb.c - a hardware trigger through a USB trigger adapter
 * (docs/usb-trigger.md; the reference adapter is adapters/usb-trigger),
 * through libusb, with an optional strobe output.
 *
 * One event thread runs libusb: bulk IN transfers stay queued and their
 * completions carry the adapter's edge events (device timestamps, sequence
 * numbers); clock exchanges go out every sync_interval_s (dithered so they
 * never lock to a bus tick) and map the adapter's clock onto
 * CLOCK_MONOTONIC with a stated error bound (core/clock_map.h). Edges are
 * fired with their mapped times, so the trigger time is when the line
 * changed on the adapter, not when the USB packet arrived. Hot-plug
 * callbacks follow the adapter: unplugged, it is reported and counted;
 * plugged again, it is reopened and the session restarts (a new clock map,
 * a new sequence). The "exposure" control sends each exposure window in the
 * adapter's clock for its strobe output.
 *
 * Options (the serve.trigger map): usb_params below.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "drivers/usb/usb_link.h"

#define LOG "trigger/usb"

/* `id`: VID:PID, four hexadecimal digits each. */
static int id_form(const char *id, char *why, size_t len)
{
    const char *hex = "0123456789abcdefABCDEF";
    if (strlen(id) == 9 && strspn(id, hex) == 4 && id[4] == ':' && strspn(id + 5, hex) == 4)
        return 0;
    snprintf(why, len, "'%s' is not VID:PID (four hexadecimal digits each, as lsusb prints them, e.g. 1209:0001)", id);
    return -1;
}

static const struct nc_param usb_params[] = {
    NC_P_STRING_CHECKED("id", NULL, id_form, "VID:PID of the adapter, hexadecimal as lsusb prints it (default: any device with the adapter's interface)"),
    NC_P_STRING("serial", NULL, "the adapter's serial number (default: any)"),
    NC_P_INT("input", "0", 0, NC_UT_MAX_LINES - 1, "", "the adapter's input line that triggers"),
    NC_P_INT("strobe_output", "-1", -1, NC_UT_MAX_LINES - 1, "", "the adapter's output line driven during exposures (-1: none)"),
    NC_P_DOUBLE("sync_interval_s", "0.1", 0.01, 10, "s", "between clock exchanges with the adapter"),
    NC_P_END,
};

static int LIBUSB_CALL on_hotplug(libusb_context *ctx, libusb_device *dev, libusb_hotplug_event ev, void *arg)
{
    struct nc__usb_trig *u = arg;
    pthread_mutex_lock(&u->lock);
    if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT && dev == u->dev) {
        u->gone = 1;
        u->session_error = 0; /* unplugged, whatever a transfer said */
    } else if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT && dev == u->retry) {
        libusb_unref_device(u->retry); /* the transfer error was its unplugging: it comes back as an arrival */
        u->retry = NULL;
    } else if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED) { /* the event loop looks at it: no I/O in a callback */
        if (u->narrived == NC__USB_N_ARRIVED) {
            libusb_unref_device(u->arrived[0]);
            memmove(u->arrived, u->arrived + 1, sizeof u->arrived[0] * --u->narrived);
        }
        u->arrived[u->narrived++] = libusb_ref_device(dev);
    }
    pthread_mutex_unlock(&u->lock);
    return 0;
}

/* A session that ended: closed, and counted and reported as an unplug, or
 * (error: the transfer status that ended it) left for the verdict: the
 * adapter is opened again after a wait, unless its hot-plug departure comes
 * first (an unplug often ends the transfers with an I/O error before udev
 * tells). While its sessions keep ending within 10 s of their start, the
 * wait doubles, up to 10 s. Event thread. */
static void session_ended(struct nc__usb_trig *u, int error)
{
    pthread_mutex_lock(&u->lock);
    libusb_device *again = error ? libusb_ref_device(u->dev) : NULL;
    pthread_mutex_unlock(&u->lock);
    nc__usb_close_session(u);
    pthread_mutex_lock(&u->lock);
    u->unplugged_at_ns = nc_mono_ns();
    u->session_error = 0;
    u->verdict = error;
    if (again) {
        if (u->retry)
            libusb_unref_device(u->retry);
        u->retry = again;
        const int64_t w = u->retry_wait_ns;
        u->retry_wait_ns = !w || u->unplugged_at_ns - u->session_start_ns > 10000000000 ? 200000000
                           : w < 5000000000 ? 2 * w : 10000000000;
        u->retry_at_ns = u->unplugged_at_ns + u->retry_wait_ns;
    }
    pthread_mutex_unlock(&u->lock);
}

/* The verdict on a session a transfer error ended, counted, into line (""
 * while it is still open): an unplug when the adapter left (its hot-plug
 * departure, or gone = 1: no such device when it was opened again), else a
 * session error once it was opened again (opened = 1) or could not be for
 * another reason (opened = -1). Lock held. */
static void verdict(struct nc__usb_trig *u, int gone, int opened, char *line, size_t len)
{
    line[0] = 0;
    if (!u->verdict || (u->retry && !gone && !opened))
        return;
    if (gone || (!u->retry && !opened))
        snprintf(line, len, "adapter %s unplugged (%lu so far); waiting for it to come back", u->desc, ++u->unplugged);
    else
        snprintf(line, len, "adapter %s: the session ended on a transfer error (%s; %lu so far)%s", u->desc,
                 u->verdict == LIBUSB_TRANSFER_STALL      ? "a stall"
                 : u->verdict == LIBUSB_TRANSFER_OVERFLOW ? "an overflow"
                                                          : "an I/O error",
                 ++u->session_errors, opened > 0 ? "; opened again" : "; opening it again, less often");
    u->verdict = 0;
}

static void *usb_thread(void *arg)
{
    struct nc__usb_trig *u = arg;
    while (!atomic_load(&u->stop)) {
        int64_t now = nc_mono_ns();
        char said[256];
        pthread_mutex_lock(&u->lock);
        int gone = u->state != NC__USB_ABSENT && u->gone;
        const int error = gone ? u->session_error : 0;
        verdict(u, 0, 0, said, sizeof said); /* it left meanwhile */
        /* Devices plugged in during a session are other devices; once the
         * session is gone, each is a candidate, oldest first; then the
         * adapter a session error left, when its time comes. */
        libusb_device *arrived = NULL;
        int from_retry = 0;
        while (u->narrived && u->state != NC__USB_ABSENT && !u->gone)
            libusb_unref_device(u->arrived[--u->narrived]);
        if (u->narrived && u->state == NC__USB_ABSENT) {
            arrived = u->arrived[0];
            memmove(u->arrived, u->arrived + 1, sizeof u->arrived[0] * --u->narrived);
        } else if (u->retry && u->state == NC__USB_ABSENT && now >= u->retry_at_ns) {
            arrived = u->retry;
            u->retry = NULL;
            from_retry = 1;
        }
        if (u->state == NC__USB_READY && !u->gone && now >= u->next_sync_ns) {
            nc__usb_send_time_req(u);
            /* +-10 % dither: exchanges never lock to a bus tick */
            u->dither = u->dither * 6364136223846793005ull + 1442695040888963407ull;
            double f = 0.9 + 0.2 * (double)(u->dither >> 11) / 9007199254740992.0;
            u->next_sync_ns = now + (int64_t)((u->burst > 0 ? 20e6 : (double)u->sync_ns) * f);
            u->burst -= u->burst > 0;
        }
        if (u->state == NC__USB_HELLO_SENT && !u->gone && now >= u->next_sync_ns) {
            /* An adapter still starting up: ask again every second. */
            struct nc_ut_msg hello = {.type = NC_UT_HELLO, .tag = nc__usb_next_tag(u)};
            u->hello_tag = hello.tag;
            nc__usb_send_msg(u, &hello);
            u->next_sync_ns = now + 1000000000;
        }
        int64_t wait = u->state != NC__USB_ABSENT                            ? u->next_sync_ns - now
                       : u->retry && u->retry_at_ns - now < 1000000000 ? u->retry_at_ns - now
                                                                          : 1000000000;
        pthread_mutex_unlock(&u->lock);
        if (said[0])
            nc_log_warn(LOG, "%s", said);
        if (gone) {
            session_ended(u, error);
            if (!error) {
                pthread_mutex_lock(&u->lock);
                unsigned long n = ++u->unplugged;
                pthread_mutex_unlock(&u->lock);
                nc_log_warn(LOG, "adapter %s unplugged (%lu so far); waiting for it to come back", u->desc, n);
            }
            continue;
        }
        if (arrived) {
            int rc = nc__usb_try_open(u, arrived);
            if (rc == -ENODEV && !from_retry)
                rc = 0; /* a device that came and went at once */
            pthread_mutex_lock(&u->lock);
            const int left = from_retry && rc == -ENODEV; /* unplugged, though udev has not said so yet */
            if (from_retry)
                verdict(u, left, rc > 0 ? 1 : -1, said, sizeof said);
            const int was_away = u->unplugged + u->session_errors > u->reopened;
            u->reopened += rc > 0 && was_away;
            const int first_failure = rc <= 0 && from_retry && !left && u->retry_failures++ == 0;
            if (rc > 0)
                u->retry_failures = 0;
            if (rc <= 0 && from_retry && !left && !u->retry) { /* again later, less often (up to every 10 s) */
                u->retry = libusb_ref_device(arrived);
                u->retry_wait_ns = u->retry_wait_ns < 5000000000 ? 2 * u->retry_wait_ns : 10000000000;
                u->retry_at_ns = nc_mono_ns() + u->retry_wait_ns;
            }
            pthread_mutex_unlock(&u->lock);
            if (said[0])
                nc_log_warn(LOG, "%s", said);
            if (rc < 0 && !left && (!from_retry || first_failure))
                nc_log_error(LOG, "%s%s", nc_errmsg(),
                             from_retry ? " (trying again, less often, up to every 10 s)" : "");
            else if (rc > 0 && was_away)
                nc_log_info(LOG, "adapter %s reopened after %.1f s", u->desc,
                            (nc_mono_ns() - u->unplugged_at_ns) * 1e-9);
            libusb_unref_device(arrived);
            continue;
        }
        wait = wait < 0 ? 0 : wait;
        struct timeval tv = {(time_t)(wait / 1000000000), (long)(wait % 1000000000 / 1000)};
        libusb_handle_events_timeout_completed(u->usb, &tv, NULL);
    }
    return NULL;
}

/* ---- the driver ---------------------------------------------------------- */

static void usb_close(void *priv);

static int parse_id(struct nc__usb_trig *u, struct nc_cfg_node *opts)
{
    const char *id = NULL;
    int rc = nc_param_string(opts, usb_params, "id", &id);
    u->vid = u->pid = -1;
    if (rc < 0 || !id)
        return rc;
    unsigned v = 0, p = 0;
    sscanf(id, "%x:%x", &v, &p); /* of the form id_form checked */
    u->vid = (int)v, u->pid = (int)p;
    return 0;
}

static int open_first(struct nc__usb_trig *u)
{
    libusb_device **list;
    ssize_t n = libusb_get_device_list(u->usb, &list);
    if (n < 0)
        return nc_error(NC_EUNSUPPORTED, "usb trigger: listing USB devices: %s", libusb_strerror((int)n));
    int rc = 0;
    for (ssize_t i = 0; i < n && rc == 0; i++)
        if ((rc = nc__usb_try_open(u, list[i])) == -ENODEV)
            rc = 0; /* a device gone while listed: not ours to name (nothing identified it as the adapter) */
    libusb_free_device_list(list, 1);
    if (rc != 0)
        return rc < 0 ? rc : 0;
    char idtxt[24] = "";
    if (u->vid >= 0)
        snprintf(idtxt, sizeof idtxt, " with id %04x:%04x", (unsigned)u->vid, (unsigned)u->pid);
    return nc_error(NC_EUNSUPPORTED, "usb trigger: no USB trigger adapter%s%s%s found among %zd USB devices (one "
                    "with interface %02x/%02x/%02x \"%s\"; `lsusb -v` lists interfaces; is navcam-usb-adapter "
                    "running on the adapter?)", u->serial[0] ? " with serial " : "", u->serial, idtxt, n,
                    NC_UT_CLASS, NC_UT_SUBCLASS, NC_UT_PROTOCOL, NC_UT_INTERFACE_NAME);
}

static int usb_open(void *priv, struct nc_cfg_node *opts, const struct nc_trigger_ctx *ctx)
{
    struct nc__usb_trig *u = priv;
    long input = 0, strobe = -1;
    double sync_s = 0.1;
    const char *serial = NULL;
    int rc;
    u->ctx = *ctx;
    pthread_mutex_init(&u->lock, NULL);
    if ((rc = parse_id(u, opts)) < 0 || (rc = nc_param_string(opts, usb_params, "serial", &serial)) < 0 ||
        (rc = nc_param_int(opts, usb_params, "input", &input)) < 0 ||
        (rc = nc_param_int(opts, usb_params, "strobe_output", &strobe)) < 0 ||
        (rc = nc_param_double(opts, usb_params, "sync_interval_s", &sync_s)) < 0)
        return rc;
    snprintf(u->serial, sizeof u->serial, "%s", serial ? serial : "");
    u->input = (int)input, u->strobe_out = (int)strobe, u->sync_ns = (int64_t)(sync_s * 1e9);
    u->dither = 0x2545f4914f6cdd1dull;
    /* HELLO's tag from a random start: an INFO still queued in the adapter for a process before this one (one
     * that died waiting for it) does not answer this one's HELLO */
    if (getrandom(&u->tag, sizeof u->tag, 0) != (ssize_t)sizeof u->tag)
        u->tag = (uint32_t)nc_mono_ns();
    if ((rc = libusb_init(&u->usb)) < 0) {
        u->usb = NULL;
        return nc_error(NC_EUNSUPPORTED, "usb trigger: libusb_init: %s", libusb_strerror(rc));
    }
    for (int i = 0; i < NC__USB_N_IN; i++) {
        u->in[i] = libusb_alloc_transfer(0);
        if (!u->in[i] || !(u->in[i]->buffer = malloc(NC__USB_MAX_PACKET))) {
            usb_close(u);
            return -ENOMEM;
        }
    }
    if ((rc = open_first(u)) < 0) {
        usb_close(u);
        return rc;
    }
    /* The adapter answers HELLO before the camera counts as open. */
    int64_t deadline = nc_mono_ns() + 2000000000;
    while (u->state == NC__USB_HELLO_SENT && !u->gone && nc_mono_ns() < deadline) {
        struct timeval tv = {0, 100000};
        libusb_handle_events_timeout_completed(u->usb, &tv, NULL);
    }
    if (u->state != NC__USB_READY) {
        rc = nc_error(NC_EUNSUPPORTED, "usb trigger: adapter %s %s", u->desc,
                      u->gone ? "went away while opening" : "did not answer HELLO within 2 s");
        usb_close(u);
        return rc;
    }
    if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) &&
        libusb_hotplug_register_callback(u->usb, LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT,
                                         0, u->vid >= 0 ? u->vid : LIBUSB_HOTPLUG_MATCH_ANY,
                                         u->pid >= 0 ? u->pid : LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
                                         on_hotplug, u, &u->hotplug) == 0)
        u->have_hotplug = 1;
    else
        nc_log_warn(LOG, "no USB hot-plug events here: an unplugged adapter will not be reopened");
    return 0;
}

static int usb_start(void *priv)
{
    struct nc__usb_trig *u = priv;
    atomic_store(&u->started, 1);
    int err = pthread_create(&u->thread, NULL, usb_thread, u);
    if (err)
        return nc_error(-err, "usb trigger: cannot start its thread: %s", strerror(err));
    u->running = 1;
    return 0;
}

static void usb_stop(void *priv)
{
    struct nc__usb_trig *u = priv;
    if (!u->running)
        return;
    atomic_store(&u->stop, 1);
    libusb_interrupt_event_handler(u->usb);
    pthread_join(u->thread, NULL);
    atomic_store(&u->started, 0);
    u->running = 0;
}

static void write_stats(struct nc__usb_trig *u, FILE *f)
{
    pthread_mutex_lock(&u->lock);
    fprintf(f, "{\"connected\": %s, \"messages\": %lu, \"edges\": %lu, \"lost\": %lu, \"missed_by_adapter\": %lu, "
               "\"level_repeats\": %lu, "
               "\"other_lines\": %lu, \"unknown\": %lu, \"unplugged\": %lu, \"session_errors\": %lu, "
               "\"reopened\": %lu, \"strobes\": %lu, "
               "\"strobes_skipped\": %lu, \"clock_exchanges\": %lu, \"clock_exchanges_used\": %d, \"clock_offset_s\": %.9f, \"clock_drift_ppm\": %.3f, "
               "\"clock_bound_us\": %.3f, \"edge_bound_max_us\": %.3f}",
            u->state == NC__USB_READY ? "true" : "false", u->messages, u->edges, u->lost, u->missed, u->level_repeats, u->other_line, u->unknown,
            u->unplugged, u->session_errors, u->reopened, u->strobes, u->strobes_skipped, u->map.added, u->map.used,
            u->map.offset_ns * 1e-9,
            u->map.drift * 1e6, u->map.valid ? u->map.bound_ns * 1e-3 : -1.0, u->edge_bound_max_ns * 1e-3);
    pthread_mutex_unlock(&u->lock);
}

/* "exposure": a struct nc_trigger_window for the strobe; "stats": a FILE *
 * to write the driver's counters to, as one JSON object. */
static int usb_control(void *priv, const char *request, void *arg)
{
    struct nc__usb_trig *u = priv;
    if (!strcmp(request, "stats")) {
        write_stats(u, arg);
        return 0;
    }
    if (strcmp(request, "exposure") || u->strobe_out < 0)
        return NC_EUNSUPPORTED;
    const struct nc_trigger_window *w = arg;
    struct nc_ut_msg m = {.type = NC_UT_STROBE, .line = (uint8_t)u->strobe_out};
    pthread_mutex_lock(&u->lock);
    /* one sent is counted when its transfer is done (out_done: delivered, or skipped after all) */
    if (!(u->state == NC__USB_READY && !u->gone && nc_clock_map_to_device(&u->map, w->start_mono_ns, &m.t0_ns) == 0 &&
          nc_clock_map_to_device(&u->map, w->end_mono_ns, &m.t1_ns) == 0 && nc__usb_send_msg(u, &m) == 0))
        u->strobes_skipped++;
    pthread_mutex_unlock(&u->lock);
    return 0;
}

static void usb_close(void *priv)
{
    struct nc__usb_trig *u = priv;
    usb_stop(u);
    if (!u->usb)
        return;
    if (u->have_hotplug)
        libusb_hotplug_deregister_callback(u->usb, u->hotplug);
    if (u->h)
        nc__usb_close_session(u);
    while (u->narrived)
        libusb_unref_device(u->arrived[--u->narrived]);
    if (u->retry)
        libusb_unref_device(u->retry);
    u->retry = NULL;
    for (int i = 0; i < NC__USB_N_IN; i++)
        if (u->in[i]) {
            free(u->in[i]->buffer);
            u->in[i]->buffer = NULL;
            libusb_free_transfer(u->in[i]);
        }
    if (u->edges || u->lost || u->unplugged || u->session_errors)
        nc_log_info(LOG, "%lu edges, %lu messages lost, %lu missed by the adapter, unplugged %lu times, %lu session "
                    "errors, reopened %lu; clock bound %.1f us at the end", u->edges, u->lost, u->missed, u->unplugged,
                    u->session_errors, u->reopened, u->map.bound_ns * 1e-3);
    libusb_exit(u->usb);
    pthread_mutex_destroy(&u->lock);
    u->usb = NULL;
}

const struct nc_trigger_driver nc_trigger_usb = {
    .name = "usb",
    .description = "a USB trigger adapter through libusb (adapter timestamps mapped to CLOCK_MONOTONIC, hot-plug), "
                   "with an optional strobe output",
    .caps = NC_TRIGGER_CAP_LINE,
    .priv_size = sizeof(struct nc__usb_trig),
    .params = usb_params,
    .open = usb_open,
    .start = usb_start,
    .stop = usb_stop,
    .control = usb_control,
    .close = usb_close,
};
