/* serve.c - the emulator's threads, queues and statistics (serve.h).
 *
 * net thread     poll(): UDP datagrams, TCP connections (length-prefixed);
 *                decodes, counts rejections, feeds the timeline, makes jobs.
 * triggers       free-run and trigger modes: three trigger drivers
 *                (trigger.h) fire edges: the free-run timer, the line
 *                (serve.trigger) and software commands (from the net thread
 *                or an output's client). The acquisition settings
 *                (struct nc_acquisition, changeable at run time by output
 *                drivers) say which of them make frames.
 * render thread  job -> pose at mid-exposure -> render -> camera model -> slot.
 * output thread  slot -> every output driver -> FRAME reply to the requester.
 * main thread    signals, limits, the periodic statistics line, shutdown.
 * Pose input never blocks: a full job queue drops a job (by the configured
 * policy) and counts it.
 */
#include "serve.h"

#include <arpa/inet.h>
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "camsys.h"
#include "error.h"
#include "output.h"
#include "protocol.h"
#include "render.h"
#include "timeline.h"
#include "trigger.h"

#define MAX_OUTPUTS 8
#define MAX_CLIENTS 16
#define LAT_SAMPLES 4096

enum mode { MODE_LOCKSTEP, MODE_FREERUN, MODE_TRIGGER };
static const char *const mode_names[] = {"lockstep", "freerun", "trigger", NULL};
/* DROP_IGNORED: a capture request the acquisition mode does not take (free-run,
 * or a software trigger while the trigger source is a line). */
enum drop_reason { DROP_QUEUE_FULL, DROP_STALE_POSE, DROP_NO_POSE, DROP_OUTPUT_BUSY, DROP_SHUTDOWN, DROP_IGNORED, DROP_COUNT };
static const char *const drop_names[] = {"queue_full", "stale_pose", "no_pose", "output_busy", "shutdown", "ignored_request"};

struct job {
    int64_t trigger_sim_ns, mid_sim_ns, trigger_mono_ns;
    int64_t ready_mono_ns; /* the earliest a camera could read the frame out: the
                            * request's arrival (lock-step) or the exposure's end */
    uint32_t sequence;
    int client;        /* TCP client slot to answer, or -1 */
    unsigned client_gen;
    const char *source;
    double exposure_s, gain_db;
    int before_poses; /* triggered before any pose: not on the simulator's clock */
};

struct slot {
    struct nc_frame_record rec;
    struct job job;
    uint16_t *dn;
    int busy; /* 0 free, 1 filled and waiting for outputs */
};

struct client {
    int fd;
    unsigned gen;
    uint8_t buf[4 + NC_PROTO_MAX_BYTES];
    size_t have;
};

struct emu {
    /* configuration */
    enum mode mode;
    double frame_rate_hz, stats_interval_s;
    int64_t pose_wait_ns; /* triggered frames: wait this long past the exposure for a later pose */
    int queue_frames, drop_oldest, stale_render;
    char bind[64];
    int udp_port, tcp_port;
    /* the camera */
    struct nc_scene scene;
    struct nc_camsys cs;
    struct nc_renderer renderer;
    struct nc_output out[MAX_OUTPUTS];
    int nout;
    int64_t out_msg_ns[MAX_OUTPUTS]; /* last failure message, for rate limiting */
    unsigned long out_quiet[MAX_OUTPUTS]; /* failures not printed since */
    /* triggers (not in lock-step): the free-run timer, software commands,
     * and the line of serve.trigger when it names a line driver */
    struct nc_trigger trig[3];
    int have_trig[3];
    struct trig_sink {
        struct emu *e;
        int kind;
    } sinks[3];
    int configured; /* the trigger kind serve.trigger configured (its gate's counts go in the summary) */
    int have_configured;
    /* acquisition settings (output drivers may change them) */
    struct nc_acquisition acq;
    pthread_mutex_t acq_lock;
    struct nc_camera_control control;
    int no_pose_scene; /* before the first pose, render the scene's configured pose */
    /* poses */
    struct nc_timeline tl;
    pthread_mutex_t tl_lock;
    pthread_cond_t tl_cond; /* a pose arrived; CLOCK_MONOTONIC */
    int64_t sim_anchor_ns, mono_anchor_ns; /* the simulation clock follows the newest pose */
    int have_anchor;
    /* jobs */
    struct job *jobs;
    int jhead, jcount;
    pthread_mutex_t jlock;
    pthread_cond_t jcond;
    /* finished frames */
    struct slot *slots;
    int nslots, shead, scount;
    pthread_mutex_t slock;
    pthread_cond_t scond;
    /* network */
    int udp_fd, tcp_fd;
    struct client clients[MAX_CLIENTS];
    pthread_mutex_t client_lock;
    /* state */
    atomic_int stop;       /* 1: stop taking input; 2: threads exit */
    atomic_int render_idle, output_idle;
    uint64_t next_frame;
    int64_t start_mono_ns;
    /* statistics */
    atomic_ulong received, rejected[NC_REJECT_COUNT], dropped[DROP_COUNT], delivered, jobs_made;
    double lat_ms[LAT_SAMPLES], render_ms[LAT_SAMPLES];
    unsigned long nlat;
    pthread_mutex_t stat_lock;
    int64_t last_reject_log_ns;
};

static volatile sig_atomic_t got_signal;
static void on_signal(int sig) { got_signal = sig; }

enum trig_kind { TRIG_FREERUN, TRIG_SOFTWARE, TRIG_LINE };
static const char *const trig_kind_names[] = {"freerun", "software", "line"};

static void on_edge(void *sink, const struct nc_trigger_edge *edge);
static void drop(struct emu *e, const struct job *j, enum drop_reason why);

/* ---- configuration -------------------------------------------------------- */

static int serve_config(struct nc_cfg *cfg, struct emu *e, const char *config_dir)
{
    struct nc_cfg_node *sv = NULL, *outs = NULL;
    int rc, m = MODE_FREERUN;
    e->no_pose_scene = 1;
    e->frame_rate_hz = 10;
    e->queue_frames = 4;
    e->stats_interval_s = 5;
    double max_extrap = 0.5, pose_wait_s = 0;
    snprintf(e->bind, sizeof e->bind, "127.0.0.1");
    e->udp_port = 5750;
    e->tcp_port = 5751;
    if ((rc = nc_cfg_map(cfg->root, "serve", &sv)) < 0)
        return rc;
    if (sv) {
        static const char *const drops[] = {"drop_newest", "drop_oldest", NULL};
        static const char *const stale[] = {"drop", "render", NULL};
        static const char *const nopose[] = {"scene", "drop", NULL};
        int np = 0;
        const char *bind = NULL;
        long v;
        int d = 0, st = 0;
        if ((rc = nc_cfg_enum(sv, "mode", mode_names, &m)) < 0 ||
            (rc = nc_cfg_double(sv, "frame_rate_hz", 1e-3, 1000, &e->frame_rate_hz)) < 0 ||
            (rc = nc_cfg_double(sv, "stats_interval_s", 0, 3600, &e->stats_interval_s)) < 0 ||
            (rc = nc_cfg_double(sv, "max_extrapolation_s", 0, 3600, &max_extrap)) < 0 ||
            (rc = nc_cfg_double(sv, "pose_wait_s", 0, 60, &pose_wait_s)) < 0 ||
            (rc = nc_cfg_enum(sv, "drop_policy", drops, &d)) < 0 || (rc = nc_cfg_enum(sv, "stale_pose", stale, &st)) < 0 ||
            (rc = nc_cfg_enum(sv, "no_pose", nopose, &np)) < 0 ||
            (rc = nc_cfg_string(sv, "bind", &bind)) < 0)
            return rc;
        e->drop_oldest = d;
        e->no_pose_scene = np == 0;
        e->stale_render = st;
        if (bind)
            snprintf(e->bind, sizeof e->bind, "%s", bind);
        if ((rc = nc_cfg_int(sv, "queue_frames", 1, 1024, &v)) < 0)
            return rc;
        if (rc)
            e->queue_frames = (int)v;
        if ((rc = nc_cfg_int(sv, "udp_port", 0, 65535, &v)) < 0)
            return rc;
        if (rc)
            e->udp_port = (int)v;
        if ((rc = nc_cfg_int(sv, "tcp_port", 0, 65535, &v)) < 0)
            return rc;
        if (rc)
            e->tcp_port = (int)v;
    }
    e->mode = (enum mode)m;
    e->pose_wait_ns = llround(pose_wait_s * 1e9);
    if ((rc = nc_timeline_init(&e->tl, 4096, (int64_t)llround(max_extrap * 1e9))) < 0)
        return rc;
    /* Triggers: serve.trigger is the line (or the software source's gate);
     * the free-run timer and the software source always exist. */
    struct nc_cfg_node *tr = NULL;
    if (sv && (rc = nc_cfg_map(sv, "trigger", &tr)) < 0)
        return rc;
    if (tr && e->mode == MODE_LOCKSTEP)
        return nc_cfg_error(tr, "serve.trigger does not apply to lock-step mode (frames follow POSE messages with "
                                "CAPTURE)");
    e->configured = TRIG_SOFTWARE;
    if (tr) {
        const char *name = NULL;
        if ((rc = nc_cfg_string(tr, "driver", &name)) < 0)
            return rc;
        const struct nc_trigger_driver *d = name ? nc_trigger_find(name) : NULL;
        e->configured = d && (d->caps & NC_TRIGGER_CAP_LINE) ? TRIG_LINE : TRIG_SOFTWARE;
        e->sinks[e->configured] = (struct trig_sink){e, e->configured};
        struct nc_trigger_ctx tc = {.fire = on_edge, .sink = &e->sinks[e->configured]};
        if ((rc = nc_trigger_open(&e->trig[e->configured], tr, &tc)) < 0)
            return rc;
        e->have_trig[e->configured] = 1;
        e->have_configured = 1;
    }
    for (int k = TRIG_FREERUN; e->mode != MODE_LOCKSTEP && k <= TRIG_SOFTWARE; k++) {
        if (e->have_trig[k])
            continue;
        char text[128];
        if (k == TRIG_FREERUN)
            snprintf(text, sizeof text, "{driver: timer, rate_hz: %.17g}", e->frame_rate_hz);
        else
            snprintf(text, sizeof text, "{driver: software}");
        struct nc_cfg tcfg;
        nc_cfg_init(&tcfg);
        e->sinks[k] = (struct trig_sink){e, k};
        struct nc_trigger_ctx tc = {.fire = on_edge, .sink = &e->sinks[k]};
        rc = nc_cfg_load_string(&tcfg, text, "serve");
        if (rc >= 0)
            rc = nc_trigger_open(&e->trig[k], tcfg.root, &tc);
        nc_cfg_free(&tcfg);
        if (rc < 0)
            return rc;
        e->have_trig[k] = 1;
    }
    /* The initial acquisition settings. */
    e->acq = (struct nc_acquisition){
        .triggered = e->mode == MODE_TRIGGER,
        .source = e->configured == TRIG_LINE ? NC_SOURCE_LINE : NC_SOURCE_SOFTWARE,
        .activation = e->have_trig[TRIG_LINE] ? e->trig[TRIG_LINE].gate.activation : NC_TRIGGER_RISING,
        .frame_rate_hz = e->frame_rate_hz,
        .exposure_s = e->cs.exposure_s,
        .gain_db = e->cs.sensor.analog_gain_db,
        .trigger_delay_s = e->have_trig[e->configured] ? e->trig[e->configured].gate.delay_ns * 1e-9 : 0,
    };
    struct nc_output_ctx ctx = {e->scene.camera.width_px, e->scene.camera.height_px, e->cs.sensor.adc_bits, config_dir,
                                &e->control};
    if ((rc = nc_cfg_seq(cfg->root, "outputs", &outs)) < 0)
        return rc;
    if (!outs) { /* default: numbered PNG files and the sidecar under out/ */
        if ((rc = nc_cfg_set(cfg, "outputs=[{driver: file, directory: out}]")) < 0 ||
            (rc = nc_cfg_seq(cfg->root, "outputs", &outs)) < 0)
            return rc;
    }
    if (outs->nchild == 0 || outs->nchild > MAX_OUTPUTS)
        return nc_cfg_error(outs, "expected 1 to %d outputs", MAX_OUTPUTS);
    for (size_t i = 0; i < outs->nchild; i++) {
        outs->child[i]->used = 1;
        if (outs->child[i]->kind != NC_CFG_MAP)
            return nc_cfg_error(outs->child[i], "expected a map with 'driver' and its options");
        if ((rc = nc_output_open(&e->out[e->nout], outs->child[i], &ctx)) < 0)
            return rc;
        e->nout++;
    }
    return 0;
}

/* ---- jobs ------------------------------------------------------------------ */

/* Queue a frame job without ever waiting: when full, drop by policy.
 * Returns 1 when this job was queued. */
static int push_job(struct emu *e, const struct job *j)
{
    pthread_mutex_lock(&e->jlock);
    atomic_fetch_add(&e->jobs_made, 1);
    if (e->jcount == e->queue_frames) {
        atomic_fetch_add(&e->dropped[DROP_QUEUE_FULL], 1);
        if (!e->drop_oldest) {
            pthread_mutex_unlock(&e->jlock);
            return 0; /* the newest job goes */
        }
        e->jhead = (e->jhead + 1) % e->queue_frames; /* the oldest goes */
        e->jcount--;
    }
    e->jobs[(e->jhead + e->jcount) % e->queue_frames] = *j;
    e->jcount++;
    pthread_cond_signal(&e->jcond);
    pthread_mutex_unlock(&e->jlock);
    return 1;
}

static int64_t sim_now(struct emu *e, int64_t mono)
{
    /* Before the first pose the clock counts from the emulator's start. */
    return e->have_anchor ? e->sim_anchor_ns + (mono - e->mono_anchor_ns) : mono - e->start_mono_ns;
}

/* A frame request at simulation time t (gated already): the exposure window
 * under the acquisition settings a, unless the message overrides them. */
static void trigger(struct emu *e, int64_t t_sim, int64_t mono, uint32_t seq, int client, unsigned gen,
                    const char *source, const struct nc_pose_msg *m, const struct nc_acquisition *a, int before_poses)
{
    struct job j = {.trigger_sim_ns = t_sim, .trigger_mono_ns = mono, .ready_mono_ns = mono, .sequence = seq,
                    .client = client, .client_gen = gen, .source = source, .exposure_s = a->exposure_s,
                    .gain_db = a->gain_db, .before_poses = before_poses};
    if (m && (m->flags & NC_MSG_EXPOSURE))
        j.exposure_s = m->exposure_s;
    if (m && (m->flags & NC_MSG_GAIN))
        j.gain_db = m->gain_db;
    /* Lock-step exposes around the requested pose; free-run and triggers
     * start the exposure at the edge (plus the trigger delay). */
    int64_t half = llround(0.5 * j.exposure_s * 1e9);
    j.mid_sim_ns = t_sim;
    if (e->mode != MODE_LOCKSTEP) {
        j.mid_sim_ns = t_sim + (a->triggered ? llround(a->trigger_delay_s * 1e9) : 0) + half;
        j.ready_mono_ns = mono + (j.mid_sim_ns - t_sim) + half;
    }
    if (push_job(e, &j) && e->mode != MODE_LOCKSTEP && e->have_trig[TRIG_LINE]) {
        /* The exposure happens on the wall clock: a strobe line follows it. */
        struct nc_trigger_window w = {.start_mono_ns = j.ready_mono_ns - 2 * half, .end_mono_ns = j.ready_mono_ns};
        nc_trigger_control(&e->trig[TRIG_LINE], "exposure", &w);
    }
}

/* A software request, as the software trigger driver passes it back. */
struct sw_request {
    const struct nc_pose_msg *m;
    int client;
    unsigned gen;
};

static void acq_get(struct emu *e, struct nc_acquisition *a)
{
    pthread_mutex_lock(&e->acq_lock);
    *a = e->acq;
    pthread_mutex_unlock(&e->acq_lock);
}

/* Every edge of every trigger driver. The acquisition settings say whether
 * its source makes frames now; the source's gate filters it; line and timer
 * edges carry CLOCK_MONOTONIC times, mapped onto the simulation clock. */
static void on_edge(void *sink, const struct nc_trigger_edge *edge)
{
    const struct trig_sink *ts = sink;
    struct emu *e = ts->e;
    const struct sw_request *rq = edge->request;
    struct nc_acquisition a;
    acq_get(e, &a);
    int active = ts->kind == TRIG_FREERUN ? !a.triggered
                                          : a.triggered && a.source == (ts->kind == TRIG_LINE ? NC_SOURCE_LINE
                                                                                              : NC_SOURCE_SOFTWARE);
    if (!active) { /* a camera ignores sources it is not set to */
        if (ts->kind == TRIG_SOFTWARE) {
            struct job j = {.trigger_sim_ns = rq ? rq->m->sim_time_ns : 0, .sequence = rq ? rq->m->sequence : 0,
                            .client = rq ? rq->client : -1, .client_gen = rq ? rq->gen : 0};
            drop(e, &j, DROP_IGNORED);
        }
        return;
    }
    if (!nc_trigger_accept(&e->trig[ts->kind], edge))
        return;
    const char *source = ts->kind == TRIG_LINE ? e->trig[TRIG_LINE].drv->name : trig_kind_names[ts->kind];
    if (rq) {
        trigger(e, rq->m->sim_time_ns, edge->mono_ns, rq->m->sequence, rq->client, rq->gen, source, rq->m, &a, 0);
        return;
    }
    pthread_mutex_lock(&e->tl_lock);
    int64_t t = sim_now(e, edge->mono_ns);
    int before = !e->have_anchor;
    pthread_mutex_unlock(&e->tl_lock);
    trigger(e, t, edge->mono_ns, 0, -1, 0, source, NULL, &a, before);
}

/* ---- camera controls (output.h) ------------------------------------------- */

static void control_get(void *emu, struct nc_acquisition *a) { acq_get(emu, a); }

static int control_set(void *emu, const struct nc_acquisition *a)
{
    struct emu *e = emu;
    if (!(a->exposure_s > 0 && a->exposure_s <= 3600) || !(a->gain_db >= -20 && a->gain_db <= 60) ||
        !(a->frame_rate_hz >= 1e-3 && a->frame_rate_hz <= 1000) || !(a->trigger_delay_s >= 0 && a->trigger_delay_s <= 10))
        return nc_error(NC_ERANGE, "acquisition settings out of range: exposure %g s, gain %g dB, rate %g Hz, delay %g s",
                        a->exposure_s, a->gain_db, a->frame_rate_hz, a->trigger_delay_s);
    pthread_mutex_lock(&e->acq_lock);
    struct nc_acquisition old = e->acq;
    int rc = 0;
    if (e->mode == MODE_LOCKSTEP &&
        (a->triggered != old.triggered || a->source != old.source || a->frame_rate_hz != old.frame_rate_hz))
        rc = nc_error(NC_EUNSUPPORTED, "lock-step mode: frames follow the poses; only exposure and gain can change");
    if (rc >= 0 && a->frame_rate_hz != old.frame_rate_hz)
        rc = nc_trigger_control(&e->trig[TRIG_FREERUN], "rate_hz", (void *)&a->frame_rate_hz);
    if (rc >= 0) {
        e->acq = *a;
        if (e->have_trig[TRIG_LINE]) {
            pthread_mutex_lock(&e->trig[TRIG_LINE].lock);
            e->trig[TRIG_LINE].gate.activation = a->activation;
            pthread_mutex_unlock(&e->trig[TRIG_LINE].lock);
        }
    }
    pthread_mutex_unlock(&e->acq_lock);
    return rc;
}

static void control_software_trigger(void *emu)
{
    struct emu *e = emu;
    if (!e->have_trig[TRIG_SOFTWARE]) {
        struct job j = {.client = -1};
        drop(e, &j, DROP_IGNORED);
        return;
    }
    struct nc_trigger_edge edge = {.mono_ns = nc_mono_ns()};
    nc_trigger_control(&e->trig[TRIG_SOFTWARE], "fire", &edge);
}

/* ---- network ---------------------------------------------------------------- */

static void log_reject(struct emu *e, enum nc_reject r, const char *from)
{
    atomic_fetch_add(&e->rejected[r], 1);
    int64_t now = nc_mono_ns();
    if (now - e->last_reject_log_ns > 1000000000) { /* at most one line a second */
        e->last_reject_log_ns = now;
        fprintf(stderr, "navcam serve: rejected a message from %s: %s (counting; further rejections this second not logged)\n",
                from, nc_reject_name(r));
    }
}

static void handle_message(struct emu *e, const uint8_t *buf, size_t len, int client, unsigned gen, const char *from)
{
    struct nc_pose_msg m;
    int64_t now = nc_mono_ns();
    atomic_fetch_add(&e->received, 1);
    enum nc_reject r = nc_msg_decode(buf, len, &m);
    if (r == NC_REJECT_NONE && m.type == NC_MSG_FRAME)
        r = NC_REJECT_BAD_TYPE; /* FRAME goes the other way */
    if (r != NC_REJECT_NONE) {
        log_reject(e, r, from);
        return;
    }
    if (m.type == NC_MSG_POSE) {
        struct nc_pose p;
        nc_pose_from_msg(&m, &p);
        pthread_mutex_lock(&e->tl_lock);
        r = nc_timeline_push(&e->tl, &p);
        if (r == NC_REJECT_NONE) {
            e->sim_anchor_ns = m.sim_time_ns;
            e->mono_anchor_ns = now;
            e->have_anchor = 1;
            pthread_cond_broadcast(&e->tl_cond);
        }
        pthread_mutex_unlock(&e->tl_lock);
        if (r != NC_REJECT_NONE) {
            log_reject(e, r, from);
            return;
        }
        if (!(m.flags & NC_MSG_CAPTURE))
            return;
    } else if (!(m.flags & NC_MSG_CAPTURE)) {
        return; /* a TRIGGER without CAPTURE asks for nothing */
    }
    if (m.type == NC_MSG_POSE && e->mode == MODE_LOCKSTEP) {
        struct nc_acquisition a;
        acq_get(e, &a);
        trigger(e, m.sim_time_ns, now, m.sequence, client, gen, "lockstep", &m, &a, 0);
    } else if (e->have_trig[TRIG_SOFTWARE]) {
        struct sw_request rq = {&m, client, gen};
        struct nc_trigger_edge edge = {.mono_ns = now, .request = &rq};
        nc_trigger_control(&e->trig[TRIG_SOFTWARE], "fire", &edge);
    } else {
        struct job j = {.trigger_sim_ns = m.sim_time_ns, .sequence = m.sequence, .client = client, .client_gen = gen};
        drop(e, &j, DROP_IGNORED);
    }
}

static int open_sockets(struct emu *e)
{
    struct sockaddr_in a = {.sin_family = AF_INET};
    if (inet_pton(AF_INET, e->bind, &a.sin_addr) != 1)
        return nc_error(NC_ECONFIG, "serve.bind: '%s' is not an IPv4 address", e->bind);
    e->udp_fd = e->tcp_fd = -1;
    int one = 1;
    if (e->udp_port) {
        e->udp_fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        a.sin_port = htons((uint16_t)e->udp_port);
        if (e->udp_fd < 0 || bind(e->udp_fd, (struct sockaddr *)&a, sizeof a) < 0)
            return nc_error(-errno, "serve: UDP %s:%d: bind: %s", e->bind, e->udp_port, strerror(errno));
    }
    if (e->tcp_port) {
        e->tcp_fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        a.sin_port = htons((uint16_t)e->tcp_port);
        if (e->tcp_fd < 0 || setsockopt(e->tcp_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) < 0 ||
            bind(e->tcp_fd, (struct sockaddr *)&a, sizeof a) < 0 || listen(e->tcp_fd, 8) < 0)
            return nc_error(-errno, "serve: TCP %s:%d: %s", e->bind, e->tcp_port, strerror(errno));
    }
    for (int i = 0; i < MAX_CLIENTS; i++)
        e->clients[i].fd = -1;
    return 0;
}

static void close_client(struct emu *e, int i)
{
    pthread_mutex_lock(&e->client_lock);
    close(e->clients[i].fd);
    e->clients[i].fd = -1;
    e->clients[i].gen++;
    e->clients[i].have = 0;
    pthread_mutex_unlock(&e->client_lock);
}

/* Consume whole length-prefixed messages from a client's buffer. */
static void client_read(struct emu *e, int i)
{
    struct client *c = &e->clients[i];
    ssize_t n = read(c->fd, c->buf + c->have, sizeof c->buf - c->have);
    if (n <= 0) {
        if (n == 0 || (errno != EAGAIN && errno != EINTR))
            close_client(e, i);
        return;
    }
    c->have += (size_t)n;
    for (;;) {
        if (c->have < 4)
            return;
        uint32_t len = (uint32_t)c->buf[0] | (uint32_t)c->buf[1] << 8 | (uint32_t)c->buf[2] << 16 |
                       (uint32_t)c->buf[3] << 24;
        if (len > NC_PROTO_MAX_BYTES || len < NC_PROTO_HEADER_BYTES + 4) {
            /* The stream cannot be resynchronised: count and disconnect. */
            log_reject(e, len > NC_PROTO_MAX_BYTES ? NC_REJECT_OVERSIZED : NC_REJECT_TRUNCATED, "a TCP client");
            atomic_fetch_add(&e->received, 1);
            close_client(e, i);
            return;
        }
        if (c->have < 4 + len)
            return;
        handle_message(e, c->buf + 4, len, i, c->gen, "a TCP client");
        memmove(c->buf, c->buf + 4 + len, c->have - 4 - len);
        c->have -= 4 + len;
    }
}

static void *net_thread(void *arg)
{
    struct emu *e = arg;
    uint8_t dgram[NC_PROTO_MAX_BYTES + 64];
    while (atomic_load(&e->stop) == 0) {
        struct pollfd pf[2 + MAX_CLIENTS];
        int map[2 + MAX_CLIENTS], n = 0;
        if (e->udp_fd >= 0)
            pf[n] = (struct pollfd){e->udp_fd, POLLIN, 0}, map[n++] = -1;
        if (e->tcp_fd >= 0)
            pf[n] = (struct pollfd){e->tcp_fd, POLLIN, 0}, map[n++] = -2;
        for (int i = 0; i < MAX_CLIENTS; i++)
            if (e->clients[i].fd >= 0)
                pf[n] = (struct pollfd){e->clients[i].fd, POLLIN, 0}, map[n++] = i;
        int r = poll(pf, (nfds_t)n, 50);
        if (r <= 0)
            continue;
        for (int k = 0; k < n; k++) {
            if (!(pf[k].revents & (POLLIN | POLLHUP | POLLERR)))
                continue;
            if (map[k] == -1) {
                for (;;) { /* drain every datagram; MSG_TRUNC reports a datagram's real size */
                    ssize_t got = recv(e->udp_fd, dgram, sizeof dgram, MSG_TRUNC);
                    if (got < 0)
                        break;
                    if ((size_t)got > sizeof dgram) {
                        atomic_fetch_add(&e->received, 1);
                        log_reject(e, NC_REJECT_OVERSIZED, "UDP");
                        continue;
                    }
                    handle_message(e, dgram, (size_t)got, -1, 0, "UDP");
                }
            } else if (map[k] == -2) {
                int fd = accept4(e->tcp_fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
                if (fd < 0)
                    continue;
                int slot = -1;
                for (int i = 0; i < MAX_CLIENTS && slot < 0; i++)
                    if (e->clients[i].fd < 0)
                        slot = i;
                if (slot < 0) {
                    close(fd);
                    continue;
                }
                pthread_mutex_lock(&e->client_lock);
                e->clients[slot].fd = fd;
                e->clients[slot].have = 0;
                pthread_mutex_unlock(&e->client_lock);
            } else {
                client_read(e, map[k]);
            }
        }
    }
    return NULL;
}

/* ---- render ------------------------------------------------------------------ */

static void reply(struct emu *e, const struct job *j, uint64_t frame, uint32_t status)
{
    if (j->client < 0)
        return;
    struct nc_pose_msg m = {.type = NC_MSG_FRAME, .sequence = j->sequence, .sim_time_ns = j->trigger_sim_ns,
                            .frame = frame, .status = status};
    uint8_t buf[4 + NC_PROTO_MAX_BYTES];
    size_t n = nc_msg_encode(&m, buf + 4, NC_PROTO_MAX_BYTES);
    for (int i = 0; i < 4; i++)
        buf[i] = (uint8_t)(n >> (8 * i));
    pthread_mutex_lock(&e->client_lock);
    struct client *c = &e->clients[j->client];
    if (c->fd >= 0 && c->gen == j->client_gen)
        (void)!send(c->fd, buf, 4 + n, MSG_NOSIGNAL);
    pthread_mutex_unlock(&e->client_lock);
}

static void drop(struct emu *e, const struct job *j, enum drop_reason why)
{
    atomic_fetch_add(&e->dropped[why], 1);
    reply(e, j, UINT64_MAX, NC_FRAME_DROPPED);
}

/* The scene's configured pose at time t (no pose received yet). */
static void scene_pose(const struct nc_scene *s, int64_t t, struct nc_pose *p)
{
    *p = (struct nc_pose){.t_ns = t,
                          .cam_position_m = s->camera.position_m,
                          .cam_attitude_q = s->camera.attitude_q,
                          .cam_velocity_m_s = s->camera.velocity_m_s,
                          .cam_angular_velocity_rad_s = s->camera.angular_velocity_rad_s,
                          .sun = s->sun.has_position ? s->sun.position_m : s->sun.direction,
                          .sun_is_position = s->sun.has_position,
                          .has_body = 1,
                          .body_position_m = s->body[0].position_m,
                          .body_attitude_q = s->body[0].attitude_q,
                          .body_velocity_m_s = s->body[0].velocity_m_s,
                          .body_angular_velocity_rad_s = s->body[0].angular_velocity_rad_s};
}

/* Scene poses from a timeline pose. */
static void apply_pose(struct nc_scene *s, const struct nc_pose *p)
{
    s->camera.position_m = p->cam_position_m;
    s->camera.attitude_q = p->cam_attitude_q;
    s->camera.velocity_m_s = p->cam_velocity_m_s;
    s->camera.angular_velocity_rad_s = p->cam_angular_velocity_rad_s;
    if (p->sun_is_position) {
        s->sun.has_position = 1;
        s->sun.position_m = p->sun;
    } else {
        s->sun.has_position = 0;
        s->sun.direction = nc_v3_unit(p->sun);
    }
    if (p->has_body) {
        s->body[0].position_m = p->body_position_m;
        s->body[0].attitude_q = p->body_attitude_q;
    }
    s->body[0].velocity_m_s = p->body_velocity_m_s;
    s->body[0].angular_velocity_rad_s = p->body_angular_velocity_rad_s;
}

static void *render_thread(void *arg)
{
    struct emu *e = arg;
    const int W = e->scene.camera.width_px, H = e->scene.camera.height_px;
    const size_t n = (size_t)W * (size_t)H;
    struct nc_frame f;
    float *el = malloc(n * sizeof *el);
    if (nc_frame_alloc(&f, W, H) < 0 || !el) {
        fprintf(stderr, "navcam serve: out of memory for frames\n");
        atomic_store(&e->stop, 2);
        free(el);
        return NULL;
    }
    /* Sun irradiance scale of the configured scene: a pose's Sun position
     * keeps the configured irradiance law (notes in scene.h). */
    for (;;) {
        pthread_mutex_lock(&e->jlock);
        while (e->jcount == 0 && atomic_load(&e->stop) < 2) {
            atomic_store(&e->render_idle, 1);
            pthread_cond_wait(&e->jcond, &e->jlock);
        }
        if (e->jcount == 0) {
            pthread_mutex_unlock(&e->jlock);
            break;
        }
        atomic_store(&e->render_idle, 0);
        struct job j = e->jobs[e->jhead];
        e->jhead = (e->jhead + 1) % e->queue_frames;
        e->jcount--;
        pthread_mutex_unlock(&e->jlock);
        if (atomic_load(&e->stop) >= 2) {
            drop(e, &j, DROP_SHUTDOWN);
            continue;
        }
        /* Triggered frames are made after the exposure has ended, as in a
         * camera; with serve.pose_wait_s a pose stream lagging the clock gets
         * that much longer to pass mid-exposure, so the pose is interpolated. */
        struct nc_pose pose;
        int64_t gap = 0;
        pthread_mutex_lock(&e->tl_lock);
        for (;;) {
            int64_t now = nc_mono_ns(), until = j.ready_mono_ns;
            if (now >= until && e->mode != MODE_LOCKSTEP && !j.before_poses && e->sim_anchor_ns < j.mid_sim_ns)
                until += e->pose_wait_ns;
            if (now >= until || atomic_load(&e->stop) >= 2)
                break;
            until = until < now + 50000000 ? until : now + 50000000; /* look at stop now and then */
            struct timespec ts = {(time_t)(until / 1000000000), (long)(until % 1000000000)};
            pthread_cond_timedwait(&e->tl_cond, &e->tl_lock, &ts);
        }
        if (atomic_load(&e->stop) >= 2) {
            pthread_mutex_unlock(&e->tl_lock);
            drop(e, &j, DROP_SHUTDOWN);
            continue;
        }
        enum nc_pose_quality q = j.before_poses ? NC_POSE_NONE : nc_timeline_at(&e->tl, j.mid_sim_ns, &pose, &gap);
        pthread_mutex_unlock(&e->tl_lock);
        if (q == NC_POSE_NONE && e->no_pose_scene) {
            scene_pose(&e->scene, j.mid_sim_ns, &pose);
            q = NC_POSE_SCENE;
        }
        if (q == NC_POSE_NONE) {
            drop(e, &j, DROP_NO_POSE);
            continue;
        }
        if (q == NC_POSE_STALE && !e->stale_render) {
            drop(e, &j, DROP_STALE_POSE);
            continue;
        }
        struct nc_scene at = e->scene; /* shallow: shares meshes and materials */
        apply_pose(&at, &pose);
        struct nc_exposure ex = {.exposure_s = j.exposure_s, .rolling = e->cs.sensor.shutter == NC_SHUTTER_ROLLING,
                                 .line_time_s = e->cs.sensor.line_time_s};
        int ts = 1;
        int64_t t0 = nc_mono_ns();
        int rc = nc_render_exposure(&e->renderer, &at, &ex, &f, &ts);
        int64_t t1 = nc_mono_ns();
        /* A free slot for the digitised frame, or drop by policy. */
        pthread_mutex_lock(&e->slock);
        if (e->scount == e->nslots) {
            pthread_mutex_unlock(&e->slock);
            drop(e, &j, DROP_OUTPUT_BUSY);
            continue;
        }
        struct slot *sl = &e->slots[(e->shead + e->scount) % e->nslots];
        pthread_mutex_unlock(&e->slock);
        struct nc_camsys cs = e->cs; /* per-frame gain */
        cs.sensor.analog_gain_db = j.gain_db;
        uint64_t frame = e->next_frame++;
        if (rc >= 0)
            rc = nc_camsys_electrons(&cs, f.radiance, j.exposure_s, el);
        if (rc >= 0)
            rc = nc_camsys_digitise(&cs, el, j.exposure_s, frame, sl->dn);
        int64_t t2 = nc_mono_ns();
        if (rc < 0) {
            fprintf(stderr, "navcam serve: frame %llu: %s\n", (unsigned long long)frame, nc_errmsg());
            drop(e, &j, DROP_OUTPUT_BUSY);
            continue;
        }
        int64_t start_sim = j.mid_sim_ns - (int64_t)llround(0.5 * j.exposure_s * 1e9);
        int64_t start_mono = j.trigger_mono_ns + (start_sim - j.trigger_sim_ns);
        sl->job = j;
        sl->rec = (struct nc_frame_record){
            .frame = frame, .request_sequence = j.sequence, .trigger_source = j.source,
            .trigger_sim_ns = j.trigger_sim_ns, .exposure_start_sim_ns = start_sim,
            .exposure_end_sim_ns = start_sim + (int64_t)llround(j.exposure_s * 1e9),
            .trigger_mono_ns = j.trigger_mono_ns, .exposure_start_mono_ns = start_mono,
            .exposure_end_mono_ns = start_mono + (int64_t)llround(j.exposure_s * 1e9), .pose = pose,
            .pose_quality = q, .pose_gap_ns = gap, .exposure_s = j.exposure_s, .gain_db = j.gain_db,
            .time_samples = ts, .render_ms = (t1 - t0) * 1e-6, .camera_ms = (t2 - t1) * 1e-6, .width_px = W,
            .height_px = H, .adc_bits = cs.sensor.adc_bits, .dn = sl->dn};
        pthread_mutex_lock(&e->slock);
        e->scount++;
        pthread_cond_signal(&e->scond);
        pthread_mutex_unlock(&e->slock);
    }
    nc_frame_free(&f);
    free(el);
    return NULL;
}

/* ---- output ------------------------------------------------------------------ */

static void *output_thread(void *arg)
{
    struct emu *e = arg;
    for (;;) {
        pthread_mutex_lock(&e->slock);
        while (e->scount == 0 && atomic_load(&e->stop) < 3) {
            atomic_store(&e->output_idle, 1);
            pthread_cond_wait(&e->scond, &e->slock);
        }
        if (e->scount == 0) {
            pthread_mutex_unlock(&e->slock);
            break;
        }
        atomic_store(&e->output_idle, 0);
        struct slot *sl = &e->slots[e->shead];
        pthread_mutex_unlock(&e->slock);
        /* Latency: pose received (lock-step) or exposure end (triggered) ->
         * frame handed to the outputs. */
        int64_t handed = nc_mono_ns();
        for (int i = 0; i < e->nout; i++) {
            int orc = nc_output_submit(&e->out[i], &sl->rec);
            if (orc >= 0 || orc == -EAGAIN) /* busy (no free buffer): counted, not logged */
                continue;
            /* One output failing (a device gone) must not flood the log:
             * at most one message a second per output. */
            int64_t now = nc_mono_ns();
            if (e->out_msg_ns[i] && now - e->out_msg_ns[i] < 1000000000) {
                e->out_quiet[i]++;
                continue;
            }
            fprintf(stderr, "navcam serve: output %s: frame %llu: %s", e->out[i].drv->name,
                    (unsigned long long)sl->rec.frame, nc_errmsg());
            if (e->out_quiet[i])
                fprintf(stderr, " (and %lu more failures)", e->out_quiet[i]);
            fputc('\n', stderr);
            e->out_msg_ns[i] = now;
            e->out_quiet[i] = 0;
        }
        pthread_mutex_lock(&e->stat_lock);
        e->lat_ms[e->nlat % LAT_SAMPLES] = (handed - sl->job.ready_mono_ns) * 1e-6;
        e->render_ms[e->nlat % LAT_SAMPLES] = sl->rec.render_ms + sl->rec.camera_ms;
        e->nlat++;
        pthread_mutex_unlock(&e->stat_lock);
        atomic_fetch_add(&e->delivered, 1);
        reply(e, &sl->job, sl->rec.frame, NC_FRAME_DELIVERED);
        pthread_mutex_lock(&e->slock);
        e->shead = (e->shead + 1) % e->nslots;
        e->scount--;
        pthread_mutex_unlock(&e->slock);
    }
    return NULL;
}

/* ---- statistics -------------------------------------------------------------- */

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void percentiles(struct emu *e, double *lat50, double *lat99, double *ren50, double *over99)
{
    pthread_mutex_lock(&e->stat_lock);
    unsigned long n = e->nlat < LAT_SAMPLES ? e->nlat : LAT_SAMPLES;
    double *a = malloc((n ? n : 1) * sizeof *a), *b = malloc((n ? n : 1) * sizeof *b), *o = malloc((n ? n : 1) * sizeof *o);
    for (unsigned long i = 0; a && b && o && i < n; i++) {
        a[i] = e->lat_ms[i];
        b[i] = e->render_ms[i];
        o[i] = e->lat_ms[i] - e->render_ms[i];
    }
    pthread_mutex_unlock(&e->stat_lock);
    *lat50 = *lat99 = *ren50 = *over99 = 0;
    if (n && a && b && o) {
        qsort(a, n, sizeof *a, cmpd);
        qsort(b, n, sizeof *b, cmpd);
        qsort(o, n, sizeof *o, cmpd);
        *lat50 = a[n / 2];
        *lat99 = a[(size_t)(0.99 * (n - 1))];
        *ren50 = b[n / 2];
        *over99 = o[(size_t)(0.99 * (n - 1))];
    }
    free(a);
    free(b);
    free(o);
}

static void stats_line(struct emu *e, double elapsed_s)
{
    double l50, l99, r50, o99;
    percentiles(e, &l50, &l99, &r50, &o99);
    unsigned long rej = 0, drp = 0;
    for (int i = 1; i < NC_REJECT_COUNT; i++)
        rej += atomic_load(&e->rejected[i]);
    for (int i = 0; i < DROP_COUNT; i++)
        drp += atomic_load(&e->dropped[i]);
    fprintf(stderr,
            "navcam serve: %.1f s: frames %lu (%.2f fps), dropped %lu (queue %lu, stale %lu, no pose %lu, output %lu), "
            "messages %lu, rejected %lu, latency p50 %.2f ms p99 %.2f ms\n",
            elapsed_s, atomic_load(&e->delivered), elapsed_s > 0 ? atomic_load(&e->delivered) / elapsed_s : 0.0, drp,
            atomic_load(&e->dropped[DROP_QUEUE_FULL]), atomic_load(&e->dropped[DROP_STALE_POSE]),
            atomic_load(&e->dropped[DROP_NO_POSE]), atomic_load(&e->dropped[DROP_OUTPUT_BUSY]), atomic_load(&e->received),
            rej, l50, l99);
}

static void stats_json(struct emu *e, double elapsed_s, FILE *f)
{
    double l50, l99, r50, o99;
    percentiles(e, &l50, &l99, &r50, &o99);
    fprintf(f, "{\"elapsed_s\": %.3f, \"mode\": \"%s\", \"frames_delivered\": %lu, \"fps\": %.4f, \"messages\": %lu, ",
            elapsed_s, mode_names[e->mode], atomic_load(&e->delivered),
            elapsed_s > 0 ? atomic_load(&e->delivered) / elapsed_s : 0.0, atomic_load(&e->received));
    fprintf(f, "\"rejected\": {");
    for (int i = 1; i < NC_REJECT_COUNT; i++)
        fprintf(f, "%s\"%s\": %lu", i > 1 ? ", " : "", nc_reject_name((enum nc_reject)i), atomic_load(&e->rejected[i]));
    fprintf(f, "}, \"dropped\": {");
    for (int i = 0; i < DROP_COUNT; i++)
        fprintf(f, "%s\"%s\": %lu", i ? ", " : "", drop_names[i], atomic_load(&e->dropped[i]));
    fprintf(f, "}, ");
    if (e->have_configured) { /* the gate of serve.trigger */
        struct nc_trigger *t = &e->trig[e->configured];
        pthread_mutex_lock(&t->lock);
        struct nc_trigger_gate g = t->gate;
        pthread_mutex_unlock(&t->lock);
        fprintf(f, "\"trigger\": {\"driver\": \"%s\", \"edges\": %lu, \"wrong_edge\": %lu, \"debounced\": %lu, "
                   "\"accepted\": %lu}, ",
                t->drv->name, g.edges, g.wrong_edge, g.debounced, g.accepted);
    }
    fprintf(f, "\"latency_p50_ms\": %.3f, \"latency_p99_ms\": %.3f, \"render_camera_p50_ms\": %.3f, "
               "\"overhead_p99_ms\": %.3f, \"outputs\": [",
            l50, l99, r50, o99);
    for (int i = 0; i < e->nout; i++)
        fprintf(f, "%s{\"driver\": \"%s\", \"submitted\": %lu, \"failed\": %lu}", i ? ", " : "", e->out[i].drv->name,
                e->out[i].submitted, e->out[i].failed);
    fprintf(f, "]}\n");
}

/* ---- setup and shutdown ------------------------------------------------------- */

int nc_serve(const struct nc_serve_options *opt)
{
    struct emu *e = calloc(1, sizeof *e);
    if (!e)
        return nc_error(-ENOMEM, "out of memory");
    pthread_mutex_init(&e->acq_lock, NULL);
    e->control = (struct nc_camera_control){e, control_get, control_set, control_software_trigger};
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    char dir[4096] = ".";
    if (opt->scene_path) {
        snprintf(dir, sizeof dir, "%s", opt->scene_path);
        snprintf(dir, sizeof dir, "%s", dirname(dir));
    }
    int rc = nc_cfg_load_scene(&cfg, opt->scene_path, opt->sets, opt->nsets);
    int have_scene = 0, have_cs = 0;
    if (rc >= 0 && (rc = nc_scene_read(&cfg, &e->scene)) >= 0)
        have_scene = 1;
    if (rc >= 0 && (rc = nc_camsys_from_config(cfg.root, &e->scene.camera, e->scene.camera.focal_length_m, &e->cs)) >= 0)
        have_cs = 1;
    if (rc >= 0)
        rc = serve_config(&cfg, e, dir);
    if (rc >= 0)
        rc = nc_cfg_check_unused(&cfg);
    nc_cfg_free(&cfg);
    if (rc >= 0 && !(e->cs.sensor.pixel_pitch_m > 0))
        rc = nc_error(NC_ECONFIG, "serve needs the camera model: give camera.focal_length_m and pixel_pitch_m, or sensor.pixel_pitch_m");
    if (rc >= 0)
        rc = nc_renderer_init(&e->renderer, &e->scene, opt->threads);
    if (rc >= 0)
        rc = open_sockets(e);
    e->nslots = e->queue_frames + 1;
    e->jobs = calloc((size_t)e->queue_frames, sizeof *e->jobs);
    e->slots = calloc((size_t)e->nslots, sizeof *e->slots);
    for (int i = 0; rc >= 0 && e->slots && i < e->nslots; i++)
        if (!(e->slots[i].dn = malloc((size_t)e->scene.camera.width_px * e->scene.camera.height_px * sizeof(uint16_t))))
            rc = nc_error(-ENOMEM, "out of memory");
    if (rc >= 0 && (!e->jobs || !e->slots))
        rc = nc_error(-ENOMEM, "out of memory");
    pthread_t tnet, trender, tout;
    int started = 0;
    if (rc >= 0) {
        pthread_mutex_init(&e->tl_lock, NULL);
        pthread_mutex_init(&e->jlock, NULL);
        pthread_mutex_init(&e->slock, NULL);
        pthread_mutex_init(&e->client_lock, NULL);
        pthread_mutex_init(&e->stat_lock, NULL);
        pthread_cond_init(&e->jcond, NULL);
        pthread_condattr_t ca;
        pthread_condattr_init(&ca);
        pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
        pthread_cond_init(&e->tl_cond, &ca);
        pthread_condattr_destroy(&ca);
        pthread_cond_init(&e->scond, NULL);
        struct sigaction sa = {.sa_handler = on_signal};
        sigemptyset(&sa.sa_mask);
        sigaction(SIGINT, &sa, NULL);
        sigaction(SIGTERM, &sa, NULL);
        e->start_mono_ns = nc_mono_ns();
        pthread_create(&tout, NULL, output_thread, e);
        pthread_create(&trender, NULL, render_thread, e);
        pthread_create(&tnet, NULL, net_thread, e);
        started = 1;
        for (int k = 0; k < 3 && rc >= 0; k++)
            if (e->have_trig[k])
                rc = nc_trigger_start(&e->trig[k]);
        int tk = e->mode == MODE_TRIGGER ? e->configured : -1;
        fprintf(stderr, "navcam serve: %s mode%s%s%s, %dx%d, UDP %s:%d, TCP %s:%d, %d output%s; SIGINT or SIGTERM stops\n",
                mode_names[e->mode], tk >= 0 ? " (" : "", tk >= 0 ? e->trig[tk].drv->name : "",
                tk >= 0 ? " trigger)" : "", e->scene.camera.width_px, e->scene.camera.height_px, e->bind, e->udp_port, e->bind,
                e->tcp_port, e->nout, e->nout == 1 ? "" : "s");
    }
    double next_stats = e->stats_interval_s;
    while (started && rc >= 0 && !got_signal) {
        struct timespec ts = {0, 20000000};
        nanosleep(&ts, NULL);
        double el = (nc_mono_ns() - e->start_mono_ns) * 1e-9;
        unsigned long done = atomic_load(&e->delivered);
        for (int i = 0; i < DROP_COUNT; i++)
            done += i == DROP_IGNORED ? 0 : atomic_load(&e->dropped[i]);
        if ((opt->max_frames > 0 && (long)done >= opt->max_frames) || (opt->max_seconds > 0 && el >= opt->max_seconds))
            break;
        if (e->stats_interval_s > 0 && el >= next_stats) {
            stats_line(e, el);
            next_stats += e->stats_interval_s;
        }
    }
    if (started) {
        /* Stop input, finish the frame in flight, drop what is queued, flush. */
        atomic_store(&e->stop, 1);
        pthread_join(tnet, NULL);
        for (int k = 0; k < 3; k++)
            if (e->have_trig[k])
                nc_trigger_stop(&e->trig[k]);
        atomic_store(&e->stop, 2);
        pthread_mutex_lock(&e->jlock);
        pthread_cond_broadcast(&e->jcond);
        pthread_mutex_unlock(&e->jlock);
        pthread_join(trender, NULL);
        atomic_store(&e->stop, 3);
        pthread_mutex_lock(&e->slock);
        pthread_cond_broadcast(&e->scond);
        pthread_mutex_unlock(&e->slock);
        pthread_join(tout, NULL);
        for (int i = 0; i < e->nout; i++)
            nc_output_control(&e->out[i], "flush", NULL);
        double el = (nc_mono_ns() - e->start_mono_ns) * 1e-9;
        stats_line(e, el);
        stats_json(e, el, stdout);
        if (opt->stats_json_path) {
            FILE *f = fopen(opt->stats_json_path, "w");
            if (f) {
                stats_json(e, el, f);
                fclose(f);
            }
        }
    }
    for (int i = 0; i < e->nout; i++)
        nc_output_close(&e->out[i]);
    for (int k = 0; k < 3; k++)
        if (e->have_trig[k])
            nc_trigger_close(&e->trig[k]);
    for (int i = 0; i < MAX_CLIENTS; i++)
        if (started && e->clients[i].fd >= 0)
            close(e->clients[i].fd);
    if (e->udp_fd > 0)
        close(e->udp_fd);
    if (e->tcp_fd > 0)
        close(e->tcp_fd);
    for (int i = 0; e->slots && i < e->nslots; i++)
        free(e->slots[i].dn);
    free(e->slots);
    free(e->jobs);
    nc_timeline_free(&e->tl);
    if (e->renderer.rt)
        nc_renderer_free(&e->renderer);
    if (have_cs)
        nc_camsys_free(&e->cs);
    if (have_scene)
        nc_scene_free(&e->scene);
    free(e);
    return rc;
}
