/* lines.c - the adapter's GPIO side: input edges with the kernel's
 * timestamps become EDGE messages; strobe windows from the host drive the
 * outputs. One thread, sleeping in ppoll on the inputs' event descriptor
 * with a timeout at the next strobe change.
 *
 * libgpiod 1.6 (Debian 12) finds the chip and the lines and drives the
 * outputs. The inputs' edges are read through the kernel's v2 line uAPI
 * (Linux >= 5.10), which libgpiod 1.6 predates: its event buffer can hold
 * 1024 edges instead of v1's 16, and every event carries the line's
 * sequence number, so edges the kernel had to drop are counted exactly
 * rather than guessed (libgpiod 2 wraps the same uAPI; Debian 12 lacks it).
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* ppoll, signalfd (the CMake build defines it for every file) */
#endif
#include <errno.h>
#include <fcntl.h>
#include <gpiod.h>
#include <linux/gpio.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include "adapter.h"
#include "core/clock.h"

#define CONSUMER "navcam-usb-adapter"

static struct gpiod_line *find(struct adapter *a, const char *name)
{
    char *end;
    unsigned long off = strtoul(name, &end, 10);
    struct gpiod_line *l = *name && !*end ? gpiod_chip_get_line(a->chip, (unsigned)off) : gpiod_chip_find_line(a->chip, name);
    if (!l)
        fprintf(stderr, "navcam-usb-adapter: GPIO chip %s has no line '%s' (gpioinfo %s lists them)\n",
                gpiod_chip_name(a->chip), name, gpiod_chip_name(a->chip));
    return l;
}

int lines_open(struct adapter *a)
{
    static const char *const bias_names[] = {"as_is", "disable", "pull_up", "pull_down"};
    static const int bias_flags[] = {0, GPIO_V2_LINE_FLAG_BIAS_DISABLED, GPIO_V2_LINE_FLAG_BIAS_PULL_UP,
                                     GPIO_V2_LINE_FLAG_BIAS_PULL_DOWN};
    int bias = -1;
    for (int i = 0; i < 4; i++)
        if (!strcmp(a->bias, bias_names[i]))
            bias = bias_flags[i];
    if (bias < 0) {
        fprintf(stderr, "navcam-usb-adapter: --bias %s: expected as_is, disable, pull_up or pull_down\n", a->bias);
        return -1;
    }
    a->chip = gpiod_chip_open_lookup(a->chip_name);
    if (!a->chip) {
        fprintf(stderr, "navcam-usb-adapter: cannot open GPIO chip '%s': %s (gpiodetect lists them)\n", a->chip_name,
                strerror(errno));
        return -1;
    }
    struct gpio_v2_line_request req;
    memset(&req, 0, sizeof req);
    for (int i = 0; i < a->n_in; i++) {
        struct gpiod_line *l = find(a, a->in[i].name);
        if (!l)
            return -1;
        if (gpiod_line_is_used(l)) {
            fprintf(stderr, "navcam-usb-adapter: input %s is in use by '%s'\n", a->in[i].name,
                    gpiod_line_consumer(l) ? gpiod_line_consumer(l) : "another consumer");
            return -1;
        }
        req.offsets[i] = gpiod_line_offset(l);
    }
    snprintf(req.consumer, sizeof req.consumer, "%s", CONSUMER);
    req.num_lines = (unsigned)a->n_in;
    req.event_buffer_size = 1024; /* the kernel's cap: 16 per line of GPIO_V2_LINES_MAX */
    req.config.flags = GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_EDGE_RISING | GPIO_V2_LINE_FLAG_EDGE_FALLING | bias;
    char dev[64];
    snprintf(dev, sizeof dev, "/dev/%s", gpiod_chip_name(a->chip));
    int cfd = open(dev, O_RDWR | O_CLOEXEC);
    if (cfd < 0 || ioctl(cfd, GPIO_V2_GET_LINE_IOCTL, &req) < 0) {
        fprintf(stderr, "navcam-usb-adapter: %s: requesting the inputs for edge events: %s\n", dev, strerror(errno));
        if (cfd >= 0)
            close(cfd);
        return -1;
    }
    close(cfd);
    a->events_fd = req.fd;
    struct gpio_v2_line_values v = {.mask = (1ull << a->n_in) - 1};
    if (ioctl(a->events_fd, GPIO_V2_LINE_GET_VALUES_IOCTL, &v) < 0)
        v.bits = 0;
    for (int i = 0; i < a->n_in; i++)
        a->in[i].offset = req.offsets[i], a->in[i].last_level = (int)(v.bits >> i & 1);
    int low = !strcmp(a->strobe_active, "low");
    for (int i = 0; i < a->n_out; i++) {
        struct line *l = &a->out[i];
        if (!(l->line = find(a, l->name)))
            return -1;
        if (gpiod_line_request_output(l->line, CONSUMER, low) < 0) {
            fprintf(stderr, "navcam-usb-adapter: strobe %s: cannot request it as an output: %s\n", l->name,
                    strerror(errno));
            l->line = NULL;
            return -1;
        }
        l->last_level = 0; /* inactive */
    }
    a->wake_fd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    return a->wake_fd < 0 ? -1 : 0;
}

static void read_edges(struct adapter *a)
{
    struct gpio_v2_line_event ev[64];
    ssize_t n = read(a->events_fd, ev, sizeof ev);
    if (n < (ssize_t)sizeof ev[0])
        return;
    pthread_mutex_lock(&a->lock);
    for (size_t k = 0; k < (size_t)n / sizeof ev[0]; k++) {
        int i = 0;
        while (i < a->n_in - 1 && a->in[i].offset != ev[k].offset)
            i++;
        struct line *l = &a->in[i];
        /* The line's sequence number counts every edge the kernel saw,
         * including those it dropped for want of buffer space. */
        uint32_t missed = l->seqno ? ev[k].line_seqno - l->seqno - 1 : ev[k].line_seqno - 1;
        int level = ev[k].id == GPIO_V2_LINE_EVENT_RISING_EDGE;
        /* Edges faster than the kernel's interrupt thread merge before any
         * sequence number is given, and the kernel reads a both-edge
         * event's direction when that thread runs: an edge to the level the
         * line already had marks either (its level is then not to be
         * trusted). */
        int repeat = !missed && level == l->last_level;
        l->seqno = ev[k].line_seqno;
        l->last_level = level;
        struct nc_ut_msg m = {.type = NC_UT_EDGE, .line = (uint8_t)i, .level = (uint8_t)level,
                              .flags = (uint8_t)((missed ? NC_UT_EDGE_AFTER_MISSED : 0) |
                                                 (repeat ? NC_UT_EDGE_LEVEL_REPEAT : 0)),
                              .arg = missed, .t0_ns = adapter_dev_ns(a, (int64_t)ev[k].timestamp_ns)};
        a->edges++;
        a->missed += missed;
        a->level_repeats += (unsigned long)repeat;
        adapter_push(a, &m);
    }
    pthread_cond_broadcast(&a->cond);
    pthread_mutex_unlock(&a->lock);
}

void lines_strobe(struct adapter *a, int line, int64_t start_dev_ns, int64_t end_dev_ns)
{
    if (line >= a->n_out)
        return;
    int64_t s = adapter_mono_ns(a, start_dev_ns), e = adapter_mono_ns(a, end_dev_ns), now = nc_mono_ns();
    pthread_mutex_lock(&a->lock);
    if (s < now)
        a->strobes_late++; /* the window had begun when it arrived: the strobe starts now */
    nc_windows_add(&a->win, s, e, line);
    pthread_mutex_unlock(&a->lock);
    uint64_t one = 1;
    if (write(a->wake_fd, &one, sizeof one) < 0 && errno != EAGAIN)
        perror("navcam-usb-adapter: eventfd");
}

void *lines_thread(void *arg)
{
    struct adapter *a = arg;
    struct pollfd p[2] = {{.fd = a->events_fd, .events = POLLIN}, {.fd = a->wake_fd, .events = POLLIN}};
    while (!atomic_load(&a->stop)) {
        int64_t now = nc_mono_ns();
        uint32_t want;
        pthread_mutex_lock(&a->lock);
        int64_t next = nc_windows_plan(&a->win, now, &want);
        pthread_mutex_unlock(&a->lock);
        for (int i = 0; i < a->n_out; i++) {
            int on = want >> i & 1;
            if (on != a->out[i].last_level &&
                gpiod_line_set_value(a->out[i].line, on ^ !strcmp(a->strobe_active, "low")) == 0)
                a->out[i].last_level = on;
        }
        struct timespec ts;
        if (ppoll(p, 2, nc_windows_timeout(next, now, &ts), NULL) < 0 && errno != EINTR) {
            perror("navcam-usb-adapter: ppoll");
            break;
        }
        if (p[1].revents & POLLIN) {
            uint64_t v;
            if (read(a->wake_fd, &v, sizeof v) < 0 && errno != EAGAIN)
                break;
        }
        if (p[0].revents & POLLIN)
            read_edges(a);
        else if (p[0].revents & (POLLERR | POLLHUP | POLLNVAL)) { /* the chip went away: said once, not polled */
            fprintf(stderr, "navcam-usb-adapter: the GPIO chip's events ended (the chip removed?): no more edges\n");
            p[0].fd = -1;
        }
    }
    for (int i = 0; i < a->n_out; i++)
        gpiod_line_set_value(a->out[i].line, !strcmp(a->strobe_active, "low"));
    return NULL;
}

void lines_close(struct adapter *a)
{
    if (a->events_fd >= 0)
        close(a->events_fd);
    for (int i = 0; i < a->n_out; i++)
        if (a->out[i].line)
            gpiod_line_release(a->out[i].line);
    if (a->chip)
        gpiod_chip_close(a->chip);
    if (a->wake_fd >= 0)
        close(a->wake_fd);
}
