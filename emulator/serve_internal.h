/* serve_internal.h - the emulator's shared state, for the files that make up
 * `navcam serve` (serve.h) and for nothing else:
 *   serve.c         life cycle: set-up, the supervising loop, shutdown
 *   serve_config.c  the `serve:` and `outputs:` sections, opening drivers
 *   serve_net.c     network input: UDP datagrams, TCP clients, messages
 *   serve_jobs.c    triggers to frame jobs, the job queue, drops and answers,
 *                   the camera controls output drivers call
 *   serve_render.c  the render thread: pose, render, camera model
 *   serve_output.c  the output thread: drivers, FRAME answers
 *   serve_stats.c   counters, percentiles, the summary
 */
#ifndef NC_SERVE_INTERNAL_H
#define NC_SERVE_INTERNAL_H

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>

#include "camera/camsys.h"
#include "camera/shot.h"
#include "camera/sky.h"
#include "emulator/output.h"
#include "emulator/serve.h"
#include "emulator/timeline.h"
#include "emulator/trigger.h"
#include "navcam/protocol.h"
#include "render/image_io.h"
#include "render/render.h"
#include "render/scene.h"

#define NC_SERVE_MAX_OUTPUTS 8
#define NC_SERVE_LAT_SAMPLES 4096
#define NC_SERVE_CLIENT_OUT_BYTES 65536 /* answers waiting for a client that does not read them */

enum nc__serve_mode { NC__MODE_LOCKSTEP, NC__MODE_FREERUN, NC__MODE_TRIGGER };
extern const char *const nc__serve_mode_names[];

/* DROP_IGNORED: a capture request the acquisition mode does not take
 * (free-run, or a software trigger while the trigger source is a line).
 * DROP_OVERRUN (free-run and trigger modes): a trigger or timer tick while
 * the camera still holds an exposure waiting for readout (docs/emulator.md).
 * DROP_QUEUE_FULL: a lock-step capture over UDP while the job queue is full. */
enum nc__drop_reason {
    NC__DROP_QUEUE_FULL,
    NC__DROP_OVERRUN,
    NC__DROP_STALE_POSE,
    NC__DROP_NO_POSE,
    NC__DROP_OUTPUT_BUSY,
    NC__DROP_SHUTDOWN,
    NC__DROP_IGNORED,
    NC__DROP_REJECTED,       /* a capture whose message the timeline refused (time went backwards) */
    NC__DROP_RENDER_ERROR,   /* the render or the camera model failed (logged) */
    NC__DROP_OUTPUT_FAILED,  /* a frame made, but no output took it (each output's failures counted) */
    NC__DROP_COUNT
};
extern const char *const nc__serve_drop_names[];

struct nc__job {
    int64_t trigger_sim_ns, mid_sim_ns, trigger_mono_ns;
    int64_t ready_mono_ns; /* the earliest a camera could read the frame out: the
                            * request's arrival (lock-step) or the exposure's end */
    int64_t period_ns;     /* free-run and trigger: the time since the trigger before (0: none) */
    uint32_t sequence;
    int client; /* TCP client slot to answer, or -1 */
    unsigned client_gen;
    const char *source;
    double exposure_s, gain_db;
    int before_poses; /* triggered before any pose: not on the simulator's clock */
    int refused;      /* lock-step: the request was refused; answer "dropped" (for refused_why) in its turn */
    enum nc__drop_reason refused_why;
    int has_pose;     /* lock-step: the pose the request carries, rendered as sent */
    struct nc_pose pose;
};

/* A job's exposure: its start on the simulator's clock and on
 * CLOCK_MONOTONIC, and its length (ns), as its frame record gives them. */
static inline void nc__job_exposure(const struct nc__job *j, int64_t *start_sim, int64_t *start_mono, int64_t *len)
{
    *len = (int64_t)llround(j->exposure_s * 1e9);
    *start_sim = j->mid_sim_ns - (int64_t)llround(0.5 * j->exposure_s * 1e9);
    *start_mono = j->trigger_mono_ns + (*start_sim - j->trigger_sim_ns);
}

/* A finished job on its way to the outputs: a frame, or (lock-step) a drop
 * that must be answered in request order. */
#define NC__SLOT_ATTRS 52
struct nc__slot {
    struct nc_frame_record rec;
    struct nc_image_attr attrs[NC__SLOT_ATTRS]; /* rec.attrs, and their values */
    char attr_text[30][200], attr_wcs[8][32], attr_sun[200];
    struct nc_shot_detail_text attr_detail;
    struct nc__job job;
    uint16_t *dn;
    int64_t render_start_mono_ns; /* the job left the queue and its pose was there: the render began */
    int dropped;                 /* 1: no frame; answer DROPPED for reason why */
    enum nc__drop_reason why;
};

struct nc__client {
    int fd;
    unsigned gen;
    uint8_t buf[4 + NC_PROTO_MAX_BYTES]; /* requests not yet taken (lock-step back-pressure keeps them here) */
    size_t have;
    uint32_t skip; /* bytes of a refused message still to come, to be passed over */
    uint8_t out[NC_SERVE_CLIENT_OUT_BYTES]; /* answers not yet sent (the client reads slowly) */
    size_t out_len;
    int gone;  /* it hung up: its requests take their turns, then it is closed */
    int moved; /* its last turn took a request, or read or passed over bytes (take_requests) */
};

struct nc__emu {
    /* configuration */
    enum nc__serve_mode mode;
    double frame_rate_hz, stats_interval_s;
    int64_t pose_wait_ns; /* triggered frames: wait this long past the exposure for a later pose */
    int queue_frames, drop_oldest, stale_render, no_pose_scene;
    int overlap; /* the camera model of frame N runs while N+1 renders (never in lock-step) */
    atomic_llong readout_end_ns; /* CLOCK_MONOTONIC the frame being rendered should be done (0: none) */
    int inside_warned;           /* the render thread's: the last frame's samples mostly met a back side */
    int64_t last_trigger_mono_ns; /* of the trigger or tick before (under jlock) */
    int64_t last_exposure_end_mono_ns; /* free-run and trigger: of the last exposure taken (under jlock) */
    int job_cap; /* jobs that may wait for the render: queue_frames (lock-step) or 1 (the sensor holds one frame) */
    char bind[64];
    int udp_port, tcp_port, max_clients;
    const struct nc_driver_registry *drivers;
    /* the camera */
    struct nc_scene scene;
    struct nc_camsys cs;
    struct nc_sky sky; /* the `stars` section (sky.on = 0 without one) */
    struct nc_renderer renderer;
    struct nc_output out[NC_SERVE_MAX_OUTPUTS];
    int nout;
    int64_t out_msg_ns[NC_SERVE_MAX_OUTPUTS];     /* last failure message, for rate limiting */
    unsigned long out_quiet[NC_SERVE_MAX_OUTPUTS]; /* failures not printed since */
    /* trigger sources (not in lock-step): the free-run timer, the line of
     * serve.trigger when it names a driver, and software commands (built
     * in: they go straight to the job queue) */
    struct nc_trigger freerun, line;
    int have_freerun, have_line;
    int software_configured;        /* serve.trigger is {driver: software, ...} */
    struct nc_trigger_counts software_counts; /* under acq_lock */
    /* acquisition settings (output drivers may change them) */
    struct nc_acquisition acq;
    pthread_mutex_t acq_lock;
    struct nc_camera_control control;
    /* poses */
    struct nc_timeline tl;
    pthread_mutex_t tl_lock;
    pthread_cond_t tl_cond; /* a pose arrived; CLOCK_MONOTONIC */
    int64_t sim_anchor_ns, mono_anchor_ns; /* the simulation clock follows the newest pose */
    int have_anchor;
    /* jobs */
    struct nc__job *jobs;
    int jhead, jcount;
    struct nc__job held; /* the render thread's job when shutdown came (written by it, read after it ends) */
    int have_held;
    pthread_mutex_t jlock;
    pthread_cond_t jcond;
    /* finished frames */
    struct nc__slot *slots;
    int nslots, shead, scount;
    pthread_mutex_t slock;
    pthread_cond_t scond;      /* a slot was filled */
    pthread_cond_t sfree;      /* a slot was freed (lock-step waits for one) */
    /* network */
    int udp_fd, tcp_fd;
    struct nc__client *clients; /* max_clients of them */
    int next_client;            /* the network thread's: whose request is taken first (take_requests) */
    pthread_mutex_t client_lock;
    unsigned long refused_clients, slow_clients; /* over max_clients; disconnected for reading no answers */
    int64_t last_refuse_log_ns;
    /* state */
    atomic_int stop; /* 1: stop taking input; 2: render exits; 3: output exits */
    atomic_int warm; /* 1: the render thread has made its warm-up frame */
    double warm_busy_ms; /* ... and the time it kept the camera busy (busy_ms's), ms; set before warm */
    atomic_int failed; /* < 0: a thread gave up with this error (logged): navcam serve fails */
    uint64_t next_frame;
    int64_t start_mono_ns;
    /* statistics */
    atomic_ulong received, rejected[NC_REJECT_COUNT], dropped[NC__DROP_COUNT], delivered;
    double lat_ms[NC_SERVE_LAT_SAMPLES], render_ms[NC_SERVE_LAT_SAMPLES], wait_ms[NC_SERVE_LAT_SAMPLES];
    /* the time one frame keeps the camera busy: render + camera model, or
     * the longer of the two where they overlap (outside lock-step) */
    double busy_ms[NC_SERVE_LAT_SAMPLES];
    unsigned long nlat;
    pthread_mutex_t stat_lock;
    int64_t last_reject_log_ns;
};

/* serve_config.c: the serve section, the trigger source and the outputs,
 * read and opened; with check, before the scene is built, only read and
 * checked against the drivers' tables (unknown keys, types, ranges), so that
 * a mistake there is reported without waiting for the scene. */
int nc__serve_config(struct nc_cfg *cfg, struct nc__emu *e, const char *config_dir, int check);

/* serve_net.c */
int nc__serve_open_sockets(struct nc__emu *e);
void nc__serve_close_sockets(struct nc__emu *e);
void *nc__serve_net_thread(void *arg);
/* At shutdown: every capture request the clients sent that was not taken
 * yet (back-pressure left it in a buffer or a socket) is answered "dropped". */
void nc__serve_answer_unread(struct nc__emu *e);

/* serve_jobs.c */
void nc__serve_lockstep(struct nc__emu *e, const struct nc_pose_msg *m, int client, unsigned gen, int64_t mono);
/* A capture request the pose timeline refused: answered "dropped" in
 * request order (lock-step: through the job queue), counted as rejected. */
void nc__serve_refused_capture(struct nc__emu *e, const struct nc_pose_msg *m, int client, unsigned gen);
void nc__serve_software(struct nc__emu *e, const struct nc_pose_msg *m, int client, unsigned gen, int64_t mono);
void nc__serve_on_freerun(void *arg, const struct nc_trigger_event *ev);
void nc__serve_on_line(void *arg, const struct nc_trigger_event *ev);
/* Answer a request (no-op for UDP and software triggers without a client):
 * queued on the client's connection, sent without waiting. */
void nc__serve_reply(struct nc__emu *e, const struct nc__job *j, uint64_t frame, uint32_t status);
/* A message as TCP carries it (u32 length first) into buf (4 + NC_PROTO_MAX_BYTES); returns the message's length. */
size_t nc__serve_encode_tcp(const struct nc_pose_msg *m, uint8_t *buf);
/* Send what a client's answers queue holds, without waiting (client_lock held). */
void nc__serve_flush_client(struct nc__emu *e, struct nc__client *c);
/* 1 when the job queue is full (lock-step then stops taking requests). */
int nc__serve_queue_full(struct nc__emu *e);
void nc__serve_drop(struct nc__emu *e, const struct nc__job *j, enum nc__drop_reason why);
void nc__serve_acq_get(struct nc__emu *e, struct nc_acquisition *a);
/* Enable the source the acquisition settings name, disable the others
 * (called with acq_lock held, or before the threads start). */
void nc__serve_enable_sources(struct nc__emu *e);
void nc__serve_init_control(struct nc__emu *e);

/* serve_render.c, serve_output.c */
void *nc__serve_render_thread(void *arg);
void *nc__serve_output_thread(void *arg);

/* serve_stats.c */
/* The median time the last 16 frames kept the camera busy (busy_ms), ms,
 * before the first the warm-up frame's (0: it failed), or with slowest the
 * longest of them (0: none yet). */
double nc__serve_busy_ms(struct nc__emu *e, int slowest);
/* The frame rate the camera can deliver now: the requested rate (free-run),
 * capped by 1 / the longest busy time of the last 16 frames, so that it
 * keeps up with each of them (0: not known yet, in trigger and lock-step
 * modes before a frame). */
double nc__serve_resulting_rate_hz(struct nc__emu *e);
void nc__serve_stats_line(struct nc__emu *e, double elapsed_s);
void nc__serve_stats_json(struct nc__emu *e, double elapsed_s, FILE *f);

#endif
