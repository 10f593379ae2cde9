/* gige_regs.c - the GigE Vision device's registers (gige_regs.h). */
#include "drivers/gige/gige_regs.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "drivers/gige/gige_image.h"

uint32_t nc__gige_reg(ArvFakeCamera *fc, uint32_t a)
{
    guint32 v = 0;
    arv_fake_camera_read_register(fc, a, &v);
    return v;
}

void nc__gige_reg_set(ArvFakeCamera *fc, uint32_t a, uint32_t v) { arv_fake_camera_write_register(fc, a, v); }

double nc__gige_reg_double(ArvFakeCamera *fc, uint32_t a)
{
    uint64_t be = 0, u;
    double d;
    arv_fake_camera_read_memory(fc, a, 8, &be);
    u = GUINT64_FROM_BE(be);
    memcpy(&d, &u, sizeof d);
    return d;
}

void nc__gige_reg_set_double(ArvFakeCamera *fc, uint32_t a, double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    u = GUINT64_TO_BE(u);
    arv_fake_camera_write_memory(fc, a, 8, &u);
}

void nc__gige_reg_set_string(ArvFakeCamera *fc, uint32_t a, size_t len, const char *s)
{
    char buf[64] = {0};
    snprintf(buf, sizeof buf < len ? sizeof buf : len, "%s", s);
    arv_fake_camera_write_memory(fc, a, (guint32)len, buf);
}

void nc__gige_publish(ArvFakeCamera *fc, const struct nc_acquisition *a)
{
    nc__gige_reg_set(fc, ARV_FAKE_CAMERA_REGISTER_EXPOSURE_TIME_US, (uint32_t)llround(a->exposure_s * 1e6));
    nc__gige_reg_set(fc, ARV_FAKE_CAMERA_REGISTER_GAIN_RAW, (uint32_t)llround(fmax(a->gain_db, 0) * 100));
    nc__gige_reg_set_double(fc, REG_FRAME_RATE, a->frame_rate_hz);
    nc__gige_reg_set(fc, REG_TRIGGER_MODE, (uint32_t)a->triggered);
    nc__gige_reg_set(fc, REG_TRIGGER_SOURCE, a->source == NC_SOURCE_SOFTWARE ? 1 : 0);
    nc__gige_reg_set(fc, REG_TRIGGER_ACT, (uint32_t)a->activation);
    nc__gige_reg_set_double(fc, REG_TRIGGER_DELAY, a->trigger_delay_s * 1e6);
}

void nc__gige_read_settings(ArvFakeCamera *fc, const struct nc_acquisition *base, struct nc_acquisition *a)
{
    *a = *base;
    a->exposure_s = nc__gige_reg(fc, ARV_FAKE_CAMERA_REGISTER_EXPOSURE_TIME_US) * 1e-6;
    a->gain_db = nc__gige_reg(fc, ARV_FAKE_CAMERA_REGISTER_GAIN_RAW) * 0.01;
    a->frame_rate_hz = nc__gige_reg_double(fc, REG_FRAME_RATE);
    a->triggered = nc__gige_reg(fc, REG_TRIGGER_MODE) != 0;
    a->source = nc__gige_reg(fc, REG_TRIGGER_SOURCE) == 1 ? NC_SOURCE_SOFTWARE : NC_SOURCE_LINE;
    uint32_t act = nc__gige_reg(fc, REG_TRIGGER_ACT);
    a->activation = act <= 2 ? (enum nc_trigger_activation)act : NC_TRIGGER_RISING;
    a->trigger_delay_s = nc__gige_reg_double(fc, REG_TRIGGER_DELAY) * 1e-6;
}

int nc__gige_same(const struct nc_acquisition *a, const struct nc_acquisition *b)
{
    return a->triggered == b->triggered && a->source == b->source && a->activation == b->activation &&
           a->frame_rate_hz == b->frame_rate_hz && a->exposure_s == b->exposure_s && a->gain_db == b->gain_db &&
           a->trigger_delay_s == b->trigger_delay_s;
}

static const uint32_t held_reg[NC_GIGE_HELD] = {
    ARV_FAKE_CAMERA_REGISTER_WIDTH,    ARV_FAKE_CAMERA_REGISTER_HEIGHT,       ARV_FAKE_CAMERA_REGISTER_X_OFFSET,
    ARV_FAKE_CAMERA_REGISTER_Y_OFFSET, ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT, REG_PACKET_SIZE, REG_HEARTBEAT};

void nc__gige_hold(ArvFakeCamera *fc, uint32_t held[NC_GIGE_HELD])
{
    for (int i = 0; i < NC_GIGE_HELD; i++)
        held[i] = nc__gige_reg(fc, held_reg[i]);
}

int nc__gige_check_registers(ArvFakeCamera *fc, int w, int h, int meta_rows, uint32_t held[NC_GIGE_HELD],
                             const struct nc_acquisition *applied, const char **why)
{
    int undone = 0;
    /* and AcquisitionMode, whose one entry is Continuous (1) */
    const uint32_t ro[4] = {ARV_FAKE_CAMERA_REGISTER_SENSOR_WIDTH, ARV_FAKE_CAMERA_REGISTER_SENSOR_HEIGHT,
                            REG_META_ROWS, ARV_FAKE_CAMERA_REGISTER_ACQUISITION_MODE};
    const uint32_t ro_value[4] = {(uint32_t)w, (uint32_t)h, (uint32_t)meta_rows, 1};
    for (int i = 0; i < 4; i++)
        if (nc__gige_reg(fc, ro[i]) != ro_value[i]) {
            nc__gige_reg_set(fc, ro[i], ro_value[i]);
            *why = "a write to SensorWidth, SensorHeight, MetadataRows (read only) or AcquisitionMode";
            undone++;
        }
    uint32_t v[NC_GIGE_HELD];
    nc__gige_hold(fc, v);
    const uint32_t W = (uint32_t)w, H = (uint32_t)(h + meta_rows), min_w = W < 16 ? W : 16, packet = v[5] & 0xffff;
    const int ok = v[0] >= min_w && v[0] <= W && v[2] <= W - v[0] && v[1] >= 1 && v[1] <= H && v[3] <= H - v[1] &&
                   (v[4] == PF_MONO8 || v[4] == PF_MONO12 || v[4] == PF_MONO16) && packet >= 576 &&
                   packet <= 65000 && packet % 4 == 0 && v[6] >= 500 && v[6] <= 60000;
    if (ok) {
        memcpy(held, v, sizeof v);
    } else if (memcmp(held, v, sizeof v)) {
        for (int i = 0; i < NC_GIGE_HELD; i++)
            nc__gige_reg_set(fc, held_reg[i], held[i]);
        *why = "Width, Height, OffsetX, OffsetY, PixelFormat, GevSCPSPacketSize or GevHeartbeatTimeout outside its "
               "range";
        undone++;
    }
    if (nc__gige_reg(fc, REG_TRIGGER_MODE) > 1 || nc__gige_reg(fc, REG_TRIGGER_SOURCE) > 1 ||
        nc__gige_reg(fc, REG_TRIGGER_ACT) > 2) {
        nc__gige_publish(fc, applied);
        *why = "TriggerMode, TriggerSource or TriggerActivation not one of its entries";
        undone++;
    }
    return undone;
}
