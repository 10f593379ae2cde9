/* output_null.c - the null output: accepts every frame and discards it (for
 * benchmarks and for running the emulator without side effects). */
#include "emulator/output.h"

static const struct nc_param null_params[] = {NC_P_END};

static int null_open(void *priv, struct nc_cfg_node *opts, const struct nc_output_ctx *ctx) { return 0; }
static int null_submit(void *priv, const struct nc_frame_record *r) { return 0; }
static void null_close(void *priv) {}

const struct nc_output_driver nc_output_null = {
    .name = "null",
    .description = "discards frames",
    .caps = NC_OUTPUT_CAP_DN16,
    .priv_size = 0,
    .params = null_params,
    .open = null_open,
    .submit = null_submit,
    .close = null_close,
};
