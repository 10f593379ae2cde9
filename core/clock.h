/* clock.h - CLOCK_MONOTONIC in nanoseconds: the clock of every trigger edge,
 * exposure window and latency figure in NavCam. */
#ifndef NC_CLOCK_H
#define NC_CLOCK_H

#include <math.h>
#include <stdint.h>
#include <time.h>

static inline int64_t nc_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* A frame period of 1 / hz s as the fraction num / den that interfaces take
 * (V4L2's timeperframe, 32-bit): num 1000 (1000/10000 s for 10 Hz), or ten
 * times more as hz num needs to be whole (10000/15 s for 0.0015 Hz), up to
 * 10^9 with den under 4e9, so within 5e-7 of 1 / hz for hz from 1e-3 to
 * 1e3 (10000000/3333333 s for 0.3333333 Hz). */
static inline void nc_period_fraction(double hz, uint32_t *num, uint32_t *den)
{
    double n = 1000;
    while (n < 1e9 && hz * n * 10 < 4e9 && fabs(hz * n - nearbyint(hz * n)) > 1e-6)
        n *= 10;
    *num = (uint32_t)n;
    *den = (uint32_t)lround(hz * n);
}

#endif
