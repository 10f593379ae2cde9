/* gige_check.h - checks of the GigE Vision output (output_gige.c) made
 * before its device starts. Internal to the gige driver. */
#ifndef NC_GIGE_CHECK_H
#define NC_GIGE_CHECK_H

#include <stddef.h>

#include "core/config.h"

/* The interface's IPv4 address into addr, and whether the GigE Vision
 * control port (UDP 3956) is free there; errors name `where`. */
int nc__gige_check_interface(const char *iface, struct nc_cfg_node *where, char *addr, size_t addr_len);
/* A GenICam description must parse and name every feature NavCam serves. */
int nc__gige_check_xml(const char *what, const void *xml, size_t len);

#endif
