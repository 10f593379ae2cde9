/* windows.h - a schedule of time windows during which output lines are
 * active (strobes during exposures): windows come in start order, the
 * owner's thread asks which lines should be active now and when the next
 * change is due, then sleeps until then. Used by the GPIO trigger driver
 * and the USB trigger adapter. Times are any one clock's nanoseconds; no
 * clock is read here; not thread-safe (its owner locks).
 */
#ifndef NC_WINDOWS_H
#define NC_WINDOWS_H

#include <stdint.h>
#include <time.h>

#define NC_WINDOWS_MAX 64

struct nc_windows {
    struct nc_window {
        int64_t start_ns, end_ns;
        int line, seen;
    } w[NC_WINDOWS_MAX];
    int head, count;
    unsigned long started;   /* windows whose line was driven */
    unsigned long missed;    /* windows that had ended before the owner's thread looked */
    unsigned long stretched; /* windows merged into the newest one of their line (schedule full) */
    unsigned long dropped;   /* windows not kept (schedule full of other lines' windows) */
};

/* Adds a window for line; a full schedule stretches the newest window when
 * it is the same line's, so a storm keeps the line active, or drops it. */
void nc_windows_add(struct nc_windows *s, int64_t start_ns, int64_t end_ns, int line);
/* Sets bit k of *active for every line k (< 32) that should be active at
 * now; returns when that next changes (INT64_MAX: no window pending).
 * Overlapping windows keep a line active. */
int64_t nc_windows_plan(struct nc_windows *s, int64_t now, uint32_t *active);
/* A ppoll() timeout until next (from nc_windows_plan) at now: ts filled, or
 * NULL for "no timeout". */
struct timespec *nc_windows_timeout(int64_t next, int64_t now, struct timespec *ts);

#endif
