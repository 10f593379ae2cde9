/* gige_regs.c - the GigE Vision device's registers (gige_regs.h). */
#include "drivers/gige/gige_regs.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "core/log.h"
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

void nc__gige_clock_poll(ArvFakeCamera *fc, struct nc__gige_clock *c, int64_t now_ns)
{
    const uint32_t control = nc__gige_reg(fc, REG_TIMESTAMP_CONTROL);
    if (control) {
        nc__gige_reg_set(fc, REG_TIMESTAMP_CONTROL, 0);
        if (control & 1) { /* the one before first: a reader that sees the new origin sees it too */
            atomic_store(&c->before_ns, atomic_load(&c->origin_ns));
            atomic_store(&c->origin_ns, now_ns);
        }
    }
    const uint64_t be = GUINT64_TO_BE(nc__gige_clock_at(c, now_ns));
    arv_fake_camera_write_memory(fc, REG_TIMESTAMP_VALUE, 8, &be);
}

uint64_t nc__gige_clock_at(const struct nc__gige_clock *c, int64_t mono_ns)
{
    const int64_t origin = atomic_load(&c->origin_ns);
    return (uint64_t)(mono_ns - (mono_ns >= origin ? origin : atomic_load(&c->before_ns)));
}

/* The register images of a's settings. */
static uint32_t exposure_reg(const struct nc_acquisition *a) { return (uint32_t)llround(a->exposure_s * 1e6); }
static uint32_t gain_reg(const struct nc_acquisition *a) { return (uint32_t)llround(fmax(a->gain_db, 0) * 100); }

void nc__gige_publish_changed(ArvFakeCamera *fc, const struct nc_acquisition *a, const struct nc_acquisition *shown)
{
    if (!shown || exposure_reg(a) != exposure_reg(shown))
        nc__gige_reg_set(fc, ARV_FAKE_CAMERA_REGISTER_EXPOSURE_TIME_US, exposure_reg(a));
    if (!shown || gain_reg(a) != gain_reg(shown))
        nc__gige_reg_set(fc, ARV_FAKE_CAMERA_REGISTER_GAIN_RAW, gain_reg(a));
    if (!shown || a->frame_rate_hz != shown->frame_rate_hz)
        nc__gige_reg_set_double(fc, REG_FRAME_RATE, a->frame_rate_hz);
    if (!shown || a->triggered != shown->triggered)
        nc__gige_reg_set(fc, REG_TRIGGER_MODE, (uint32_t)a->triggered);
    if (!shown || a->source != shown->source)
        nc__gige_reg_set(fc, REG_TRIGGER_SOURCE, a->source == NC_SOURCE_SOFTWARE ? 1 : 0);
    if (!shown || a->activation != shown->activation)
        nc__gige_reg_set(fc, REG_TRIGGER_ACT, (uint32_t)a->activation);
    if (!shown || a->trigger_delay_s * 1e6 != shown->trigger_delay_s * 1e6)
        nc__gige_reg_set_double(fc, REG_TRIGGER_DELAY, a->trigger_delay_s * 1e6);
}

void nc__gige_publish(ArvFakeCamera *fc, const struct nc_acquisition *a)
{
    nc__gige_publish_changed(fc, a, NULL);
    /* A setting the registers show rounded stands until a client writes
     * another value: a write of the value shown leaves the register as it
     * was, which is all a poll sees. */
    const double ex_us = exposure_reg(a), gain = gain_reg(a) * 0.01;
    if (fabs(ex_us * 1e-6 - a->exposure_s) > 1e-9 * a->exposure_s)
        nc_log_warn("output/gige", "the exposure %.15g s shows as ExposureTime %.0f us; frames take %.15g s until a "
                    "client writes another value (a write of %.0f us is not seen)", a->exposure_s, ex_us,
                    a->exposure_s, ex_us);
    if (fabs(gain - a->gain_db) > 1e-9)
        nc_log_warn("output/gige", "the gain %.15g dB shows as Gain %.2f dB; frames take %.15g dB until a client "
                    "writes another value (a write of %.2f dB is not seen)", a->gain_db, gain, a->gain_db, gain);
}

void nc__gige_read_settings(ArvFakeCamera *fc, const struct nc_acquisition *base, struct nc_acquisition *a)
{
    /* A register that still shows base's value gives base's value itself,
     * not its rounded image (whole microseconds, 0.01 dB, no negative gain). */
    *a = *base;
    const uint32_t ex = nc__gige_reg(fc, ARV_FAKE_CAMERA_REGISTER_EXPOSURE_TIME_US);
    const uint32_t gain = nc__gige_reg(fc, ARV_FAKE_CAMERA_REGISTER_GAIN_RAW);
    const double delay_us = nc__gige_reg_double(fc, REG_TRIGGER_DELAY);
    a->exposure_s = ex == exposure_reg(base) ? base->exposure_s : ex * 1e-6;
    a->gain_db = gain == gain_reg(base) ? base->gain_db : gain * 0.01;
    a->frame_rate_hz = nc__gige_reg_double(fc, REG_FRAME_RATE);
    a->triggered = nc__gige_reg(fc, REG_TRIGGER_MODE) != 0;
    a->source = nc__gige_reg(fc, REG_TRIGGER_SOURCE) == 1 ? NC_SOURCE_SOFTWARE : NC_SOURCE_LINE;
    uint32_t act = nc__gige_reg(fc, REG_TRIGGER_ACT);
    a->activation = act <= 2 ? (enum nc_trigger_activation)act : NC_TRIGGER_RISING;
    a->trigger_delay_s = delay_us == base->trigger_delay_s * 1e6 ? base->trigger_delay_s : delay_us * 1e-6;
}

int nc__gige_in_range(struct nc_acquisition *want, const struct nc_acquisition *held, const char *why[3])
{
    static _Thread_local char msg[3][96];
    int n = 0;
    if (want->exposure_s != held->exposure_s && !(want->exposure_s >= 1e-6 && want->exposure_s <= 10.0)) {
        snprintf(msg[n], sizeof msg[n], "ExposureTime %g us outside 1 us to 10 s", want->exposure_s * 1e6);
        why[n] = msg[n], n++, want->exposure_s = held->exposure_s;
    }
    if (want->gain_db != held->gain_db && !(want->gain_db >= 0 && want->gain_db <= 48)) {
        snprintf(msg[n], sizeof msg[n], "Gain %g dB outside 0 to 48 dB", want->gain_db);
        why[n] = msg[n], n++, want->gain_db = held->gain_db;
    }
    if (want->frame_rate_hz != held->frame_rate_hz && !(want->frame_rate_hz >= 0.01)) {
        snprintf(msg[n], sizeof msg[n], "AcquisitionFrameRate %g Hz below 0.01 Hz", want->frame_rate_hz);
        why[n] = msg[n], n++, want->frame_rate_hz = held->frame_rate_hz;
    }
    return n;
}

void nc__gige_take_unit(struct nc_acquisition *to, const struct nc_acquisition *from, int unit)
{
    if (unit == 0)
        to->exposure_s = from->exposure_s;
    else if (unit == 1)
        to->gain_db = from->gain_db;
    else if (unit == 2)
        to->frame_rate_hz = from->frame_rate_hz;
    else
        to->triggered = from->triggered, to->source = from->source, to->activation = from->activation,
        to->trigger_delay_s = from->trigger_delay_s;
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

static const char *const held_name[NC_GIGE_HELD] = {"Width",       "Height",            "OffsetX",
                                                     "OffsetY",     "PixelFormat",       "GevSCPSPacketSize",
                                                     "GevHeartbeatTimeout"};

/* Whether image and transport registers v hold for a sensor of W x H rows
 * (the metadata rows included). */
static int holds(const uint32_t v[NC_GIGE_HELD], uint32_t W, uint32_t H)
{
    const uint32_t min_w = W < 16 ? W : 16, packet = v[5] & 0xffff;
    return v[0] >= min_w && v[0] <= W && v[2] <= W - v[0] && v[1] >= 1 && v[1] <= H && v[3] <= H - v[1] &&
           (v[4] == PF_MONO8 || v[4] == PF_MONO12 || v[4] == PF_MONO16) && packet >= 576 && packet <= 65000 &&
           packet % 4 == 0 && v[6] >= 500 && v[6] <= 60000;
}

int nc__gige_holds(const uint32_t v[NC_GIGE_HELD], int w, int h, int meta_rows)
{
    return holds(v, (uint32_t)w, (uint32_t)(h + meta_rows));
}

int nc__gige_check_registers(ArvFakeCamera *fc, int w, int h, int meta_rows, uint32_t held[NC_GIGE_HELD],
                             const struct nc_acquisition *applied, void (*refused)(void *, const char *), void *arg)
{
    char msg[512];
    int undone = 0;
    /* and AcquisitionMode, whose one entry is Continuous (1) */
    const uint32_t ro[4] = {ARV_FAKE_CAMERA_REGISTER_SENSOR_WIDTH, ARV_FAKE_CAMERA_REGISTER_SENSOR_HEIGHT,
                            REG_META_ROWS, ARV_FAKE_CAMERA_REGISTER_ACQUISITION_MODE};
    const uint32_t ro_value[4] = {(uint32_t)w, (uint32_t)h, (uint32_t)meta_rows, 1};
    for (int i = 0; i < 4; i++)
        if (nc__gige_reg(fc, ro[i]) != ro_value[i]) {
            nc__gige_reg_set(fc, ro[i], ro_value[i]);
            refused(arg, "a write to SensorWidth, SensorHeight, MetadataRows (read only) or AcquisitionMode");
            undone++;
        }
    uint32_t v[NC_GIGE_HELD], again[NC_GIGE_HELD];
    nc__gige_hold(fc, v);
    nc__gige_hold(fc, again);
    const uint32_t W = (uint32_t)w, H = (uint32_t)(h + meta_rows);
    /* (read twice: if a client is writing them right now, the next check
     * sees them whole) */
    if (!memcmp(v, again, sizeof v)) {
        if (!holds(v, W, H)) {
            /* Undo the fewest of the writes since the last check that make the
             * rest hold (the writes that held were a set that holds). */
            unsigned changed = 0, undo = 0;
            for (int i = 0; i < NC_GIGE_HELD; i++)
                changed |= (unsigned)(v[i] != held[i]) << i;
            for (int k = 1; k <= NC_GIGE_HELD && !undo; k++)
                for (unsigned m = changed; m && !undo; m = (m - 1) & changed) {
                    uint32_t t[NC_GIGE_HELD];
                    for (int i = 0; i < NC_GIGE_HELD; i++)
                        t[i] = m >> i & 1 ? held[i] : v[i];
                    if (__builtin_popcount(m) == k && holds(t, W, H))
                        undo = m;
                }
            if (!undo)
                undo = changed;
            size_t n = (size_t)snprintf(msg, sizeof msg, "the write of");
            for (int i = 0; i < NC_GIGE_HELD; i++)
                if (undo >> i & 1) {
                    const char *sep = n > 12 ? "," : "";
                    n += (size_t)snprintf(msg + n, n < sizeof msg ? sizeof msg - n : 0,
                                          i == 4 ? "%s %s %#x" : "%s %s %u", sep, held_name[i],
                                          i == 5 ? v[i] & 0xffff : v[i]);
                    nc__gige_reg_set(fc, held_reg[i], held[i]);
                    v[i] = held[i];
                }
            snprintf(msg + n, n < sizeof msg ? sizeof msg - n : 0,
                     " (the region within %ux%u pixels, Width from %u; PixelFormat Mono8, Mono12 or Mono16; "
                     "GevSCPSPacketSize 576 to 65000 bytes, a multiple of 4; GevHeartbeatTimeout 500 to 60000 ms)",
                     W, H, W < 16 ? W : 16);
            refused(arg, msg);
            undone++;
        }
        memcpy(held, v, sizeof v);
    }
    /* A trigger enumeration that is no entry gets the applied setting back,
     * the others stand. */
    const uint32_t treg[3] = {REG_TRIGGER_MODE, REG_TRIGGER_SOURCE, REG_TRIGGER_ACT}, tmax[3] = {1, 1, 2};
    const uint32_t tapplied[3] = {(uint32_t)applied->triggered, applied->source == NC_SOURCE_SOFTWARE ? 1u : 0u,
                                  (uint32_t)applied->activation};
    static const char *const tname[3] = {"TriggerMode", "TriggerSource", "TriggerActivation"};
    for (int i = 0; i < 3; i++) {
        const uint32_t t = nc__gige_reg(fc, treg[i]);
        if (t > tmax[i]) {
            nc__gige_reg_set(fc, treg[i], tapplied[i]);
            snprintf(msg, sizeof msg, "%s %u: not one of its entries", tname[i], t);
            refused(arg, msg);
            undone++;
        }
    }
    return undone;
}

void nc__gige_apply(ArvFakeCamera *fc, const struct nc_camera_control *ctl, struct nc_acquisition *applied,
                    void (*refused)(void *, const char *), void *arg)
{
    struct nc_acquisition want, held = *applied, shown;
    nc__gige_read_settings(fc, applied, &want);
    if (nc__gige_same(&want, applied))
        return;
    shown = want;
    const char *why[3];
    int undo = nc__gige_in_range(&want, &held, why);
    for (int k = 0; k < undo; k++)
        refused(arg, why[k]);
    if (!nc__gige_same(&want, &held) && ctl->set(ctl->emu, &want) >= 0)
        held = want;
    else
        for (int u = 0; u < NC_GIGE_UNITS; u++) {
            struct nc_acquisition t = held;
            nc__gige_take_unit(&t, &want, u);
            if (nc__gige_same(&t, &held))
                continue;
            if (ctl->set(ctl->emu, &t) >= 0)
                held = t;
            else
                refused(arg, nc_errmsg()), undo = 1;
        }
    if (undo) /* the registers undone show what holds; a client's write since then stands */
        nc__gige_publish_changed(fc, &held, &shown);
    *applied = held;
}
