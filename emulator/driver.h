/* driver.h - what output and trigger registries share: choosing a driver by
 * the `driver` key of its config map. Internal to the emulator. */
#ifndef NC_DRIVER_H
#define NC_DRIVER_H

#include "config.h"

/* A registry is a NULL-terminated array of pointers to driver structs whose
 * first member is `const char *name`. */
const void *nc__driver_find(const void *const *registry, const char *name);

/* Reads opts' `driver` and finds it; on failure returns NULL with *rc set to
 * an error naming the file, line and the drivers this build has. */
const void *nc__driver_select(struct nc_cfg_node *opts, const char *kind, const void *const *registry, int *rc);

#endif
