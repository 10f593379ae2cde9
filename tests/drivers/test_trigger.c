/* test_trigger.c - the trigger gate (activation edge, lock-out debounce) on
 * hand-made edge sequences, and the timer trigger driver through the
 * registry and the gate: edges lie exactly on the period grid with the
 * configured pulse width, the gate's delay moves the exposure start, the
 * activation filters edges, and stop() returns at once even between edges
 * many seconds apart. Configuration errors name the key. */
#include <stdatomic.h>
#include <string.h>
#include <time.h>

#include "core/config.h"
#include "core/error.h"
#include "drivers/registry.h"
#include "emulator/trigger.h"
#include "testutil.h"

#define MS 1000000LL

static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static int gate_run(enum nc_trigger_activation act, int64_t debounce_ns, const struct nc_trigger_edge *e, int n,
                    int *accepted)
{
    struct nc_trigger_gate g = {.activation = act, .debounce_ns = debounce_ns};
    int k = 0;
    for (int i = 0; i < n; i++)
        if (nc_trigger_gate_accept(&g, &e[i]))
            accepted[k++] = i;
    return k;
}

static void test_gate(void)
{
    /* A pulse train 10 ms apart, 2 ms wide, whose first rising edge bounces
     * three times within 0.3 ms. */
    struct nc_trigger_edge e[] = {
        {0, 1},       {100000, 0}, {200000, 1}, {300000, 0}, {310000, 1},
        {2 * MS, 0},  {10 * MS, 1}, {12 * MS, 0}, {20 * MS, 1}, {22 * MS, 0},
    };
    int n = (int)(sizeof e / sizeof e[0]), acc[16];
    int k = gate_run(NC_TRIGGER_RISING, 0, e, n, acc);
    CHECK(k == 5, "rising, no debounce: %d edges accepted, want every rising edge (5)", k);
    k = gate_run(NC_TRIGGER_RISING, 1 * MS, e, n, acc);
    CHECK(k == 3 && acc[0] == 0 && acc[1] == 6 && acc[2] == 8, "rising, 1 ms debounce: %d accepted (want 0, 6, 8)", k);
    /* Falling: the bounce's first falling edge opens the lock-out; the
     * pulse's real end, 1.9 ms later, is outside it. */
    k = gate_run(NC_TRIGGER_FALLING, 1 * MS, e, n, acc);
    CHECK(k == 4 && acc[0] == 1 && acc[1] == 5 && acc[2] == 7 && acc[3] == 9,
          "falling, 1 ms debounce: %d accepted (want 1, 5, 7, 9)", k);
    k = gate_run(NC_TRIGGER_ANY, 1 * MS, e, n, acc);
    CHECK(k == 6 && acc[1] == 5 && acc[2] == 6, "any edge, 1 ms debounce: %d accepted (want 0, 5, 6, 7, 8, 9)", k);
    /* Counters add up. */
    struct nc_trigger_gate g = (struct nc_trigger_gate){.activation = NC_TRIGGER_RISING, .debounce_ns = 1 * MS};
    for (int i = 0; i < n; i++)
        nc_trigger_gate_accept(&g, &e[i]);
    CHECK(g.edges == 10 && g.wrong_edge == 5 && g.debounced == 2 && g.accepted == 3,
          "counters: edges %lu wrong %lu debounced %lu accepted %lu", g.edges, g.wrong_edge, g.debounced, g.accepted);
}

/* Events recorded by the timer test's sink: what passed the gate. */
struct rec {
    struct nc_trigger_event e[64];
    int64_t fired_at[64];
    atomic_int n;
};

static void record(void *sink, const struct nc_trigger_event *ev)
{
    struct rec *r = sink;
    int i = atomic_load(&r->n);
    if (i < 64) {
        r->e[i] = *ev;
        r->fired_at[i] = now_ns();
        atomic_store(&r->n, i + 1);
    }
}

/* A trigger from YAML through this build's registry, as `navcam serve` opens one. */
static int open_yaml(struct nc_cfg *cfg, struct nc_trigger *t, const char *yaml, struct rec *r)
{
    memset(t, 0, sizeof *t);
    nc_cfg_init(cfg);
    int rc = nc_cfg_load_string(cfg, yaml, "trigger.yaml");
    const struct nc_trigger_driver *d = NULL;
    if (rc >= 0)
        d = nc_registry_select_trigger(&nc_drivers, cfg->root, NULL, NULL, &rc);
    if (d)
        rc = nc_trigger_open(t, d, cfg->root, record, r);
    return rc;
}

/* open_yaml, which must succeed. */
static int open_ok(struct nc_cfg *cfg, struct nc_trigger *t, const char *yaml, struct rec *r)
{
    int rc = open_yaml(cfg, t, yaml, r);
    CHECK(rc == 0, "open: %s", nc_errmsg());
    return rc;
}

/* Run trigger t until r holds at least n edges. */
static void run_until(struct nc_trigger *t, struct rec *r, int n)
{
    CHECK(nc_trigger_start(t) == 0, "start: %s", nc_errmsg());
    while (atomic_load(&r->n) < n)
        nanosleep(&(struct timespec){0, 1000000}, NULL);
    nc_trigger_stop(t);
}

static void test_timer(void)
{
    struct nc_cfg cfg;
    struct nc_trigger t;
    static struct rec r;
    /* Every edge passes (any_edge): rising on the 5 ms grid, falling 1 ms later. */
    if (open_ok(&cfg, &t, "driver: timer\nrate_hz: 200\npulse_width_s: 0.001\nactivation: any_edge\n"
                "delay_s: 0.004\n", &r) < 0)
        return;
    CHECK(nc_cfg_check_unused(&cfg) == 0, "timer options left unread: %s", nc_errmsg());
    CHECK(nc_trigger_activation(&t) == NC_TRIGGER_ANY && nc_trigger_delay_ns(&t) == 4 * MS, "gate options not applied");
    run_until(&t, &r, 20);
    int n = atomic_load(&r.n);
    int64_t worst_late = 0;
    for (int i = 0; i < n; i++) {
        int64_t want = r.e[0].edge_mono_ns + (i / 2) * 5 * MS + (i & 1) * MS;
        CHECK(r.e[i].edge_mono_ns == want, "edge %d at %lld ns, want the grid time %lld", i,
              (long long)r.e[i].edge_mono_ns, (long long)want);
        CHECK(r.e[i].start_mono_ns == r.e[i].edge_mono_ns + 4 * MS, "edge %d: exposure start not edge + delay", i);
        CHECK(r.fired_at[i] >= r.e[i].edge_mono_ns, "edge %d fired before its time", i);
        if (r.fired_at[i] - r.e[i].edge_mono_ns > worst_late)
            worst_late = r.fired_at[i] - r.e[i].edge_mono_ns;
    }
    struct nc_trigger_counts c;
    nc_trigger_counts(&t, &c);
    CHECK(c.accepted == (unsigned long)n && c.wrong_edge == 0, "counts: %lu accepted, %d recorded", c.accepted, n);
    printf("timer: %d edges on a 5 ms grid, 1 ms pulses; fired at most %.3f ms after the edge time\n", n,
           worst_late * 1e-6);
    nc_trigger_close(&t);
    nc_cfg_free(&cfg);

    /* 60 Hz, a period of 16 666 666.67 ns: rising edge k at llround(k 1e9 /
     * 60) past the grid's start, never a sum of rounded periods (which
     * drifts 1/3 ns a tick, 72 us an hour). */
    static struct rec r60;
    if (open_ok(&cfg, &t, "driver: timer\nrate_hz: 60\n", &r60) < 0)
        return;
    run_until(&t, &r60, 7);
    for (int k = 1; k < 7; k++)
        CHECK(r60.e[k].edge_mono_ns - r60.e[0].edge_mono_ns == llround((k + 1) * 1e9 / 60) - llround(1e9 / 60),
              "60 Hz: edge %d at %lld ns from edge 0, want %lld", k,
              (long long)(r60.e[k].edge_mono_ns - r60.e[0].edge_mono_ns),
              (long long)(llround((k + 1) * 1e9 / 60) - llround(1e9 / 60)));
    nc_trigger_close(&t);
    nc_cfg_free(&cfg);

    /* Falling edges only, then rising only after a run-time change: the gate
     * filters, and counts what it filtered. */
    static struct rec rf;
    if (open_ok(&cfg, &t, "driver: timer\nrate_hz: 200\nactivation: falling_edge\n", &rf) < 0)
        return;
    run_until(&t, &rf, 6);
    int nf = atomic_load(&rf.n);
    for (int i = 1; i < nf; i++)
        CHECK(rf.e[i].edge_mono_ns - rf.e[i - 1].edge_mono_ns == 5 * MS, "falling edges %d, %d not one period apart",
              i - 1, i);
    nc_trigger_counts(&t, &c);
    CHECK(c.wrong_edge >= c.accepted - 1 && c.accepted == (unsigned long)nf, "falling only: %lu wrong edges, %lu accepted",
          c.wrong_edge, c.accepted);
    nc_trigger_close(&t);
    nc_cfg_free(&cfg);

    /* stop() wakes a timer that would next fire in 100 s. */
    static struct rec r2;
    if (open_ok(&cfg, &t, "driver: timer\nrate_hz: 0.01\n", &r2) < 0)
        return;
    nc_trigger_start(&t);
    nanosleep(&(struct timespec){0, 20000000}, NULL);
    int64_t t0 = now_ns();
    nc_trigger_close(&t);
    double stop_ms = (now_ns() - t0) * 1e-6;
    CHECK(stop_ms < 100, "stopping a slow timer took %.1f ms", stop_ms);
    CHECK(atomic_load(&r2.n) == 0, "a 100 s timer fired within 20 ms");
    nc_cfg_free(&cfg);
}

static void expect_error(const char *yaml, const char *needle)
{
    struct nc_cfg cfg;
    struct nc_trigger t;
    static struct rec r;
    int rc = open_yaml(&cfg, &t, yaml, &r);
    if (rc >= 0)
        rc = nc_cfg_check_unused(&cfg);
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), needle), "'%s': got rc %d, '%s'; want an error with '%s'", yaml, rc,
          nc_errmsg(), needle);
    if (t.drv && t.priv)
        nc_trigger_close(&t);
    nc_cfg_free(&cfg);
}

int main(void)
{
    test_gate();
    test_timer();
    expect_error("driver: gpio9\n", "this build has: timer");
    expect_error("rate_hz: 3\n", "driver");
    expect_error("driver: timer\nrate_hz: 100\npulse_width_s: 0.02\n", "shorter than the period");
    expect_error("driver: timer\nactivation: sideways\n", "activation");
    /* Unknown keys are refused by the driver's table, with file and line. */
    expect_error("driver: timer\nrate_hz: 10\nrate: 3\n", "trigger.yaml:3: rate: unknown key for trigger driver 'timer'");
    expect_error("driver: timer\nrate_hz: -1\n", "rate_hz");
    return nc_test_end();
}
