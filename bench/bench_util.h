/* bench_util.h - timing helpers shared by the benchmarks: a monotonic clock
 * in milliseconds, the median of a sample (sorts it), numbers from the
 * emulator's JSON summary. */
#ifndef NC_BENCH_UTIL_H
#define NC_BENCH_UTIL_H

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static inline double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static inline int nc__cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static inline double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, nc__cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The number after "key": in a flat JSON text (the serve summary); -1 if absent. */
static inline double json_number(const char *text, const char *key)
{
    char pat[80];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    const char *p = strstr(text, pat);
    return p ? atof(p + strlen(pat)) : -1;
}

/* A whole small file as a string into buf (at most len - 1 bytes). */
static inline void read_text(const char *path, char *buf, size_t len)
{
    FILE *f = fopen(path, "r");
    size_t got = f ? fread(buf, 1, len - 1, f) : 0;
    buf[got] = 0;
    if (f)
        fclose(f);
}

/* The options --frames N (1..1000, else *frames stays) and --threads N
 * (default: the online cores) of a benchmark named name. Returns -1 to go
 * on, else the exit status (--help: 0, a bad option: 2). */
static inline int bench_frames_threads(int argc, char **argv, const char *name, int *frames, int *threads)
{
    static const struct option opts[] = {{"frames", required_argument, NULL, 'n'},
                                         {"threads", required_argument, NULL, 'j'},
                                         {"help", no_argument, NULL, 'h'},
                                         {NULL, 0, NULL, 0}};
    int c, n = *frames;
    *threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    while ((c = getopt_long(argc, argv, "n:j:h", opts, NULL)) != -1) {
        switch (c) {
        case 'n': n = atoi(optarg); break;
        case 'j': *threads = atoi(optarg); break;
        default: printf("Usage: %s [--frames N] [--threads N]\n", name); return c == 'h' ? 0 : 2;
        }
    }
    if (n >= 1 && n <= 1000)
        *frames = n;
    return -1;
}

#endif
