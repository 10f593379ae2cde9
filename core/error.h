/* error.h - NavCam error codes and the per-thread error message.
 *
 * Functions return 0 or a negative code. System failures return -errno; project
 * failures return one of the NC_E* codes below, which come from one macro list
 * so that nc_strerror() and nc_err_name() can never drift from the enum.
 * The detailed message (file, line, key, object, operation) is kept per thread
 * and read with nc_errmsg(); it is set once, where the failure happened.
 */
#ifndef NC_ERROR_H
#define NC_ERROR_H

#include <stddef.h>

#define NC_ERRNO_MAP(X)                                                       \
    X(CONFIG, "invalid configuration")                                        \
    X(MESH, "invalid mesh")                                                   \
    X(IMAGE, "image input/output failed")                                     \
    X(RENDER, "renderer failure")                                             \
    X(RANGE, "value out of range")                                            \
    X(UNSUPPORTED, "not supported")                                           \
    X(USAGE, "invalid command line")

enum nc_error_code {
    NC__EBASE = -2000, /* below every errno value */
#define NC__XENUM(name, text) NC_E##name,
    NC_ERRNO_MAP(NC__XENUM)
#undef NC__XENUM
};

/* Text of an error code: a project code or -errno. */
const char *nc_strerror(int code);
/* Symbolic name, e.g. "NC_ECONFIG" or "ENOENT". */
const char *nc_err_name(int code);

/* Record a formatted message for this thread and return code, so that a
 * failure site reads: return nc_error(NC_ECONFIG, "%s:%d: ...", ...); */
int nc_error(int code, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The last message recorded on this thread ("" if none). */
const char *nc_errmsg(void);
void nc_error_clear(void);

#endif
