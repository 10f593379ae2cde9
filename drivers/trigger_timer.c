/* trigger_timer.c - the timer trigger: a pulse train on CLOCK_MONOTONIC, a
 * rising edge every 1/rate_hz and a falling edge pulse_width_s later, on a
 * fixed grid (no drift). Free-run mode uses it at serve.frame_rate_hz. The
 * edge times are the grid times, as a hardware timestamp would be. The
 * "rate_hz" control (a double *) changes the rate at run time: the grid
 * restarts one new period after the change. */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <string.h>
#include <time.h>

#include "core/clock.h"
#include "core/error.h"
#include "emulator/trigger.h"

struct timer {
    struct nc_trigger_ctx ctx;
    int64_t period_ns, width_ns;
    double rate_hz; /* the grid: edge k at start + k / rate_hz, rounded to the nanosecond, never summed */
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t cond; /* on CLOCK_MONOTONIC, so that stop() wakes the sleeper */
    int stop, running;
    unsigned restart; /* bumped by a rate change */
};

/* The default pulse: 1 ms, or half the period when that is shorter. */
static int64_t default_width(int64_t period_ns) { return period_ns / 2 < 1000000 ? period_ns / 2 : 1000000; }

static const struct nc_param timer_params[] = {
    NC_P_DOUBLE("rate_hz", "10", 1e-3, 10000, "Hz", "pulses per second"),
    NC_P_DOUBLE("pulse_width_s", NULL, 1e-6, 1000, "s", "from the rising to the falling edge, shorter than the period (default 1 ms, or half the period when that is shorter)"),
    NC_P_END,
};

/* The period and pulse width of opts (NULL: the defaults): 0, or < 0 if
 * the pulse is not shorter than the period. Before the scene is built
 * (nc_trigger_check), and at open. */
static int timer_times(struct nc_cfg_node *opts, double *rate_hz, int64_t *period_ns, int64_t *width_ns)
{
    double width_s = -1;
    int rc;
    if ((rc = nc_param_double(opts, timer_params, "rate_hz", rate_hz)) < 0 ||
        (rc = nc_param_double(opts, timer_params, "pulse_width_s", &width_s)) < 0)
        return rc;
    *period_ns = llround(1e9 / *rate_hz);
    *width_ns = width_s > 0 ? llround(width_s * 1e9) : default_width(*period_ns);
    if (*width_ns >= *period_ns)
        return nc_cfg_key_error(opts, "pulse_width_s", "pulse_width_s must be shorter than the period 1/rate_hz = %g s",
                                *period_ns * 1e-9);
    return 0;
}

static int timer_check(struct nc_cfg_node *opts)
{
    double rate_hz;
    int64_t period_ns, width_ns;
    return timer_times(opts, &rate_hz, &period_ns, &width_ns);
}

static int timer_open(void *priv, struct nc_cfg_node *opts, const struct nc_trigger_ctx *ctx)
{
    struct timer *t = priv;
    int rc = timer_times(opts, &t->rate_hz, &t->period_ns, &t->width_ns);
    if (rc < 0)
        return rc;
    t->ctx = *ctx;
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&t->cond, &ca);
    pthread_condattr_destroy(&ca);
    pthread_mutex_init(&t->lock, NULL);
    return 0;
}

/* Sleep until an absolute CLOCK_MONOTONIC time: 1 when reached, 0 when
 * stopped, -1 when the rate changed meanwhile. */
static int sleep_until(struct timer *t, int64_t at, unsigned restart)
{
    struct timespec ts = {(time_t)(at / 1000000000), (long)(at % 1000000000)};
    pthread_mutex_lock(&t->lock);
    while (!t->stop && t->restart == restart && pthread_cond_timedwait(&t->cond, &t->lock, &ts) != ETIMEDOUT)
        ;
    int go = t->stop ? 0 : t->restart == restart ? 1 : -1;
    pthread_mutex_unlock(&t->lock);
    return go;
}

static void *timer_thread(void *arg)
{
    struct timer *t = arg;
    for (;;) {
        pthread_mutex_lock(&t->lock);
        unsigned restart = t->restart;
        const int64_t width = t->width_ns, start = nc_mono_ns();
        const double period = 1e9 / t->rate_hz; /* ns, not rounded: 60 Hz stays 60 Hz for hours */
        pthread_mutex_unlock(&t->lock);
        int go = 1;
        for (int64_t k = 1; go == 1; k++) {
            const int64_t next = start + llround((double)k * period);
            struct nc_trigger_edge rise = {.mono_ns = next, .rising = 1};
            struct nc_trigger_edge fall = {.mono_ns = next + width, .rising = 0};
            if ((go = sleep_until(t, rise.mono_ns, restart)) == 1)
                t->ctx.fire(t->ctx.sink, &rise);
            if (go == 1 && (go = sleep_until(t, fall.mono_ns, restart)) == 1)
                t->ctx.fire(t->ctx.sink, &fall);
        }
        if (go == 0)
            return NULL;
    }
}

static int timer_control(void *priv, const char *request, void *arg)
{
    struct timer *t = priv;
    if (strcmp(request, "rate_hz"))
        return NC_EUNSUPPORTED;
    double hz = *(const double *)arg;
    if (!(hz >= 1e-3 && hz <= 10000))
        return nc_error(NC_ERANGE, "timer trigger: rate %g Hz outside [0.001, 10000]", hz);
    pthread_mutex_lock(&t->lock);
    t->rate_hz = hz;
    t->period_ns = llround(1e9 / hz);
    if (t->width_ns >= t->period_ns)
        t->width_ns = default_width(t->period_ns);
    t->restart++;
    pthread_cond_broadcast(&t->cond);
    pthread_mutex_unlock(&t->lock);
    return 0;
}

static int timer_start(void *priv)
{
    struct timer *t = priv;
    int err = pthread_create(&t->thread, NULL, timer_thread, t);
    if (err)
        return nc_error(-err, "timer trigger: cannot start its thread: %s", strerror(err));
    t->running = 1;
    return 0;
}

static void timer_stop(void *priv)
{
    struct timer *t = priv;
    if (!t->running)
        return;
    pthread_mutex_lock(&t->lock);
    t->stop = 1;
    pthread_cond_broadcast(&t->cond);
    pthread_mutex_unlock(&t->lock);
    pthread_join(t->thread, NULL);
    t->running = 0;
}

static void timer_close(void *priv)
{
    struct timer *t = priv;
    timer_stop(t);
    pthread_cond_destroy(&t->cond);
    pthread_mutex_destroy(&t->lock);
}

const struct nc_trigger_driver nc_trigger_timer = {
    .name = "timer",
    .description = "a pulse train on the CLOCK_MONOTONIC grid (a pulse generator)",
    .caps = NC_TRIGGER_CAP_LINE,
    .priv_size = sizeof(struct timer),
    .params = timer_params,
    .check = timer_check,
    .open = timer_open,
    .start = timer_start,
    .stop = timer_stop,
    .control = timer_control,
    .close = timer_close,
};
