/* trigger_gpio.c - a hardware trigger on a GPIO line through libgpiod 1.6,
 * with an optional strobe output line that is active while the sensor
 * exposes.
 *
 * The trigger line is requested for both edges; the emulator's gate applies
 * the activation edge and the debounce (trigger.h), so a client may change
 * the activation at run time. Each edge carries the kernel's event timestamp,
 * which on Linux >= 5.7 is CLOCK_MONOTONIC: the trigger time is when the line
 * changed, not when this thread woke up.
 *
 * The strobe follows the "exposure" control: the emulator passes every
 * exposure window (CLOCK_MONOTONIC) as it schedules the exposure, and this
 * driver's thread drives the line at the window's start and end (ppoll with
 * a nanosecond timeout, on the same thread that reads the edges).
 *
 * Options (the serve.trigger map): gpio_params below.
 */
#include <errno.h>
#include <gpiod.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "core/windows.h"
#include "emulator/trigger.h"

#define CONSUMER "navcam"

struct gpio_line {
    struct gpiod_chip *chip; /* owned unless shared with the trigger line */
    struct gpiod_line *line;
    char desc[160];          /* "gpiochip0 line 3 \"TRIG\"" for messages */
};

struct gpio_trig {
    struct nc_trigger_ctx ctx;
    struct gpio_line in, strobe;
    int have_strobe, strobe_active_low, strobe_on;
    int wake_fd;
    pthread_t thread;
    int running;
    atomic_int stop;
    pthread_mutex_t lock; /* the exposure windows */
    struct nc_windows win;
    unsigned long read_errors, strobe_errors;
    int warned_clock;
};

static int all_digits(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; s++)
        if (*s < '0' || *s > '9')
            return 0;
    return 1;
}

static const char *const biases[] = {"as_is", "disable", "pull_up", "pull_down", NULL};
static const char *const levels[] = {"high", "low", NULL};

static const struct nc_param strobe_params[] = {
    NC_P_STRING_REQUIRED("line", "name or offset of the strobe output line"),
    NC_P_STRING("chip", NULL, "its chip (default: the trigger line's chip)"),
    NC_P_ENUM("active", "high", levels, "the line's level during an exposure"),
    NC_P_END,
};

static const struct nc_param gpio_params[] = {
    NC_P_STRING_REQUIRED("line", "name or offset of the trigger input line (gpioinfo lists them)"),
    NC_P_STRING("chip", NULL, "gpiochipN, /dev/gpiochipN, a chip label or a number (without it `line` must be a name, searched on every chip)"),
    NC_P_ENUM("bias", "as_is", biases, "the input's pull resistor"),
    NC_P_MAP("strobe", strobe_params, "an output line active while the sensor exposes"),
    NC_P_END,
};

/* Find chip and line from the `line` and `chip` keys of opts (whose table is
 * params); `shared` is a chip already open that the line defaults to. */
static int find_line(struct nc_cfg_node *opts, const struct nc_param *params, struct gpiod_chip *shared,
                     struct gpio_line *out)
{
    const char *name = NULL, *chip = NULL;
    int rc;
    if ((rc = nc_param_string(opts, params, "line", &name)) < 0 || (rc = nc_param_string(opts, params, "chip", &chip)) < 0)
        return rc;
    struct nc_cfg_node *ln = nc_cfg_get(opts, "line");
    if (chip) {
        out->chip = gpiod_chip_open_lookup(chip);
        if (!out->chip) {
            const int err = errno;
            return nc_cfg_key_error(opts, "chip", "cannot open GPIO chip '%s': %s (%s)", chip, strerror(err),
                                    err == EACCES ? "udev/99-navcam.rules gives group gpio access: docs/setup.md"
                                                  : "gpiodetect lists the chips");
        }
    }
    struct gpiod_chip *c = out->chip ? out->chip : shared;
    if (all_digits(name)) {
        if (!c)
            return nc_cfg_error(ln, "a line offset needs `chip` (or use the line's name)");
        out->line = gpiod_chip_get_line(c, (unsigned)strtoul(name, NULL, 10));
        if (!out->line)
            return nc_cfg_error(ln, "GPIO chip %s has no line %s (it has %u lines)", gpiod_chip_name(c), name,
                                gpiod_chip_num_lines(c));
    } else if (c) {
        out->line = gpiod_chip_find_line(c, name);
        if (!out->line)
            return nc_cfg_error(ln, "GPIO chip %s has no line named '%s' (gpioinfo %s lists them)", gpiod_chip_name(c),
                                name, gpiod_chip_name(c));
    } else {
        errno = 0;
        out->line = gpiod_line_find(name); /* opens every chip: ENOENT when none has the line */
        const int err = errno;
        if (!out->line && err && err != ENOENT)
            return nc_cfg_error(ln, "cannot search the GPIO chips for a line named '%s': %s (%s)", name, strerror(err),
                                err == EACCES ? "a chip this user cannot open: give `chip`, or udev/99-navcam.rules "
                                                "gives group gpio access: docs/setup.md"
                                              : "gpiodetect lists the chips");
        if (!out->line)
            return nc_cfg_error(ln, "no GPIO chip has a line named '%s' (gpioinfo lists them)", name);
        out->chip = gpiod_line_get_chip(out->line);
    }
    const char *lname = gpiod_line_name(out->line);
    snprintf(out->desc, sizeof out->desc, "%s line %u%s%s%s", gpiod_chip_name(gpiod_line_get_chip(out->line)),
             gpiod_line_offset(out->line), lname ? " \"" : "", lname ? lname : "", lname ? "\"" : "");
    if (gpiod_line_is_used(out->line)) {
        const char *who = gpiod_line_consumer(out->line);
        return nc_cfg_error(ln, "GPIO %s is already in use by '%s'", out->desc, who ? who : "another consumer");
    }
    return 0;
}

static void release_line(struct gpio_line *l, struct gpiod_chip *shared)
{
    if (l->line)
        gpiod_line_release(l->line);
    if (l->chip && l->chip != shared)
        gpiod_chip_close(l->chip);
    memset(l, 0, sizeof *l);
}

static int open_lines(struct gpio_trig *g, struct nc_cfg_node *opts)
{
    static const int bias_flags[] = {0, GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE, GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP,
                                     GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN};
    int bias = 0, rc;
    struct nc_cfg_node *st = NULL;
    int low = 0;
    /* All options first, then the hardware. */
    if ((rc = nc_param_enum(opts, gpio_params, "bias", &bias)) < 0 ||
        (rc = nc_param_map(opts, gpio_params, "strobe", &st)) < 0 ||
        (st && (rc = nc_param_enum(st, strobe_params, "active", &low)) < 0))
        return rc;
    if ((rc = find_line(opts, gpio_params, NULL, &g->in)) < 0)
        return rc;
    if (gpiod_line_request_both_edges_events_flags(g->in.line, CONSUMER, bias_flags[bias]) < 0)
        return nc_cfg_key_error(opts, "line", "cannot request GPIO %s for edge events: %s", g->in.desc,
                                strerror(errno));
    if (st) {
        if ((rc = find_line(st, strobe_params, gpiod_line_get_chip(g->in.line), &g->strobe)) < 0)
            return rc;
        g->strobe_active_low = low;
        if (gpiod_line_request_output(g->strobe.line, CONSUMER, low) < 0)
            return nc_cfg_key_error(st, "line", "cannot request GPIO %s as an output: %s", g->strobe.desc,
                                    strerror(errno));
        g->have_strobe = 1;
    }
    g->wake_fd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (g->wake_fd < 0)
        return nc_error(-errno, "gpio trigger: eventfd: %s", strerror(errno));
    pthread_mutex_init(&g->lock, NULL);
    if (g->have_strobe)
        nc_log_info("trigger/gpio", "trigger on %s, strobe on %s (active %s)", g->in.desc, g->strobe.desc,
                    g->strobe_active_low ? "low" : "high");
    else
        nc_log_info("trigger/gpio", "trigger on %s", g->in.desc);
    return 0;
}

static void gpio_close(void *priv);

static int gpio_open(void *priv, struct nc_cfg_node *opts, const struct nc_trigger_ctx *ctx)
{
    struct gpio_trig *g = priv;
    g->ctx = *ctx;
    g->wake_fd = -1;
    int rc = open_lines(g, opts);
    if (rc < 0)
        gpio_close(g);
    return rc;
}

static void set_strobe(struct gpio_trig *g, int on)
{
    if (on == g->strobe_on)
        return;
    if (gpiod_line_set_value(g->strobe.line, on ^ g->strobe_active_low) < 0) {
        if (g->strobe_errors++ == 0) /* once: a chip that is gone fails every window (counted, closing says) */
            nc_log_error("trigger/gpio", "strobe %s: %s", g->strobe.desc, strerror(errno));
        return;
    }
    g->strobe_on = on;
}

static void read_edges(struct gpio_trig *g, int fd)
{
    struct gpiod_line_event ev[16];
    int n = gpiod_line_event_read_fd_multiple(fd, ev, 16);
    if (n < 0) {
        if (errno != EAGAIN && g->read_errors++ == 0)
            nc_log_error("trigger/gpio", "reading events of %s: %s", g->in.desc, strerror(errno));
        return;
    }
    int64_t now = nc_mono_ns();
    for (int i = 0; i < n; i++) {
        struct nc_trigger_edge e = {.mono_ns = (int64_t)ev[i].ts.tv_sec * 1000000000 + ev[i].ts.tv_nsec,
                                    .rising = ev[i].event_type == GPIOD_LINE_EVENT_RISING_EDGE};
        /* Kernels before 5.7 stamp events with CLOCK_REALTIME: then the
         * read time is the best CLOCK_MONOTONIC estimate there is. */
        if (e.mono_ns > now || now - e.mono_ns > 3600 * (int64_t)1000000000) {
            if (!g->warned_clock++)
                nc_log_warn("trigger/gpio", "event timestamps of %s are not CLOCK_MONOTONIC (kernel "
                            "older than 5.7?); using the time events are read", g->in.desc);
            e.mono_ns = now;
        }
        g->ctx.fire(g->ctx.sink, &e);
    }
}

static void *gpio_thread(void *arg)
{
    struct gpio_trig *g = arg;
    int efd = gpiod_line_event_get_fd(g->in.line);
    while (!atomic_load(&g->stop)) {
        int64_t now = nc_mono_ns(), next = INT64_MAX;
        if (g->have_strobe) {
            uint32_t want;
            pthread_mutex_lock(&g->lock);
            next = nc_windows_plan(&g->win, now, &want);
            pthread_mutex_unlock(&g->lock);
            set_strobe(g, want & 1);
        }
        struct pollfd p[2] = {{.fd = efd, .events = POLLIN}, {.fd = g->wake_fd, .events = POLLIN}};
        struct timespec ts;
        if (ppoll(p, 2, nc_windows_timeout(next, now, &ts), NULL) < 0 && errno != EINTR) {
            nc_log_error("trigger/gpio", "ppoll: %s", strerror(errno));
            break;
        }
        if (p[1].revents & POLLIN) {
            uint64_t v;
            if (read(g->wake_fd, &v, sizeof v) < 0 && errno != EAGAIN)
                break;
        }
        if (p[0].revents & POLLIN)
            read_edges(g, efd);
        else if (p[0].revents & (POLLERR | POLLHUP | POLLNVAL)) {
            /* the chip is gone (a USB GPIO expander unplugged, a gpio-sim chip removed): the kernel says so on
             * every poll from now on; no edge can come, so the line is no longer polled */
            nc_log_error("trigger/gpio", "%s: the GPIO chip is gone (unplugged or removed): no more edges from it "
                         "until navcam serve is restarted", g->in.desc);
            efd = -1;
        }
    }
    if (g->have_strobe)
        set_strobe(g, 0);
    return NULL;
}

static void wake(struct gpio_trig *g)
{
    uint64_t one = 1;
    if (write(g->wake_fd, &one, sizeof one) < 0 && errno != EAGAIN)
        nc_log_error("trigger/gpio", "eventfd: %s", strerror(errno));
}

static int gpio_start(void *priv)
{
    struct gpio_trig *g = priv;
    int err = pthread_create(&g->thread, NULL, gpio_thread, g);
    if (err)
        return nc_error(-err, "gpio trigger: cannot start its thread: %s", strerror(err));
    g->running = 1;
    return 0;
}

static void gpio_stop(void *priv)
{
    struct gpio_trig *g = priv;
    if (!g->running)
        return;
    atomic_store(&g->stop, 1);
    wake(g);
    pthread_join(g->thread, NULL);
    g->running = 0;
}

/* "exposure": a struct nc_trigger_window to drive the strobe for. */
static int gpio_control(void *priv, const char *request, void *arg)
{
    struct gpio_trig *g = priv;
    if (strcmp(request, "exposure") || !g->have_strobe)
        return NC_EUNSUPPORTED;
    const struct nc_trigger_window *w = arg;
    pthread_mutex_lock(&g->lock);
    nc_windows_add(&g->win, w->start_mono_ns, w->end_mono_ns, 0); /* a storm stretches the newest window */
    pthread_mutex_unlock(&g->lock);
    wake(g);
    return 0;
}

static void gpio_close(void *priv)
{
    struct gpio_trig *g = priv;
    gpio_stop(g);
    if (g->have_strobe && (g->win.missed || g->read_errors || g->strobe_errors))
        nc_log_info("trigger/gpio", "%lu strobes, %lu exposure windows passed before the strobe could be "
                    "driven, %lu event read errors, %lu strobe line writes failed", g->win.started, g->win.missed,
                    g->read_errors, g->strobe_errors);
    struct gpiod_chip *shared = g->in.line ? gpiod_line_get_chip(g->in.line) : NULL;
    release_line(&g->strobe, shared);
    release_line(&g->in, NULL);
    if (g->wake_fd >= 0) {
        close(g->wake_fd);
        pthread_mutex_destroy(&g->lock);
    }
}

const struct nc_trigger_driver nc_trigger_gpio = {
    .name = "gpio",
    .description = "a GPIO line through libgpiod (kernel edge timestamps), with an optional strobe output",
    .caps = NC_TRIGGER_CAP_LINE,
    .priv_size = sizeof(struct gpio_trig),
    .params = gpio_params,
    .open = gpio_open,
    .start = gpio_start,
    .stop = gpio_stop,
    .control = gpio_control,
    .close = gpio_close,
};
