/* clock.h - CLOCK_MONOTONIC in nanoseconds: the clock of every trigger edge,
 * exposure window and latency figure in NavCam. */
#ifndef NC_CLOCK_H
#define NC_CLOCK_H

#include <stdint.h>
#include <time.h>

static inline int64_t nc_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

#endif
