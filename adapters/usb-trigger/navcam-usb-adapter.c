/* navcam-usb-adapter.c - the reference USB trigger adapter: a user-space
 * USB gadget (FunctionFS) that turns a board with a device-mode USB port
 * (a Raspberry Pi, for one) into NavCam's trigger adapter
 * (docs/usb-trigger.md is the protocol; README.md beside this file says how
 * to set a board up).
 *
 * Threads: the main one serves ep0 (the function's life: bind, enable,
 * disable) and signals; one reads the host's requests from the OUT
 * endpoint; one writes queued messages to the IN endpoint, one packet per
 * write; lines.c's reads the GPIO inputs and drives the strobes. Nothing
 * here may block the GPIO thread: it only queues.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* ppoll, signalfd (the CMake build defines it for every file) */
#endif
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <linux/usb/ch9.h>
#include <linux/usb/functionfs.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#include "adapter.h"
#include "core/clock.h"
#include "core/le.h"

static int ep_in = -1, ep_out = -1;

int64_t adapter_dev_ns(const struct adapter *a, int64_t mono_ns)
{
    return mono_ns + llround(a->clock_offset_s * 1e9 + a->clock_drift_ppm * 1e-6 * (double)(mono_ns - a->mono0_ns));
}

int64_t adapter_mono_ns(const struct adapter *a, int64_t dev_ns)
{
    double x = (double)(dev_ns - a->mono0_ns) - a->clock_offset_s * 1e9;
    return a->mono0_ns + llround(x / (1 + a->clock_drift_ppm * 1e-6));
}

void adapter_push(struct adapter *a, struct nc_ut_msg *m)
{
    m->seq = a->seq++; /* given even to a message dropped: the host sees the gap */
    if (a->qcount == QUEUE_LEN) {
        a->dropped++;
        return;
    }
    a->q[(a->qhead + a->qcount++) % QUEUE_LEN] = *m;
}

/* ---- FunctionFS ------------------------------------------------------------ */

static int write_descriptors(int ep0)
{
    struct ep_pair {
        struct usb_interface_descriptor intf;
        struct usb_endpoint_descriptor_no_audio in, out;
    } __attribute__((packed));
    struct {
        struct usb_functionfs_descs_head_v2 head;
        uint32_t fs_count, hs_count;
        struct ep_pair fs, hs;
    } __attribute__((packed)) d;
    struct ep_pair p = {
        .intf = {.bLength = sizeof p.intf, .bDescriptorType = USB_DT_INTERFACE, .bNumEndpoints = 2,
                 .bInterfaceClass = NC_UT_CLASS, .bInterfaceSubClass = NC_UT_SUBCLASS,
                 .bInterfaceProtocol = NC_UT_PROTOCOL, .iInterface = 1},
        .in = {.bLength = sizeof p.in, .bDescriptorType = USB_DT_ENDPOINT, .bEndpointAddress = 1 | USB_DIR_IN,
               .bmAttributes = USB_ENDPOINT_XFER_BULK},
        .out = {.bLength = sizeof p.out, .bDescriptorType = USB_DT_ENDPOINT, .bEndpointAddress = 2 | USB_DIR_OUT,
                .bmAttributes = USB_ENDPOINT_XFER_BULK},
    };
    memset(&d, 0, sizeof d);
    d.fs = d.hs = p;
    nc_le_put_u16((uint8_t *)&d.fs.in.wMaxPacketSize, 64);
    nc_le_put_u16((uint8_t *)&d.fs.out.wMaxPacketSize, 64);
    nc_le_put_u16((uint8_t *)&d.hs.in.wMaxPacketSize, 512);
    nc_le_put_u16((uint8_t *)&d.hs.out.wMaxPacketSize, 512);
    nc_le_put_u32((uint8_t *)&d.head.magic, FUNCTIONFS_DESCRIPTORS_MAGIC_V2);
    nc_le_put_u32((uint8_t *)&d.head.length, sizeof d);
    nc_le_put_u32((uint8_t *)&d.head.flags, FUNCTIONFS_HAS_FS_DESC | FUNCTIONFS_HAS_HS_DESC);
    nc_le_put_u32((uint8_t *)&d.fs_count, 3);
    nc_le_put_u32((uint8_t *)&d.hs_count, 3);
    struct {
        struct usb_functionfs_strings_head head;
        uint16_t lang;
        char name[sizeof NC_UT_INTERFACE_NAME];
    } __attribute__((packed)) s;
    nc_le_put_u32((uint8_t *)&s.head.magic, FUNCTIONFS_STRINGS_MAGIC);
    nc_le_put_u32((uint8_t *)&s.head.length, sizeof s);
    nc_le_put_u32((uint8_t *)&s.head.str_count, 1);
    nc_le_put_u32((uint8_t *)&s.head.lang_count, 1);
    nc_le_put_u16((uint8_t *)&s.lang, 0x0409);
    memcpy(s.name, NC_UT_INTERFACE_NAME, sizeof s.name);
    if (write(ep0, &d, sizeof d) != (ssize_t)sizeof d || write(ep0, &s, sizeof s) != (ssize_t)sizeof s) {
        perror("navcam-usb-adapter: writing the descriptors to ep0");
        return -1;
    }
    return 0;
}

/* Bind the gadget to a UDC (name "" unbinds). */
static int set_udc(struct adapter *a, const char *name)
{
    char path[512], first[128] = "";
    if (!strcmp(name, "auto")) {
        FILE *ls = popen("ls /sys/class/udc 2>/dev/null", "r");
        if (!ls || !fgets(first, sizeof first, ls)) {
            fprintf(stderr, "navcam-usb-adapter: --udc auto: no USB device controller in /sys/class/udc (load your "
                            "board's UDC driver, e.g. dwc2 on a Raspberry Pi)\n");
            if (ls)
                pclose(ls);
            return -1;
        }
        pclose(ls);
        first[strcspn(first, "\n")] = 0;
        name = first;
    }
    snprintf(path, sizeof path, "%s/UDC", a->gadget);
    int fd = open(path, O_WRONLY);
    int ok = fd >= 0 && write(fd, *name ? name : "\n", *name ? strlen(name) : 1) >= 0;
    if (!ok)
        fprintf(stderr, "navcam-usb-adapter: %s: writing '%s': %s\n", path, name, strerror(errno));
    else if (*name)
        fprintf(stderr, "navcam-usb-adapter: bound to %s\n", name);
    if (fd >= 0)
        close(fd);
    return ok ? 0 : -1;
}

static int max_packet(int fd)
{
    struct usb_endpoint_descriptor d;
    if (ioctl(fd, FUNCTIONFS_ENDPOINT_DESC, &d) < 0)
        return 64;
    int n = nc_le_get_u16((const uint8_t *)&d.wMaxPacketSize) & 0x7ff;
    return n >= NC_UT_MSG_BYTES ? n : 64;
}

/* Wait until the host has configured the function (or we stop). Lock held. */
static void wait_enabled(struct adapter *a)
{
    while (!a->enabled && !atomic_load(&a->stop))
        pthread_cond_wait(&a->cond, &a->lock);
}

/* After a failed transfer: 50 ms, or less if the function's state changes,
 * so that a gone host is not spun on. Lock held. */
static void pause_locked(struct adapter *a)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += 50000000;
    ts.tv_sec += ts.tv_nsec / 1000000000, ts.tv_nsec %= 1000000000;
    pthread_cond_timedwait(&a->cond, &a->lock, &ts);
}

static void *writer_thread(void *arg)
{
    struct adapter *a = arg;
    uint8_t buf[1024];
    int pkt = 64, was_enabled = 0;
    pthread_mutex_lock(&a->lock);
    while (!atomic_load(&a->stop)) {
        wait_enabled(a);
        if (!was_enabled)
            pkt = max_packet(ep_in), was_enabled = 1;
        if (!a->qcount) {
            pthread_cond_wait(&a->cond, &a->lock);
            was_enabled = a->enabled;
            continue;
        }
        int n = 0;
        int64_t now = adapter_dev_ns(a, nc_mono_ns());
        while (a->qcount && (n + 1) * NC_UT_MSG_BYTES <= pkt) {
            struct nc_ut_msg *m = &a->q[a->qhead];
            if (m->type == NC_UT_TIME)
                m->t1_ns = now; /* t3: as late as the reply can be stamped */
            nc_ut_encode(buf + n++ * NC_UT_MSG_BYTES, m);
            a->qhead = (a->qhead + 1) % QUEUE_LEN;
            a->qcount--;
        }
        pthread_mutex_unlock(&a->lock);
        ssize_t w = write(ep_in, buf, (size_t)n * NC_UT_MSG_BYTES);
        int err = errno;
        pthread_mutex_lock(&a->lock);
        if (w == (ssize_t)n * NC_UT_MSG_BYTES) {
            a->sent += (unsigned long)n;
        } else { /* the host went away with them: they show as a sequence gap if it comes back unreset */
            a->write_lost += (unsigned long)n;
            if (a->enabled && err != ESHUTDOWN)
                fprintf(stderr, "navcam-usb-adapter: writing to the IN endpoint: %s\n", strerror(err));
            was_enabled = 0;
            pause_locked(a);
        }
    }
    pthread_mutex_unlock(&a->lock);
    return NULL;
}

static void on_request(struct adapter *a, const struct nc_ut_msg *m, int64_t t2)
{
    if (m->type == NC_UT_STROBE) {
        lines_strobe(a, m->line, m->t0_ns, m->t1_ns);
        return;
    }
    pthread_mutex_lock(&a->lock);
    if (m->type == NC_UT_HELLO) {
        /* A new session: what was queued for the last one is not wanted. */
        a->flushed += a->qcount;
        a->qcount = 0;
        a->hellos++;
        struct nc_ut_msg r = {.type = NC_UT_INFO, .line = (uint8_t)a->n_in, .level = (uint8_t)a->n_out,
                              .tag = m->tag, .arg = NC_UT_VERSION, .t0_ns = t2, .t1_ns = (int64_t)a->dropped};
        adapter_push(a, &r);
    } else if (m->type == NC_UT_TIME_REQ) {
        struct nc_ut_msg r = {.type = NC_UT_TIME, .tag = m->tag, .t0_ns = t2};
        a->time_reqs++;
        adapter_push(a, &r);
    }
    pthread_cond_broadcast(&a->cond);
    pthread_mutex_unlock(&a->lock);
}

static void *reader_thread(void *arg)
{
    struct adapter *a = arg;
    uint8_t buf[1024];
    while (!atomic_load(&a->stop)) {
        /* A packet at a time: a host's transfer of several messages in one full packet ends with no short
         * packet, so a longer read would wait for the next transfer (an outside check: 16 requests in one
         * 512-byte packet answered only when another came, 1.5 s later). */
        const int pkt = max_packet(ep_out);
        ssize_t n = read(ep_out, buf, pkt < (int)sizeof buf ? (size_t)pkt : sizeof buf);
        int64_t t2 = adapter_dev_ns(a, nc_mono_ns());
        if (n < 0) {
            pthread_mutex_lock(&a->lock);
            if (a->enabled && errno != ESHUTDOWN && errno != EINTR)
                fprintf(stderr, "navcam-usb-adapter: reading the OUT endpoint: %s\n", strerror(errno));
            pause_locked(a);
            pthread_mutex_unlock(&a->lock);
            continue;
        }
        for (ssize_t off = 0; off + NC_UT_MSG_BYTES <= n; off += NC_UT_MSG_BYTES) {
            struct nc_ut_msg m;
            if (nc_ut_decode(buf + off, &m) == 0)
                on_request(a, &m, t2);
        }
    }
    return NULL;
}

/* ---- ep0 and the process ---------------------------------------------------- */

static void on_ep0_event(struct adapter *a, int ep0, const struct usb_functionfs_event *ev)
{
    static const char *const names[] = {"bind", "unbind", "enable", "disable", "setup", "suspend", "resume"};
    if (ev->type <= FUNCTIONFS_RESUME && ev->type != FUNCTIONFS_SETUP)
        fprintf(stderr, "navcam-usb-adapter: %s\n", names[ev->type]);
    pthread_mutex_lock(&a->lock);
    if (ev->type == FUNCTIONFS_ENABLE)
        a->enabled = 1;
    else if (ev->type == FUNCTIONFS_DISABLE || ev->type == FUNCTIONFS_UNBIND)
        a->enabled = 0;
    pthread_cond_broadcast(&a->cond);
    pthread_mutex_unlock(&a->lock);
    /* No control requests are served: stall them (FunctionFS stalls an IN
     * request on a read of ep0 and an OUT request on a write; either call
     * then fails with EL2HLT, as it should). */
    if (ev->type == FUNCTIONFS_SETUP) {
        ssize_t r = ev->u.setup.bRequestType & USB_DIR_IN ? read(ep0, NULL, 0) : write(ep0, NULL, 0);
        (void)r;
    }
}

static void print_stats(struct adapter *a)
{
    pthread_mutex_lock(&a->lock);
    fprintf(stderr, "navcam-usb-adapter: stats {\"edges\": %lu, \"missed\": %lu, \"level_repeats\": %lu, \"sent\": %lu, \"dropped\": %lu, "
                    "\"flushed\": %lu, \"write_lost\": %lu, \"queued\": %u, \"hellos\": %lu, \"time_requests\": %lu, "
                    "\"strobes\": %lu, \"strobes_late\": %lu, \"strobes_missed\": %lu, \"strobes_stretched\": %lu, "
                    "\"strobes_dropped\": %lu}\n",
            a->edges, a->missed, a->level_repeats, a->sent, a->dropped, a->flushed, a->write_lost, a->qcount, a->hellos, a->time_reqs,
            a->win.started, a->strobes_late, a->win.missed, a->win.stretched, a->win.dropped);
    pthread_mutex_unlock(&a->lock);
}

static int serve(struct adapter *a, int ep0)
{
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT), sigaddset(&set, SIGTERM), sigaddset(&set, SIGUSR1);
    pthread_sigmask(SIG_BLOCK, &set, NULL); /* before the threads: they inherit it */
    int sfd = signalfd(-1, &set, SFD_CLOEXEC);
    pthread_t t[3];
    pthread_create(&t[0], NULL, lines_thread, a);
    pthread_create(&t[1], NULL, writer_thread, a);
    pthread_create(&t[2], NULL, reader_thread, a);
    if (a->gadget && set_udc(a, a->udc) < 0)
        atomic_store(&a->stop, 1);
    fprintf(stderr, "navcam-usb-adapter: serving on %s; SIGINT or SIGTERM stops, SIGUSR1 prints counters\n", a->ffs);
    while (!atomic_load(&a->stop)) {
        struct pollfd p[2] = {{.fd = ep0, .events = POLLIN}, {.fd = sfd, .events = POLLIN}};
        if (poll(p, 2, -1) < 0 && errno != EINTR)
            break;
        if (p[1].revents & POLLIN) {
            struct signalfd_siginfo si;
            if (read(sfd, &si, sizeof si) == (ssize_t)sizeof si && si.ssi_signo == SIGUSR1)
                print_stats(a);
            else
                atomic_store(&a->stop, 1);
        }
        if (p[0].revents & POLLIN) {
            struct usb_functionfs_event ev[4];
            ssize_t n = read(ep0, ev, sizeof ev);
            for (ssize_t i = 0; i + (ssize_t)sizeof ev[0] <= n; i += (ssize_t)sizeof ev[0])
                on_ep0_event(a, ep0, &ev[i / (ssize_t)sizeof ev[0]]);
        }
    }
    if (a->gadget)
        set_udc(a, ""); /* the host sees the adapter unplugged; blocked endpoint I/O returns */
    atomic_store(&a->stop, 1);
    pthread_mutex_lock(&a->lock);
    pthread_cond_broadcast(&a->cond);
    pthread_mutex_unlock(&a->lock);
    uint64_t one = 1;
    if (write(a->wake_fd, &one, sizeof one) < 0)
        perror("navcam-usb-adapter: eventfd");
    pthread_join(t[0], NULL); /* the strobes are left inactive */
    print_stats(a);
    return 0;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: navcam-usb-adapter --ffs DIR --chip CHIP --input LINE [options]\n"
            "NavCam's USB trigger adapter: GPIO input edges, with the kernel's timestamps, go to the\n"
            "host as EDGE messages; the host's strobe windows drive GPIO outputs (docs/usb-trigger.md).\n"
            "  --ffs DIR             a mounted FunctionFS instance (navcam-usb-gadget.sh setup makes one)\n"
            "  --chip CHIP           the GPIO chip: gpiochipN, /dev/gpiochipN, its label or number\n"
            "  --input LINE          an input line, by name or offset; repeat for inputs 1, 2, ... (up to %d)\n"
            "  --bias B              the inputs' bias: as_is (default), disable, pull_up, pull_down\n"
            "  --strobe LINE         an output line driven during exposures; repeat for outputs 1, 2, ...\n"
            "  --strobe-active L     the outputs' active level: high (default) or low\n"
            "  --gadget DIR          the configfs gadget to bind once the descriptors are written,\n"
            "                        and to unbind on exit (e.g. /sys/kernel/config/usb_gadget/navcam)\n"
            "  --udc NAME            the USB device controller to bind to (default auto: the first in\n"
            "                        /sys/class/udc)\n"
            "  --clock-offset-s S    report times S seconds ahead of the board's CLOCK_MONOTONIC, and\n"
            "  --clock-drift-ppm P   running P ppm fast: tests stand for a board with its own clock\n"
            "  -h, --help            this text\n",
            NC_UT_MAX_LINES);
}

static int add_line(struct line *tab, int *n, const char *name)
{
    if (*n == NC_UT_MAX_LINES) {
        fprintf(stderr, "navcam-usb-adapter: at most %d inputs and %d outputs\n", NC_UT_MAX_LINES, NC_UT_MAX_LINES);
        return -1;
    }
    tab[(*n)++].name = name;
    return 0;
}

int main(int argc, char **argv)
{
    static struct adapter a; /* zeroed, in .bss: its queue is 2 MB */
    a.bias = "as_is", a.strobe_active = "high", a.udc = "auto", a.wake_fd = -1, a.events_fd = -1;
    static const struct option opts[] = {
        {"ffs", 1, 0, 'f'}, {"chip", 1, 0, 'c'}, {"input", 1, 0, 'i'}, {"bias", 1, 0, 'b'}, {"strobe", 1, 0, 's'},
        {"strobe-active", 1, 0, 'a'}, {"gadget", 1, 0, 'g'}, {"udc", 1, 0, 'u'}, {"clock-offset-s", 1, 0, 'o'},
        {"clock-drift-ppm", 1, 0, 'd'}, {"help", 0, 0, 'h'}, {0, 0, 0, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'f': a.ffs = optarg; break;
        case 'c': a.chip_name = optarg; break;
        case 'i': if (add_line(a.in, &a.n_in, optarg) < 0) return 2; break;
        case 'b': a.bias = optarg; break;
        case 's': if (add_line(a.out, &a.n_out, optarg) < 0) return 2; break;
        case 'a': a.strobe_active = optarg; break;
        case 'g': a.gadget = optarg; break;
        case 'u': a.udc = optarg; break;
        case 'o': a.clock_offset_s = atof(optarg); break;
        case 'd': a.clock_drift_ppm = atof(optarg); break;
        case 'h': usage(stdout); return 0;
        default: usage(stderr); return 2;
        }
    }
    if (!a.ffs || !a.chip_name || !a.n_in || optind < argc ||
        (strcmp(a.strobe_active, "high") && strcmp(a.strobe_active, "low"))) {
        usage(stderr);
        return 2;
    }
    a.mono0_ns = nc_mono_ns();
    pthread_mutex_init(&a.lock, NULL);
    pthread_cond_init(&a.cond, NULL);
    char path[512];
    snprintf(path, sizeof path, "%s/ep0", a.ffs);
    int ep0 = open(path, O_RDWR | O_CLOEXEC);
    if (ep0 < 0) {
        fprintf(stderr, "navcam-usb-adapter: %s: %s (is FunctionFS mounted there?)\n", path, strerror(errno));
        return 1;
    }
    if (lines_open(&a) < 0) {
        lines_close(&a);
        return 1;
    }
    if (write_descriptors(ep0) < 0)
        return 1;
    snprintf(path, sizeof path, "%s/ep1", a.ffs);
    ep_in = open(path, O_RDWR | O_CLOEXEC);
    snprintf(path, sizeof path, "%s/ep2", a.ffs);
    ep_out = open(path, O_RDWR | O_CLOEXEC);
    if (ep_in < 0 || ep_out < 0) {
        fprintf(stderr, "navcam-usb-adapter: %s/ep1, ep2: %s\n", a.ffs, strerror(errno));
        return 1;
    }
    int rc = serve(&a, ep0);
    lines_close(&a);
    return rc;
}
