/* gige_regs.h - the GigE Vision device's registers (output_gige.c): NavCam's
 * own addresses, typed access to the register memory of Aravis's device,
 * the emulator's acquisition settings as registers, and the checks a
 * camera's firmware makes on what clients write. Registers are plain
 * memory shared with the device thread (no locking in Aravis 0.8): 32-bit
 * accesses are single loads and stores. Internal to the gige driver. */
#ifndef NC_GIGE_REGS_H
#define NC_GIGE_REGS_H

#include <arv.h>
#include <stddef.h>
#include <stdint.h>

#include "emulator/output.h"

/* NavCam's application registers (see the XML's header comment). */
enum {
    REG_FRAME_RATE = 0x1000,     /* double, Hz */
    REG_TRIGGER_MODE = 0x1010,   /* 0 Off, 1 On */
    REG_TRIGGER_SOURCE = 0x1014, /* 0 Line0, 1 Software */
    REG_TRIGGER_ACT = 0x1018,    /* 0 rising, 1 falling, 2 any */
    REG_TRIGGER_SW = 0x101c,     /* latch: a client writes 1 */
    REG_TRIGGER_DELAY = 0x1020,  /* double, us */
    REG_RESULTING_RATE = 0x1028, /* double, Hz, read-only */
    REG_META_ROWS = 0x1030,      /* 0 or 1 */
    REG_ACQ_COMMAND = 0x1034,    /* a client writes 1 (AcquisitionStart) or 0 (Stop); REG_ACQ_NONE once taken */
    REG_PACKET_SIZE = 0xd04,     /* stream channel 0: packet size in the low 16 bits */
    REG_HOST_PORT = 0xd00,       /* stream channel 0: the client's port in the low 16 bits */
    REG_HEARTBEAT = 0x938,       /* heartbeat timeout, ms */
    REG_TIMESTAMP_CONTROL = 0x944, /* a client writes 2 (latch) or 1 (reset) */
    REG_TIMESTAMP_VALUE = 0x948,   /* 64 bits: the device clock, ns */
    REG_VENDOR = 0x48,
    REG_MODEL = 0x68,
    REG_VERSION = 0x88,
    REG_INFO = 0xa8,
};

#define REG_ACQ_NONE 0xffffffffu

uint32_t nc__gige_reg(ArvFakeCamera *fc, uint32_t a);
void nc__gige_reg_set(ArvFakeCamera *fc, uint32_t a, uint32_t v);
double nc__gige_reg_double(ArvFakeCamera *fc, uint32_t a);
void nc__gige_reg_set_double(ArvFakeCamera *fc, uint32_t a, double d);
void nc__gige_reg_set_string(ArvFakeCamera *fc, uint32_t a, size_t len, const char *s);

/* The device's timestamp counter (GVSP timestamps, GevTimestampValue):
 * CLOCK_MONOTONIC in ns since the last GevTimestampControlReset (since the
 * clock's own start until one). */
struct nc__gige_clock {
    _Atomic int64_t origin_ns, before_ns; /* CLOCK_MONOTONIC of the last reset, and of the one before */
};
/* At each poll, CLOCK_MONOTONIC now_ns: a reset a client wrote to the
 * timestamp control register taken (a latch needs nothing: see below), the
 * register cleared, and the counter's value now written to
 * GevTimestampValue in one 8-byte store. The device cannot see a write when
 * it comes, so the value is the counter at the last poll, never older than
 * one poll period. */
void nc__gige_clock_poll(ArvFakeCamera *fc, struct nc__gige_clock *c, int64_t now_ns);
/* The counter's value at CLOCK_MONOTONIC mono_ns (an exposure's start):
 * before the last reset, what it was then. */
uint64_t nc__gige_clock_at(const struct nc__gige_clock *c, int64_t mono_ns);

/* The registers a client sees, from the emulator's settings a; _changed
 * writes only those whose image differs from shown (what they show now). */
void nc__gige_publish(ArvFakeCamera *fc, const struct nc_acquisition *a);
void nc__gige_publish_changed(ArvFakeCamera *fc, const struct nc_acquisition *a, const struct nc_acquisition *shown);
/* The settings the registers hold now (those they do not hold from base;
 * a register that shows base's value gives base's value, not its image). */
void nc__gige_read_settings(ArvFakeCamera *fc, const struct nc_acquisition *base, struct nc_acquisition *a);
int nc__gige_same(const struct nc_acquisition *a, const struct nc_acquisition *b);
/* The settings a client wrote within the XML's ranges (ExposureTime 1 us
 * to 10 s, Gain 0 to 48 dB, AcquisitionFrameRate from 0.01 Hz): a field
 * outside gets held's value back, and why[] names the write. Returns how
 * many were undone (why[] valid until this thread's next call). */
int nc__gige_in_range(struct nc_acquisition *want, const struct nc_acquisition *held, const char *why[3]);
/* What a client writes goes to the emulator in units it takes or refuses
 * whole: 0 ExposureTime, 1 Gain, 2 AcquisitionFrameRate, 3 the trigger
 * (TriggerMode, TriggerSource, TriggerActivation, TriggerDelay). Unit u of
 * from into to. */
#define NC_GIGE_UNITS 4
void nc__gige_take_unit(struct nc_acquisition *to, const struct nc_acquisition *from, int unit);
/* The settings the registers show, when a client changed them, to the
 * emulator through ctl (applied: what held, updated): writes outside the
 * XML's ranges are undone, the others stand; if the emulator refuses them
 * together (lock-step, a line it lacks), each unit is tried alone and those
 * it refuses are undone. Calls refused(arg, why) for each. */
void nc__gige_apply(ArvFakeCamera *fc, const struct nc_camera_control *ctl, struct nc_acquisition *applied,
                    void (*refused)(void *, const char *), void *arg);

/* The image and transport registers a client writes, checked together:
 * Width, Height, OffsetX, OffsetY, PixelFormat, GevSCPSPacketSize,
 * GevHeartbeatTimeout. */
#define NC_GIGE_HELD 7
void nc__gige_hold(ArvFakeCamera *fc, uint32_t held[NC_GIGE_HELD]);
/* Whether their values v hold for a sensor of w x h pixels with meta_rows
 * metadata rows (nc__gige_check_registers's rules). */
int nc__gige_holds(const uint32_t v[NC_GIGE_HELD], int w, int h, int meta_rows);
/* Aravis's device stores whatever a client writes (GenICam's ranges are
 * the client's to check, and Aravis leaves them unchecked by default): the
 * checks a camera's firmware makes, for a sensor of w x h pixels with
 * meta_rows metadata rows. The read-only registers get their values back;
 * of the image registers (the region within the sensor, a packet size of
 * 576..65000 in steps of 4, a pixel format that is an entry, a heartbeat
 * timeout of 500..60000 ms) written since the last check, the fewest whose
 * undoing makes the rest hold get their held values back (held: the last
 * set that held, updated); a trigger enumeration that is no entry gets the
 * applied setting back. Calls refused(arg, why) for each write undone and
 * returns how many. */
int nc__gige_check_registers(ArvFakeCamera *fc, int w, int h, int meta_rows, uint32_t held[NC_GIGE_HELD],
                             const struct nc_acquisition *applied, void (*refused)(void *, const char *), void *arg);

#endif
