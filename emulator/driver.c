/* driver.c - selecting a driver from a registry by name (driver.h). */
#include "driver.h"

#include <stdio.h>
#include <string.h>

static const char *driver_name(const void *drv) { return *(const char *const *)drv; }

const void *nc__driver_find(const void *const *registry, const char *name)
{
    for (int i = 0; registry[i]; i++)
        if (!strcmp(driver_name(registry[i]), name))
            return registry[i];
    return NULL;
}

const void *nc__driver_select(struct nc_cfg_node *opts, const char *kind, const void *const *registry, int *rc)
{
    const char *name;
    *rc = nc_cfg_string(opts, "driver", &name);
    if (*rc <= 0) {
        if (*rc == 0)
            *rc = nc_cfg_missing(opts, "driver", kind);
        return NULL;
    }
    const void *drv = nc__driver_find(registry, name);
    if (!drv) {
        char list[256] = "";
        for (int i = 0; registry[i]; i++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", driver_name(registry[i]));
        *rc = nc_cfg_error(nc_cfg_get(opts, "driver"), "unknown %s '%s' (this build has: %s)", kind, name, list);
    }
    return drv;
}
