/* driver.h - the set of drivers a program has, and choosing one by the
 * `driver` key of its config map. The emulator never names a driver: the
 * program (app/) hands it a registry, which drivers/registry.c (generated
 * by CMake) fills with the drivers of the build. So no library calls up a
 * layer, and a test can hand the emulator drivers of its own.
 */
#ifndef NC_DRIVER_H
#define NC_DRIVER_H

#include "core/config.h"
#include "emulator/output.h"
#include "emulator/trigger.h"

struct nc_driver_registry {
    const struct nc_output_driver *const *outputs;   /* NULL-terminated */
    const struct nc_trigger_driver *const *triggers; /* NULL-terminated */
};

const struct nc_output_driver *nc_registry_output(const struct nc_driver_registry *r, const char *name);
const struct nc_trigger_driver *nc_registry_trigger(const struct nc_driver_registry *r, const char *name);

/* Reads opts' `driver` and finds it among the outputs (or triggers); on
 * failure returns NULL with *rc set to an error naming the file, line and
 * the drivers this build has. builtin (may be NULL) is a further name that
 * the caller handles itself; it is returned as *is_builtin = 1. */
const struct nc_output_driver *nc_registry_select_output(const struct nc_driver_registry *r, struct nc_cfg_node *opts,
                                                         int *rc);
const struct nc_trigger_driver *nc_registry_select_trigger(const struct nc_driver_registry *r, struct nc_cfg_node *opts,
                                                           const char *builtin, int *is_builtin, int *rc);

#endif
