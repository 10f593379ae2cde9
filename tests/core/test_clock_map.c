/* test_clock_map.c - a device clock mapped onto the host's (core/clock_map.h)
 * against simulated clocks whose truth is known: the mapped time of every
 * event must lie within the bound the map states, and the bound must shrink
 * as exchanges accumulate.
 *
 * The simulated link is USB through a host controller that serves its
 * queue on a 4 ms tick (dummy_hcd under a 250 Hz kernel, the test guest's):
 * each leg waits for the next tick plus up to 0.3 ms, so the legs are
 * asymmetric by up to a tick - the case where taking the round trip's
 * middle is wrong by milliseconds and only the interval is right. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "core/clock_map.h"
#include "testutil.h"

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double uniform(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

struct device {
    double theta_ns, drift; /* device = theta + (1 + drift) host */
};
static int64_t dev_at(const struct device *d, int64_t h) { return (int64_t)llround(d->theta_ns + (1 + d->drift) * h); }

/* One leg through a controller ticking every tick_ns: arrival time.
 * tick_ns 0: a leg of 20 to 500 us, independent of the time. */
static int64_t leg(int64_t t, int64_t tick_ns)
{
    if (!tick_ns)
        return t + 20000 + (int64_t)(uniform() * 480000);
    int64_t next = (t / tick_ns + 1) * tick_ns;
    return next + (int64_t)(uniform() * 300000);
}

/* Exchanges every 90-110 ms for dur_s; after each, 20 events in the next
 * 100 ms are mapped. Returns the largest |error| - bound seen (ns) and the
 * final bound. */
static double run(const struct device *d, int64_t tick_ns, double dur_s, double *final_bound, double *max_err,
                  unsigned long *outside)
{
    struct nc_clock_map m;
    nc_clock_map_reset(&m);
    int64_t h = 5000000000ll + (int64_t)(uniform() * 1e9);
    double worst = -INFINITY;
    *max_err = 0, *outside = 0;
    int64_t dummy;
    CHECK(nc_clock_map_to_host(&m, 0, &dummy) == -1, "a map with no exchange maps nothing");
    /* Exchanges dithered by +-10 % (as the USB driver does), so that they
     * do not lock to the controller's tick. */
    for (int k = 0; k < (int)(dur_s * 10); k++, h += 90000000 + (int64_t)(uniform() * 20000000)) {
        int64_t t1 = h, a = leg(t1, tick_ns), b = a + 20000 + (int64_t)(uniform() * 280000), t4 = leg(b, tick_ns);
        nc_clock_map_add(&m, t1, dev_at(d, a), dev_at(d, b), t4);
        for (int j = 0; j < 20; j++) {
            int64_t he = t4 + (int64_t)(uniform() * 1e8), got;
            nc_clock_map_to_host(&m, dev_at(d, he), &got);
            double err = fabs((double)(got - he));
            *max_err = fmax(*max_err, err);
            double bd = nc_clock_map_bound_ns(&m, dev_at(d, he));
            worst = fmax(worst, err - bd);
            *outside += err > bd + 1; /* + 1 ns: rounding */
        }
    }
    *final_bound = m.bound_ns;
    return worst;
}

int main(void)
{
    /* 1. Constant symmetric delays, no drift: exact. */
    {
        struct nc_clock_map m;
        nc_clock_map_reset(&m);
        const int64_t theta = 123456789012345ll;
        for (int k = 0; k < 10; k++) {
            int64_t t1 = 1000000000ll * k;
            nc_clock_map_add(&m, t1, t1 + 500000 + theta, t1 + 600000 + theta, t1 + 1100000);
        }
        int64_t host, back;
        nc_clock_map_to_host(&m, 9500000000ll + theta, &host);
        nc_clock_map_to_device(&m, host, &back);
        CHECK(host == 9500000000ll, "symmetric exchanges: mapped %lld, want 9500000000", (long long)host);
        CHECK(back == 9500000000ll + theta, "back to the device: %lld", (long long)(back - theta));
        CHECK(fabs(m.bound_ns - 500000) < 1e-3, "bound %g ns, want half the round trip less the device's stay (0.5 ms)",
              m.bound_ns);
        /* A reply that claims more time on the device than the round trip took. */
        nc_clock_map_add(&m, 0, 0, 2000000, 1000000);
        CHECK(m.rejected == 1 && m.added == 10, "impossible exchange rejected (%lu)", m.rejected);
    }
    /* 2. A board clock 1000.5 s ahead running 150 ppm fast, a 4 ms tick. */
    struct device d = {1000.5e9, 150e-6};
    double bound, err;
    unsigned long outside;
    double worst = run(&d, 4000000, 20, &bound, &err, &outside);
    printf("offset 1000.5 s, drift 150 ppm, 4 ms tick, 20 s: largest error %.1f us, final bound %.1f us, "
           "largest error less bound %.2f us, %lu of 4000 events outside the bound\n",
           err / 1e3, bound / 1e3, worst / 1e3, outside);
    CHECK(outside == 0, "%lu events mapped outside their bound", outside);
    /* The reply leaves just after a tick and waits most of the next one,
     * which no exchange can tell from an offset: the bound stays near half
     * a tick, but no wider. */
    CHECK(bound < 0.6 * 4e6, "final bound %.1f us, with a 4 ms tick", bound / 1e3);
    /* 3. A slow clock and a 1 ms tick (a real full-speed bus). */
    d = (struct device){-3.2e9, -80e-6};
    worst = run(&d, 1000000, 20, &bound, &err, &outside);
    printf("offset -3.2 s, drift -80 ppm, 1 ms tick, 20 s: largest error %.1f us, final bound %.1f us, %lu outside\n",
           err / 1e3, bound / 1e3, outside);
    CHECK(outside == 0, "%lu events mapped outside their bound", outside);
    CHECK(bound < 0.6 * 1e6, "final bound %.1f us, with a 1 ms tick", bound / 1e3);
    /* 4. Legs of 20-500 us with no tick: the intersection closes in on the
     * fastest legs of either direction. */
    d = (struct device){42e9, 30e-6};
    worst = run(&d, 0, 20, &bound, &err, &outside);
    printf("offset 42 s, drift 30 ppm, legs of 20-500 us, 20 s: largest error %.1f us, final bound %.1f us, "
           "%lu outside\n", err / 1e3, bound / 1e3, outside);
    CHECK(outside == 0, "%lu events mapped outside their bound", outside);
    CHECK(bound < 50000, "final bound %.1f us: the fastest legs are 20 us", bound / 1e3);
    return nc_test_end();
}
