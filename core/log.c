/* log.c - prefixed, line-atomic log lines on stderr (log.h). */
#include "core/log.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *program = "navcam";
static atomic_int threshold = -1; /* -1: not yet read from NAVCAM_LOG */

void nc_log_set_program(const char *name) { program = name; }

void nc_log_set_level(enum nc_log_level level) { atomic_store(&threshold, (int)level); }

int nc_log_enabled(enum nc_log_level level)
{
    int t = atomic_load(&threshold);
    if (t < 0) {
        static const char *const names[] = {"error", "warn", "info", "debug"};
        const char *env = getenv("NAVCAM_LOG");
        t = NC_LOG_INFO;
        for (int i = 0; env && i < 4; i++)
            if (!strcmp(env, names[i]))
                t = i;
        atomic_store(&threshold, t);
    }
    return (int)level <= t;
}

void nc_log(enum nc_log_level level, const char *object, const char *fmt, ...)
{
    if (!nc_log_enabled(level))
        return;
    char line[2048];
    static const char *const tags[] = {"error: ", "warning: ", "", ""};
    int n = snprintf(line, sizeof line, "%s: %s: %s", program, object, tags[level]);
    if (n < 0 || (size_t)n >= sizeof line)
        return;
    va_list ap;
    va_start(ap, fmt);
    int m = vsnprintf(line + n, sizeof line - (size_t)n, fmt, ap);
    va_end(ap);
    size_t len = m < 0 ? (size_t)n : (size_t)n + (size_t)m;
    if (len > sizeof line - 2)
        len = sizeof line - 2; /* cut, but still one whole line */
    line[len++] = '\n';
    for (size_t off = 0; off < len;) {
        ssize_t w = write(STDERR_FILENO, line + off, len - off);
        if (w <= 0)
            break;
        off += (size_t)w;
    }
}
