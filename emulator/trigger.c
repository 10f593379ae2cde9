/* trigger.c - opening trigger drivers, and the gate every edge passes
 * between a driver and the emulator: activation edge, debounce, delay
 * (trigger.h). Must not know any driver. */
#include "emulator/trigger.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

static const char *const activations[] = {"rising_edge", "falling_edge", "any_edge", NULL};

const struct nc_param nc_trigger_common_params[] = {
    NC_P_STRING("driver", NULL, "the trigger source (`navcam serve --help` lists them)"),
    NC_P_ENUM("activation", "rising_edge", activations, "which line edge triggers (line sources only)"),
    NC_P_DOUBLE("delay_s", "0", 0, 10, "s", "from the edge to the start of the exposure"),
    NC_P_DOUBLE("debounce_s", "0", 0, 10, "s", "edges this soon after an accepted one are ignored (line sources only)"),
    NC_P_END,
};

int nc_trigger_gate_accept(struct nc_trigger_gate *g, const struct nc_trigger_edge *edge)
{
    g->edges++;
    if ((g->activation == NC_TRIGGER_RISING && !edge->rising) || (g->activation == NC_TRIGGER_FALLING && edge->rising)) {
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
    g->accepted++;
    return 1;
}

/* Every edge of the driver: through the gate, then to the emulator. */
static void on_edge(void *sink, const struct nc_trigger_edge *edge)
{
    struct nc_trigger *t = sink;
    pthread_mutex_lock(&t->lock);
    int ok = t->enabled && nc_trigger_gate_accept(&t->gate, edge);
    int64_t delay = t->gate.delay_ns;
    pthread_mutex_unlock(&t->lock);
    if (ok) {
        struct nc_trigger_event ev = {.edge_mono_ns = edge->mono_ns, .start_mono_ns = edge->mono_ns + delay};
        t->sink(t->sink_arg, &ev);
    }
}

int nc_trigger_check(const struct nc_trigger_driver *drv, struct nc_cfg_node *opts)
{
    char what[96];
    snprintf(what, sizeof what, "trigger driver '%s'", drv->name);
    const struct nc_param *const tables[] = {nc_trigger_common_params, drv->params};
    int rc = nc_params_check(opts, tables, 2, what);
    if (rc >= 0)
        rc = nc_params_values(opts, tables, 2);
    return rc < 0 || !drv->check ? rc : drv->check(opts);
}

int nc_trigger_open(struct nc_trigger *t, const struct nc_trigger_driver *drv, struct nc_cfg_node *opts,
                    nc_trigger_sink_fn sink, void *arg)
{
    memset(t, 0, sizeof *t);
    int rc, act = NC_TRIGGER_RISING;
    double delay_s = 0, debounce_s = 0;
    if ((rc = nc_trigger_check(drv, opts)) < 0 ||
        (rc = nc_param_enum(opts, nc_trigger_common_params, "activation", &act)) < 0 ||
        (rc = nc_param_double(opts, nc_trigger_common_params, "delay_s", &delay_s)) < 0 ||
        (rc = nc_param_double(opts, nc_trigger_common_params, "debounce_s", &debounce_s)) < 0)
        return rc;
    t->drv = drv;
    t->sink = sink;
    t->sink_arg = arg;
    t->enabled = 1;
    t->gate.activation = (enum nc_trigger_activation)act;
    t->gate.delay_ns = llround(delay_s * 1e9);
    t->gate.debounce_ns = llround(debounce_s * 1e9);
    t->priv = calloc(1, drv->priv_size ? drv->priv_size : 1);
    if (!t->priv)
        return nc_error(-ENOMEM, "out of memory");
    pthread_mutex_init(&t->lock, NULL);
    t->ctx = (struct nc_trigger_ctx){.fire = on_edge, .sink = t};
    if ((rc = drv->open(t->priv, opts, &t->ctx)) < 0) {
        free(t->priv);
        pthread_mutex_destroy(&t->lock);
        memset(t, 0, sizeof *t);
    }
    return rc;
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

void nc_trigger_enable(struct nc_trigger *t, int enabled)
{
    pthread_mutex_lock(&t->lock);
    t->enabled = enabled;
    pthread_mutex_unlock(&t->lock);
}

void nc_trigger_set_gate(struct nc_trigger *t, enum nc_trigger_activation activation, int64_t delay_ns)
{
    pthread_mutex_lock(&t->lock);
    t->gate.activation = activation;
    t->gate.delay_ns = delay_ns;
    pthread_mutex_unlock(&t->lock);
}

enum nc_trigger_activation nc_trigger_activation(struct nc_trigger *t)
{
    pthread_mutex_lock(&t->lock);
    enum nc_trigger_activation a = t->gate.activation;
    pthread_mutex_unlock(&t->lock);
    return a;
}

int64_t nc_trigger_delay_ns(struct nc_trigger *t)
{
    pthread_mutex_lock(&t->lock);
    int64_t d = t->gate.delay_ns;
    pthread_mutex_unlock(&t->lock);
    return d;
}

void nc_trigger_counts(struct nc_trigger *t, struct nc_trigger_counts *out)
{
    pthread_mutex_lock(&t->lock);
    *out = (struct nc_trigger_counts){t->gate.edges, t->gate.wrong_edge, t->gate.debounced, t->gate.accepted};
    pthread_mutex_unlock(&t->lock);
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
