/* clock_map.h - a device's clock mapped onto CLOCK_MONOTONIC from timed
 * request/reply exchanges, with a bound on the error (NTP's four
 * timestamps; docs/usb-trigger.md "Clock mapping").
 *
 * One exchange: the host sends a request at t1 (host clock), the device
 * receives it at t2 and replies at t3 (device clock), the host receives the
 * reply at t4. Whatever the two legs' delays, the offset device - host lies
 * in [t3 - t4, t2 - t1]. With the device's clock linear in the host's
 * (offset + drift x, |drift| <= 1000 ppm), the newest exchanges that agree
 * bound a convex set of (offset, drift); the map is its middle, and the
 * error bound is its extent - a bound that holds whatever the legs'
 * asymmetry, not a statistical guess. Pure arithmetic, no clock is read
 * here; not thread-safe (its owner locks).
 */
#ifndef NC_CLOCK_MAP_H
#define NC_CLOCK_MAP_H

#include <stdint.h>

#define NC_CLOCK_MAP_SAMPLES 128

struct nc_clock_map {
    struct nc_clock_sample {
        int64_t t1, t2, t3, t4; /* ns: host send, device receive, device send, host receive */
    } s[NC_CLOCK_MAP_SAMPLES];
    int n, head;                /* ring of the newest exchanges */
    unsigned long added, rejected;
    /* device - host = offset_ns + drift * (device - ref_dev_ns) */
    int valid;
    int64_t ref_dev_ns;
    double offset_ns, drift;
    double bound_ns;         /* the offset's error bound at ref_dev_ns */
    double drift_half_range; /* the drift's (dimensionless) */
    int used;                /* exchanges that agree (the newest ones) */
};

void nc_clock_map_reset(struct nc_clock_map *m);
/* Adds one exchange and refits. An exchange whose device time runs
 * backwards against its host times (t3 - t2 > t4 - t1) is counted in
 * `rejected` and ignored. */
void nc_clock_map_add(struct nc_clock_map *m, int64_t t1, int64_t t2, int64_t t3, int64_t t4);
/* Device time to CLOCK_MONOTONIC; -1 before the first exchange. */
int nc_clock_map_to_host(const struct nc_clock_map *m, int64_t dev_ns, int64_t *host_ns);
/* The error bound of nc_clock_map_to_host at dev_ns (INFINITY before the
 * first exchange): the offset's, plus the drift's times the distance from
 * the newest exchange. */
double nc_clock_map_bound_ns(const struct nc_clock_map *m, int64_t dev_ns);
/* CLOCK_MONOTONIC to device time; -1 before the first exchange. */
int nc_clock_map_to_device(const struct nc_clock_map *m, int64_t host_ns, int64_t *dev_ns);

#endif
