/* test_windows.c - the schedule of strobe windows (core/windows.h): which
 * lines are active when, when the next change is due, and what a storm
 * (a full schedule) or a late thread does to it. */
#include <stdint.h>

#include "core/windows.h"
#include "testutil.h"

int main(void)
{
    static struct nc_windows s;
    uint32_t on;
    CHECK(nc_windows_plan(&s, 0, &on) == INT64_MAX && on == 0, "empty: nothing active, no change due");
    nc_windows_add(&s, 100, 200, 0);
    nc_windows_add(&s, 150, 300, 1);
    nc_windows_add(&s, 250, 260, 0);
    CHECK(nc_windows_plan(&s, 50, &on) == 100 && on == 0, "before: next change at the first start (got on %x)", on);
    CHECK(nc_windows_plan(&s, 120, &on) == 150 && on == 1, "line 0 on, next the second start");
    CHECK(nc_windows_plan(&s, 160, &on) == 200 && on == 3, "both on, next the first end");
    CHECK(nc_windows_plan(&s, 255, &on) == 260 && on == 3, "line 0 again (third window), line 1 still");
    CHECK(nc_windows_plan(&s, 400, &on) == INT64_MAX && on == 0 && s.started == 3 && s.missed == 0,
          "all over: %lu started, %lu missed", s.started, s.missed);
    /* A thread that wakes after a whole window: counted, never driven. */
    nc_windows_add(&s, 500, 510, 0);
    CHECK(nc_windows_plan(&s, 600, &on) == INT64_MAX && on == 0 && s.missed == 1, "a window passed unseen");
    /* A storm: the newest window of the same line stretches. */
    for (int i = 0; i < NC_WINDOWS_MAX + 10; i++)
        nc_windows_add(&s, 1000 + i, 1001 + i, 0);
    CHECK(s.stretched == 10 && s.count == NC_WINDOWS_MAX, "stretched %lu", s.stretched);
    CHECK(nc_windows_plan(&s, 1000 + NC_WINDOWS_MAX + 5, &on) == 1000 + NC_WINDOWS_MAX + 10 && on == 1,
          "the last window kept covers the storm's end");
    nc_windows_add(&s, 5000, 5001, 2);
    CHECK(s.dropped == 0, "room again after the plan retired windows");
    /* A window added later that ends sooner (the exposure shortened while
     * one ran): once it ends it is gone, its line off and its end not due
     * again, while the longer one before it stays. */
    static struct nc_windows t;
    nc_windows_add(&t, 0, 100, 0);
    nc_windows_add(&t, 10, 20, 1);
    CHECK(nc_windows_plan(&t, 15, &on) == 20 && on == 3, "both on at 15 (on %x)", on);
    CHECK(nc_windows_plan(&t, 50, &on) == 100 && on == 1 && t.count == 1,
          "at 50 only line 0 (on %x), next change its end (%d kept)", on, t.count);
    nc_windows_add(&t, 60, 70, 1);
    CHECK(nc_windows_plan(&t, 65, &on) == 70 && on == 3, "a third window in order after the compaction (on %x)", on);
    struct timespec ts;
    CHECK(nc_windows_timeout(INT64_MAX, 0, &ts) == NULL, "no change due: no timeout");
    CHECK(nc_windows_timeout(3500000000ll, 1000000000ll, &ts) == &ts && ts.tv_sec == 2 && ts.tv_nsec == 500000000,
          "timeout 2.5 s");
    CHECK(nc_windows_timeout(5, 10, &ts) == &ts && ts.tv_sec == 0 && ts.tv_nsec == 0, "overdue: zero");
    return nc_test_end();
}
