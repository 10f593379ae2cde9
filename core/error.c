/* error.c - error codes to text, and the per-thread message buffer. */
#define _GNU_SOURCE 1 /* strerrorname_np */
#include "core/error.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static _Thread_local char errmsg[1024];

const char *nc_strerror(int code)
{
    switch (code) {
#define NC__XSTR(name, text) case NC_E##name: return text;
        NC_ERRNO_MAP(NC__XSTR)
#undef NC__XSTR
    default:
        break;
    }
    if (code < 0 && code > NC__EBASE)
        return strerror(-code);
    return code == 0 ? "success" : "unknown error";
}

const char *nc_err_name(int code)
{
    switch (code) {
#define NC__XNAME(name, text) case NC_E##name: return "NC_E" #name;
        NC_ERRNO_MAP(NC__XNAME)
#undef NC__XNAME
    default:
        break;
    }
    if (code == 0)
        return "OK";
    /* Every errno value the C library knows has its symbolic name (glibc
     * 2.32+); "E?" would tell a user nothing. */
    const char *name = code < 0 && code > NC__EBASE ? strerrorname_np(-code) : NULL;
    return name ? name : "E?";
}

int nc_error(int code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(errmsg, sizeof errmsg, fmt, ap);
    va_end(ap);
    return code;
}

const char *nc_errmsg(void) { return errmsg; }

void nc_error_clear(void) { errmsg[0] = '\0'; }
