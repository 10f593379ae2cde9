/* trigger.c - opening trigger drivers, and the gate every edge passes:
 * activation edge, debounce, delay (trigger.h). Must not know any driver. */
#include "trigger.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "driver.h"
#include "error.h"

int64_t nc_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

const struct nc_trigger_driver *nc_trigger_find(const char *name)
{
    return nc__driver_find((const void *const *)nc_trigger_drivers, name);
}

int nc_trigger_gate_accept(struct nc_trigger_gate *g, const struct nc_trigger_edge *edge)
{
    g->edges++;
    if (!edge->command) {
        if ((g->activation == NC_TRIGGER_RISING && !edge->rising) ||
            (g->activation == NC_TRIGGER_FALLING && edge->rising)) {
            g->wrong_edge++;
            return 0;
        }
        /* Lock-out debounce: bounce after an accepted edge is ignored. */
        if (g->debounce_ns > 0 && g->have_last && edge->mono_ns - g->last_ns < g->debounce_ns) {
            g->debounced++;
            return 0;
        }
        g->last_ns = edge->mono_ns;
        g->have_last = 1;
    }
    g->accepted++;
    return 1;
}

int nc_trigger_open(struct nc_trigger *t, struct nc_cfg_node *opts, const struct nc_trigger_ctx *ctx)
{
    static const char *const acts[] = {"rising_edge", "falling_edge", "any_edge", NULL};
    memset(t, 0, sizeof *t);
    int rc, act = NC_TRIGGER_RISING;
    double delay_s = 0, debounce_s = 0;
    t->drv = nc__driver_select(opts, "trigger driver", (const void *const *)nc_trigger_drivers, &rc);
    if (!t->drv)
        return rc;
    if ((rc = nc_cfg_enum(opts, "activation", acts, &act)) < 0 ||
        (rc = nc_cfg_double(opts, "delay_s", 0, 10, &delay_s)) < 0 ||
        (rc = nc_cfg_double(opts, "debounce_s", 0, 10, &debounce_s)) < 0)
        return rc;
    if (!(t->drv->caps & NC_TRIGGER_CAP_LINE) && (nc_cfg_get(opts, "activation") || nc_cfg_get(opts, "debounce_s")))
        return nc_cfg_error(opts, "trigger driver '%s' gives commands, not line edges: activation and debounce_s do "
                                  "not apply",
                            t->drv->name);
    t->gate.activation = (enum nc_trigger_activation)act;
    t->gate.delay_ns = llround(delay_s * 1e9);
    t->gate.debounce_ns = llround(debounce_s * 1e9);
    t->priv = calloc(1, t->drv->priv_size ? t->drv->priv_size : 1);
    if (!t->priv)
        return nc_error(-ENOMEM, "out of memory");
    if ((rc = t->drv->open(t->priv, opts, ctx)) < 0) {
        free(t->priv);
        t->priv = NULL;
        return rc;
    }
    pthread_mutex_init(&t->lock, NULL);
    return 0;
}

int nc_trigger_start(struct nc_trigger *t)
{
    int rc = t->drv->start ? t->drv->start(t->priv) : 0;
    t->started = rc >= 0;
    return rc;
}

void nc_trigger_stop(struct nc_trigger *t)
{
    if (t->started && t->drv->stop)
        t->drv->stop(t->priv);
    t->started = 0;
}

int nc_trigger_control(struct nc_trigger *t, const char *request, void *arg)
{
    if (!t->drv->control)
        return NC_EUNSUPPORTED;
    return t->drv->control(t->priv, request, arg);
}

int nc_trigger_accept(struct nc_trigger *t, const struct nc_trigger_edge *edge)
{
    pthread_mutex_lock(&t->lock);
    int ok = nc_trigger_gate_accept(&t->gate, edge);
    pthread_mutex_unlock(&t->lock);
    return ok;
}

void nc_trigger_close(struct nc_trigger *t)
{
    if (!t->drv || !t->priv)
        return;
    nc_trigger_stop(t);
    t->drv->close(t->priv);
    free(t->priv);
    pthread_mutex_destroy(&t->lock);
    memset(t, 0, sizeof *t);
}
