/* driver.c - finding drivers in a registry by name (driver.h). */
#include "emulator/driver.h"

#include <stdio.h>
#include <string.h>

/* Output and trigger driver structs both start with `const char *name`. */
static const char *driver_name(const void *drv) { return *(const char *const *)drv; }

static const void *find(const void *const *list, const char *name)
{
    for (int i = 0; list && list[i]; i++)
        if (!strcmp(driver_name(list[i]), name))
            return list[i];
    return NULL;
}

const struct nc_output_driver *nc_registry_output(const struct nc_driver_registry *r, const char *name)
{
    return find((const void *const *)r->outputs, name);
}

const struct nc_trigger_driver *nc_registry_trigger(const struct nc_driver_registry *r, const char *name)
{
    return find((const void *const *)r->triggers, name);
}

static const void *select_driver(const void *const *list, struct nc_cfg_node *opts, const char *kind,
                                 const char *builtin, int *is_builtin, int *rc)
{
    const char *name;
    if (is_builtin)
        *is_builtin = 0;
    *rc = nc_cfg_string(opts, "driver", &name);
    if (*rc == 0 && builtin && is_builtin) { /* not named: the built-in one, the default */
        *is_builtin = 1;
        *rc = 1;
        return NULL;
    }
    if (*rc <= 0) {
        if (*rc == 0)
            *rc = nc_cfg_missing(opts, "driver", kind);
        return NULL;
    }
    if (builtin && !strcmp(name, builtin)) {
        *is_builtin = 1;
        return NULL;
    }
    const void *drv = find(list, name);
    if (!drv) {
        char names[256] = "", hint[96] = "";
        const char *all[32];
        size_t n = 0;
        if (builtin)
            snprintf(names, sizeof names, "%s", builtin), all[n++] = builtin;
        for (int i = 0; list && list[i]; i++) {
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", names[0] ? ", " : "",
                     driver_name(list[i]));
            if (n < 32)
                all[n++] = driver_name(list[i]);
        }
        const char *best = nc__cfg_nearest(name, all, n);
        if (best)
            snprintf(hint, sizeof hint, "; did you mean '%s'?", best);
        *rc = nc_cfg_key_error(opts, "driver", "unknown %s '%s'%s (this build has: %s)", kind, name, hint, names);
    }
    return drv;
}

const struct nc_output_driver *nc_registry_select_output(const struct nc_driver_registry *r, struct nc_cfg_node *opts,
                                                         int *rc)
{
    return select_driver((const void *const *)r->outputs, opts, "output driver", NULL, NULL, rc);
}

const struct nc_trigger_driver *nc_registry_select_trigger(const struct nc_driver_registry *r, struct nc_cfg_node *opts,
                                                           const char *builtin, int *is_builtin, int *rc)
{
    return select_driver((const void *const *)r->triggers, opts, "trigger driver", builtin, is_builtin, rc);
}
