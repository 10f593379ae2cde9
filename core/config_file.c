/* config_file.c - a configuration file's text for the YAML reader
 * (config.h nc_cfg_load_file): read a line at a time (a NUL byte or a CR
 * inside a line named by its line and column, core/lines.h), each line
 * ended by LF alone. */
#include "core/config.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/grow.h"
#include "core/lines.h"

int nc_cfg_load_file(struct nc_cfg *cfg, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return nc_error(-errno, "%s: cannot open: %s", path, strerror(errno));
    struct nc_lines ln; /* a NUL byte named by its line and column */
    nc_lines_init(&ln, f, path, NC_ECONFIG);
    char *buf = NULL;
    size_t len = 0, cap = 0;
    int rc;
    while ((rc = nc_lines_next(&ln)) > 0) {
        if (nc_grow((void **)&buf, &cap, len + ln.len + 1, 1) < 0) {
            rc = nc_error(-ENOMEM, "%s: out of memory", path);
            break;
        }
        /* the line's end as LF alone: libyaml counts each CR of a CR CR LF as a line break of its own */
        size_t n = ln.len;
        const int lf = n > 0 && ln.line[n - 1] == '\n';
        n -= (size_t)lf;
        while (n > 0 && ln.line[n - 1] == '\r')
            n--;
        memcpy(buf + len, ln.line, n);
        len += n;
        if (lf)
            buf[len++] = '\n';
        buf[len] = '\0';
    }
    nc_lines_free(&ln);
    fclose(f);
    if (rc == 0)
        rc = nc_cfg_load_string(cfg, buf ? buf : "", path);
    free(buf);
    return rc;
}
