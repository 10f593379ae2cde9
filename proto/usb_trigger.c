/* usb_trigger.c - the USB trigger adapter's messages in bytes (usb_trigger.h). */
#include "proto/usb_trigger.h"


#include "core/le.h"

void nc_ut_encode(uint8_t out[NC_UT_MSG_BYTES], const struct nc_ut_msg *m)
{
    out[0] = m->type, out[1] = m->line, out[2] = m->level, out[3] = m->flags;
    nc_le_put_u32(out + 4, m->seq);
    nc_le_put_u32(out + 8, m->tag);
    nc_le_put_u32(out + 12, m->arg);
    nc_le_put_u64(out + 16, (uint64_t)m->t0_ns);
    nc_le_put_u64(out + 24, (uint64_t)m->t1_ns);
}

int nc_ut_decode(const uint8_t in[NC_UT_MSG_BYTES], struct nc_ut_msg *m)
{
    m->type = in[0], m->line = in[1], m->level = in[2], m->flags = in[3];
    m->seq = nc_le_get_u32(in + 4);
    m->tag = nc_le_get_u32(in + 8);
    m->arg = nc_le_get_u32(in + 12);
    m->t0_ns = (int64_t)nc_le_get_u64(in + 16);
    m->t1_ns = (int64_t)nc_le_get_u64(in + 24);
    switch (m->type) {
    case NC_UT_EDGE: case NC_UT_TIME: case NC_UT_INFO: case NC_UT_HELLO: case NC_UT_TIME_REQ: case NC_UT_STROBE:
        return 0;
    default:
        return -1;
    }
}
