/* trigger_software.c - the software trigger: a TRIGGER message (or a POSE
 * with CAPTURE) fires a frame. The emulator hands each request to the
 * "fire" control; this driver turns it into a command edge. */
#include <string.h>

#include "error.h"
#include "trigger.h"

struct software {
    struct nc_trigger_ctx ctx;
};

static int software_open(void *priv, struct nc_cfg_node *opts, const struct nc_trigger_ctx *ctx)
{
    ((struct software *)priv)->ctx = *ctx;
    return 0;
}

static int software_control(void *priv, const char *request, void *arg)
{
    struct software *s = priv;
    if (strcmp(request, "fire"))
        return NC_EUNSUPPORTED;
    struct nc_trigger_edge edge = *(const struct nc_trigger_edge *)arg;
    edge.command = 1;
    edge.rising = 1;
    s->ctx.fire(s->ctx.sink, &edge);
    return 0;
}

static void software_close(void *priv) {}

const struct nc_trigger_driver nc_trigger_software = {
    .name = "software",
    .description = "TRIGGER messages, or POSE messages with CAPTURE",
    .caps = NC_TRIGGER_CAP_COMMAND,
    .priv_size = sizeof(struct software),
    .open = software_open,
    .control = software_control,
    .close = software_close,
};
