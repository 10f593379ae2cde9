/* windows.c - the schedule of active windows (windows.h). */
#include "core/windows.h"

void nc_windows_add(struct nc_windows *s, int64_t start_ns, int64_t end_ns, int line)
{
    if (s->count == NC_WINDOWS_MAX) {
        struct nc_window *last = &s->w[(s->head + s->count - 1) % NC_WINDOWS_MAX];
        if (last->line != line) {
            s->dropped++;
            return;
        }
        if (end_ns > last->end_ns)
            last->end_ns = end_ns;
        s->stretched++;
        return;
    }
    s->w[(s->head + s->count++) % NC_WINDOWS_MAX] = (struct nc_window){start_ns, end_ns, line, 0};
}

int64_t nc_windows_plan(struct nc_windows *s, int64_t now, uint32_t *active)
{
    int64_t next = INT64_MAX;
    *active = 0;
    /* Every window that has ended goes, not only the first: one added
     * later may end sooner (a shorter exposure), and must not stay active
     * or due. The rest keep their order. */
    int kept = 0;
    for (int i = 0; i < s->count; i++) {
        const struct nc_window w = s->w[(s->head + i) % NC_WINDOWS_MAX];
        if (w.end_ns <= now)
            s->missed += !w.seen;
        else
            s->w[(s->head + kept++) % NC_WINDOWS_MAX] = w;
    }
    s->count = kept;
    for (int i = 0; i < s->count; i++) {
        struct nc_window *w = &s->w[(s->head + i) % NC_WINDOWS_MAX];
        if (w->start_ns <= now) {
            *active |= w->line < 32 ? 1u << w->line : 0;
            if (!w->seen)
                w->seen = 1, s->started++;
            next = w->end_ns < next ? w->end_ns : next;
        } else {
            next = w->start_ns < next ? w->start_ns : next;
        }
    }
    return next;
}

struct timespec *nc_windows_timeout(int64_t next, int64_t now, struct timespec *ts)
{
    if (next == INT64_MAX)
        return NULL;
    int64_t d = next > now ? next - now : 0;
    *ts = (struct timespec){(time_t)(d / 1000000000), (long)(d % 1000000000)};
    return ts;
}
