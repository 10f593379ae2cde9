/* config_key.c - a --set key path (config.h nc_cfg_set): names joined by
 * '.', list items as [N] or .N; "a[0].b" is "a.0.b". */
#include "core/config.h"

#include <ctype.h>
#include <stdio.h>

#include "core/error.h"

int nc__cfg_key_path(const char *key, size_t len, char *out, size_t cap, const char *origin)
{
    enum { NAME0, NAME, INDEX0, INDEX, CLOSED } at = NAME0; /* what the characters so far end in */
    if (len >= cap)
        return nc_error(NC_EUSAGE, "%s: key path too long", origin);
    size_t i = 0, j = 0;
    for (; i < len; i++) {
        const char c = key[i];
        const int sep = c == '.' || c == '[' || c == ']';
        if ((at == NAME0 || at == NAME) && !sep)
            at = NAME;
        else if ((at == INDEX0 || at == INDEX) && isdigit((unsigned char)c))
            at = INDEX;
        else if (at == INDEX && c == ']')
            at = CLOSED;
        else if ((at == NAME || at == CLOSED) && (c == '.' || c == '['))
            at = c == '.' ? NAME0 : INDEX0;
        else
            break;
        if (c != ']')
            out[j++] = c == '[' ? '.' : c;
    }
    out[j] = '\0';
    if (i == len && (at == NAME || at == CLOSED))
        return 0;
    char where[48] = "it ends unfinished";
    if (i < len)
        snprintf(where, sizeof where, "at its character %zu, '%c'", i + 1, key[i]);
    return nc_error(NC_EUSAGE, "%s: '%.*s' is no key path (%s): names joined by '.', list items as [N] or .N, e.g. "
                    "bodies[0].material.A", origin, (int)len, key, where);
}
