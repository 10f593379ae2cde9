/* adapter.h - the reference USB trigger adapter (README.md beside this
 * file): what its two halves share. lines.c reads the GPIO inputs and
 * drives the strobe outputs; navcam-usb-adapter.c speaks the protocol
 * (proto/usb_trigger.h) through FunctionFS. They meet in the message queue
 * and the strobe windows below.
 */
#ifndef NC_ADAPTER_H
#define NC_ADAPTER_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "core/windows.h"
#include "proto/usb_trigger.h"

#define QUEUE_LEN 65536 /* messages waiting for the host */

struct line {
    const char *name;
    struct gpiod_line *line; /* outputs */
    unsigned offset;         /* inputs: on the chip */
    uint32_t seqno;          /* inputs: the kernel's sequence number of the last edge read */
    int last_level;          /* inputs: after the last edge read; outputs: the level driven */
};

struct adapter {
    /* options */
    const char *chip_name, *ffs, *gadget, *udc;
    const char *bias, *strobe_active;
    int n_in, n_out;
    struct line in[NC_UT_MAX_LINES], out[NC_UT_MAX_LINES];
    double clock_offset_s, clock_drift_ppm;
    int64_t mono0_ns;
    struct gpiod_chip *chip;
    int events_fd; /* the inputs' edge events (kernel v2 line request) */
    atomic_int stop;
    int wake_fd; /* wakes the lines thread: a new strobe window, or stop */
    /* the queue to the host, and its counters */
    pthread_mutex_t lock;
    pthread_cond_t cond;
    struct nc_ut_msg q[QUEUE_LEN];
    unsigned qhead, qcount;
    uint32_t seq;
    int enabled; /* the host has configured the function */
    unsigned long edges, missed, level_repeats, dropped, flushed, sent, write_lost, hellos, time_reqs;
    /* strobe windows (lock) */
    struct nc_windows win;
    unsigned long strobes_late;
};

/* The board's clock as the adapter reports it: CLOCK_MONOTONIC, moved by
 * --clock-offset-s and --clock-drift-ppm (which tests use to stand for a
 * board whose clock is not the host's). */
int64_t adapter_dev_ns(const struct adapter *a, int64_t mono_ns);
int64_t adapter_mono_ns(const struct adapter *a, int64_t dev_ns);
/* Queue a message for the host; seq is given here. Lock held. */
void adapter_push(struct adapter *a, struct nc_ut_msg *m);

/* lines.c */
int lines_open(struct adapter *a);
void *lines_thread(void *arg);
/* A strobe window from the host (device clock). Lock not held. */
void lines_strobe(struct adapter *a, int line, int64_t start_dev_ns, int64_t end_dev_ns);
void lines_close(struct adapter *a);

#endif
