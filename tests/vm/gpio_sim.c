/* gpio_sim.c - drive and watch gpio-sim lines from a test, with
 * CLOCK_MONOTONIC times around every action.
 *
 *   gpio_sim edges PULLFILE N PERIOD_MS OUT.csv
 *       N rising edges at least PERIOD_MS apart (each followed by a falling
 *       edge half a period later) by writing pull-up / pull-down to the sim
 *       line's sysfs `pull` file; one line per rising edge:
 *       "i,before_ns,after_ns". Each wait counts from the previous write, so
 *       a late wake-up (a loaded TCG guest) never bunches edges together.
 *       PERIOD_MS 0: as fast as the writes go (a storm).
 *   gpio_sim watch VALUEFILE OUT.csv STOPFILE
 *       Read an output line's sysfs `value` every 100 us until STOPFILE
 *       exists; one line per change: "mono_ns,value" (the first line is the
 *       initial value). Where two reads lie more than 5 ms apart (a stalled
 *       TCG guest: a pulse between them went unseen), OUT.csv.gaps gets a
 *       line "from_ns,to_ns".
 */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void sleep_until(int64_t t)
{
    struct timespec ts = {(time_t)(t / 1000000000), (long)(t % 1000000000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR)
        ;
}

static int put(int fd, const char *s)
{
    size_t n = strlen(s);
    return pwrite(fd, s, n, 0) == (ssize_t)n ? 0 : -1;
}

static int edges(const char *pull, int n, double period_ms, const char *out)
{
    int fd = open(pull, O_WRONLY);
    FILE *csv = fopen(out, "w");
    if (fd < 0 || !csv) {
        perror(fd < 0 ? pull : out);
        return 1;
    }
    if (put(fd, "pull-down") < 0) {
        perror(pull);
        return 1;
    }
    int64_t period = (int64_t)(period_ms * 1e6), t = now_ns();
    for (int i = 0; i < n; i++) {
        if (period)
            sleep_until(t + period / 2);
        int64_t a = now_ns();
        if (put(fd, "pull-up") < 0) {
            perror(pull);
            return 1;
        }
        int64_t b = now_ns();
        fprintf(csv, "%d,%lld,%lld\n", i, (long long)a, (long long)b);
        if (period)
            sleep_until(b + period / 2);
        if (put(fd, "pull-down") < 0) {
            perror(pull);
            return 1;
        }
        t = now_ns();
    }
    fclose(csv);
    close(fd);
    return 0;
}

static int watch(const char *value, const char *out, const char *stop)
{
    char gaps_path[4096];
    snprintf(gaps_path, sizeof gaps_path, "%s.gaps", out);
    int fd = open(value, O_RDONLY);
    FILE *csv = fopen(out, "w"), *gaps = fopen(gaps_path, "w");
    if (fd < 0 || !csv || !gaps) {
        perror(fd < 0 ? value : !csv ? out : gaps_path);
        return 1;
    }
    int last = -1;
    int64_t prev = 0;
    for (unsigned k = 0;; k++) {
        char c[4];
        if (pread(fd, c, sizeof c, 0) < 1) {
            perror(value);
            return 1;
        }
        int64_t t = now_ns();
        if (k > 0 && t - prev > 5000000)
            fprintf(gaps, "%lld,%lld\n", (long long)prev, (long long)t);
        prev = t;
        int v = c[0] == '1';
        if (v != last) {
            fprintf(csv, "%lld,%d\n", (long long)t, v);
            last = v;
        }
        if (k % 256 == 0 && access(stop, F_OK) == 0)
            break;
        usleep(100);
    }
    fclose(csv);
    fclose(gaps);
    close(fd);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 6 && !strcmp(argv[1], "edges"))
        return edges(argv[2], atoi(argv[3]), atof(argv[4]), argv[5]);
    if (argc == 5 && !strcmp(argv[1], "watch"))
        return watch(argv[2], argv[3], argv[4]);
    fprintf(stderr, "usage: gpio_sim edges PULLFILE N PERIOD_MS OUT.csv | gpio_sim watch VALUEFILE OUT.csv STOPFILE\n");
    return 2;
}
