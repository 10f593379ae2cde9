/* bench_util.h - timing helpers shared by the benchmarks: a monotonic clock
 * in milliseconds, the median of a sample (sorts it), numbers from the
 * emulator's JSON summary. */
#ifndef NC_BENCH_UTIL_H
#define NC_BENCH_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

#endif
