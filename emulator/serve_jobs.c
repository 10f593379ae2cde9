/* serve_jobs.c - from a trigger to a frame job (serve_internal.h): lock-step
 * requests, software commands and accepted trigger events become exposure
 * windows in the bounded job queue; drops are counted and answered; the
 * camera controls that output drivers call (output.h). Never waits: pose
 * input and trigger threads call in here. */
#include <errno.h>
#include <math.h>
#include <string.h>
#include <sys/socket.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "emulator/serve_internal.h"

const char *const nc__serve_drop_names[] = {
    "queue_full", "overrun", "stale_pose", "no_pose", "output_busy", "shutdown", "ignored_request", "rejected_request",
    "render_error", "output_failed"};

void nc__serve_flush_client(struct nc__emu *e, struct nc__client *c)
{
    size_t sent = 0;
    while (c->fd >= 0 && sent < c->out_len) {
        ssize_t w = send(c->fd, c->out + sent, c->out_len - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
            sent = c->out_len; /* the connection is broken (EPIPE, ECONNRESET): no one reads them */
            break;
        }
        if (w <= 0)
            break; /* EAGAIN: the net thread sends the rest when the socket takes it */
        sent += (size_t)w;
    }
    memmove(c->out, c->out + sent, c->out_len - sent);
    c->out_len -= sent;
}

size_t nc__serve_encode_tcp(const struct nc_pose_msg *m, uint8_t *buf)
{
    size_t n = nc_msg_encode(m, buf + 4, NC_PROTO_MAX_BYTES);
    for (int i = 0; i < 4; i++)
        buf[i] = (uint8_t)(n >> (8 * i));
    return n;
}

void nc__serve_reply(struct nc__emu *e, const struct nc__job *j, uint64_t frame, uint32_t status)
{
    if (j->client < 0)
        return;
    struct nc_pose_msg m = {.type = NC_MSG_FRAME, .sequence = j->sequence, .sim_time_ns = j->trigger_sim_ns,
                            .frame = frame, .status = status};
    uint8_t buf[4 + NC_PROTO_MAX_BYTES];
    size_t n = nc__serve_encode_tcp(&m, buf);
    pthread_mutex_lock(&e->client_lock);
    struct nc__client *c = &e->clients[j->client];
    if (c->fd >= 0 && c->gen == j->client_gen) {
        if (c->out_len + 4 + n > sizeof c->out) {
            /* A client that reads none of its answers must not hold up the
             * others: it is disconnected, and said so. */
            nc_log_warn("emulator/net", "a TCP client read none of its last %zu answers: disconnected",
                        c->out_len / (4 + n));
            e->slow_clients++;
            shutdown(c->fd, SHUT_RDWR);
            c->gen++; /* its remaining answers go nowhere, unlogged (the net thread closes the socket) */
            c->out_len = 0;
        } else {
            memcpy(c->out + c->out_len, buf, 4 + n);
            c->out_len += 4 + n;
            nc__serve_flush_client(e, c);
        }
    }
    pthread_mutex_unlock(&e->client_lock);
}

int nc__serve_queue_full(struct nc__emu *e)
{
    pthread_mutex_lock(&e->jlock);
    int full = e->jcount == e->job_cap;
    pthread_mutex_unlock(&e->jlock);
    return full;
}

void nc__serve_drop(struct nc__emu *e, const struct nc__job *j, enum nc__drop_reason why)
{
    atomic_fetch_add(&e->dropped[why], 1);
    nc__serve_reply(e, j, UINT64_MAX, NC_FRAME_DROPPED);
}

/* Free-run and trigger modes: a tick or trigger whose exposure would wait
 * after its end for the frame being rendered longer than the time since the
 * trigger before it (one frame period) is an overrun, so every frame leaves
 * at most one period plus one render after its exposure, and the camera runs
 * at the rate its render allows (jlock held). */
static int too_late(struct nc__emu *e, struct nc__job *j)
{
    int64_t busy = atomic_load(&e->readout_end_ns);
    j->period_ns = e->last_trigger_mono_ns ? j->trigger_mono_ns - e->last_trigger_mono_ns : 0;
    e->last_trigger_mono_ns = j->trigger_mono_ns;
    return busy && j->period_ns && busy - j->ready_mono_ns > j->period_ns;
}

/* Queue a frame job without ever waiting. Free-run and trigger: a trigger
 * too late for the render (too_late) is an overrun; the camera holds one
 * exposure waiting for readout (job_cap 1), and a trigger while it does is
 * an overrun too: the new one is ignored (drop_newest, as a camera does)
 * or replaces the waiting one (drop_oldest). Lock-step over UDP: queue_full.
 * Returns 1 when this job was queued. */
static int push_job(struct nc__emu *e, struct nc__job *j)
{
    pthread_mutex_lock(&e->jlock);
    int64_t start_sim, start, len;
    nc__job_exposure(j, &start_sim, &start, &len);
    /* One sensor: an exposure cannot begin before the one before it ends. */
    if (e->mode != NC__MODE_LOCKSTEP && (too_late(e, j) || start < e->last_exposure_end_mono_ns)) {
        pthread_mutex_unlock(&e->jlock);
        nc__serve_drop(e, j, NC__DROP_OVERRUN); /* counted, and answered if a TCP client asked */
        return 0;
    }
    struct nc__job oldest;
    int replaced = 0;
    if (e->jcount == e->job_cap) {
        const enum nc__drop_reason why = e->mode == NC__MODE_LOCKSTEP ? NC__DROP_QUEUE_FULL : NC__DROP_OVERRUN;
        if (!e->drop_oldest || e->mode == NC__MODE_LOCKSTEP) {
            pthread_mutex_unlock(&e->jlock);
            nc__serve_drop(e, j, why); /* the newest job goes */
            return 0;
        }
        oldest = e->jobs[e->jhead]; /* the oldest goes */
        replaced = 1;
        e->jhead = (e->jhead + 1) % e->queue_frames;
        e->jcount--;
    }
    e->jobs[(e->jhead + e->jcount) % e->queue_frames] = *j;
    e->jcount++;
    if (e->mode != NC__MODE_LOCKSTEP)
        e->last_exposure_end_mono_ns = start + len;
    pthread_cond_signal(&e->jcond);
    pthread_mutex_unlock(&e->jlock);
    if (replaced)
        nc__serve_drop(e, &oldest, NC__DROP_OVERRUN);
    return 1;
}

/* A triggered exposure: the trigger at t_sim (edge_mono on CLOCK_MONOTONIC),
 * the exposure from start_mono (the edge plus the trigger delay) under the
 * acquisition settings a, unless the message overrides them. */
static void expose(struct nc__emu *e, int64_t t_sim, int64_t edge_mono, int64_t start_mono, const char *source,
                   const struct nc_pose_msg *m, int client, unsigned gen, const struct nc_acquisition *a, int before_poses)
{
    struct nc__job j = {.trigger_sim_ns = t_sim, .trigger_mono_ns = edge_mono, .sequence = m ? m->sequence : 0,
                        .client = client, .client_gen = gen, .source = source, .exposure_s = a->exposure_s,
                        .gain_db = a->gain_db, .before_poses = before_poses};
    if (m && (m->flags & NC_MSG_EXPOSURE))
        j.exposure_s = m->exposure_s;
    if (m && (m->flags & NC_MSG_GAIN))
        j.gain_db = m->gain_db;
    int64_t half = llround(0.5 * j.exposure_s * 1e9);
    j.mid_sim_ns = t_sim + (start_mono - edge_mono) + half;
    j.ready_mono_ns = start_mono + 2 * half;
    if (push_job(e, &j) && e->have_line) {
        /* The exposure happens on the wall clock: a strobe line follows it. */
        struct nc_trigger_window w = {.start_mono_ns = start_mono, .end_mono_ns = j.ready_mono_ns};
        nc_trigger_control(&e->line, "exposure", &w);
    }
}

static int64_t sim_now(struct nc__emu *e, int64_t mono, int *before_poses)
{
    /* Before the first pose the clock counts from the emulator's start. */
    pthread_mutex_lock(&e->tl_lock);
    *before_poses = !e->have_anchor;
    int64_t t = e->have_anchor ? e->sim_anchor_ns + (mono - e->mono_anchor_ns) : mono - e->start_mono_ns;
    pthread_mutex_unlock(&e->tl_lock);
    return t;
}

void nc__serve_lockstep(struct nc__emu *e, const struct nc_pose_msg *m, int client, unsigned gen, int64_t mono)
{
    struct nc_acquisition a;
    nc__serve_acq_get(e, &a);
    /* Lock-step exposes around the requested pose; the frame can be read
     * out as soon as the request is here. */
    struct nc__job j = {.trigger_sim_ns = m->sim_time_ns, .mid_sim_ns = m->sim_time_ns, .trigger_mono_ns = mono,
                        .ready_mono_ns = mono, .sequence = m->sequence, .client = client, .client_gen = gen,
                        .source = "lockstep", .exposure_s = a.exposure_s, .gain_db = a.gain_db, .has_pose = 1};
    nc_pose_from_msg(m, &j.pose);
    nc_scene_pose_body(&e->scene, &j.pose);
    if (m->flags & NC_MSG_EXPOSURE)
        j.exposure_s = m->exposure_s;
    if (m->flags & NC_MSG_GAIN)
        j.gain_db = m->gain_db;
    push_job(e, &j);
}

/* A request answered "dropped" for why: a TCP client's in lock-step through
 * the queue, so that every answer keeps its request's order (the client's
 * next request waits while the queue is full); else at once. */
static void refuse(struct nc__emu *e, struct nc__job *j, enum nc__drop_reason why)
{
    j->refused = 1;
    j->refused_why = why;
    if (e->mode == NC__MODE_LOCKSTEP && j->client >= 0)
        push_job(e, j);
    else
        nc__serve_drop(e, j, why);
}

void nc__serve_refused_capture(struct nc__emu *e, const struct nc_pose_msg *m, int client, unsigned gen)
{
    struct nc__job j = {.trigger_sim_ns = m->sim_time_ns, .sequence = m->sequence, .client = client,
                        .client_gen = gen};
    refuse(e, &j, NC__DROP_REJECTED);
}

/* A software command (m: the TRIGGER or POSE message that asked, or NULL
 * for a client's TriggerSoftware): straight to the job queue when the
 * camera is triggered by software, else counted and answered as ignored. */
void nc__serve_software(struct nc__emu *e, const struct nc_pose_msg *m, int client, unsigned gen, int64_t mono)
{
    pthread_mutex_lock(&e->acq_lock);
    struct nc_acquisition a = e->acq;
    int active = e->mode != NC__MODE_LOCKSTEP && a.triggered && a.source == NC_SOURCE_SOFTWARE;
    if (active) {
        e->software_counts.edges++;
        e->software_counts.accepted++;
    }
    pthread_mutex_unlock(&e->acq_lock);
    if (!active) {
        struct nc__job j = {.trigger_sim_ns = m ? m->sim_time_ns : 0, .sequence = m ? m->sequence : 0,
                            .client = client, .client_gen = gen};
        refuse(e, &j, NC__DROP_IGNORED);
        return;
    }
    int before = 0;
    int64_t t = m ? m->sim_time_ns : sim_now(e, mono, &before);
    expose(e, t, mono, mono + llround(a.trigger_delay_s * 1e9), "software", m, client, gen, &a, before);
}

/* Accepted edges of the free-run timer and of the trigger line (their gates
 * have filtered them, and only the source the acquisition is set to is
 * enabled); the check below covers an edge racing a change of settings. */
static void on_event(struct nc__emu *e, const struct nc_trigger_event *ev, int line)
{
    struct nc_acquisition a;
    nc__serve_acq_get(e, &a);
    if (line ? !(a.triggered && a.source == NC_SOURCE_LINE) : a.triggered)
        return; /* a camera ignores sources it is not set to */
    int before;
    int64_t t = sim_now(e, ev->edge_mono_ns, &before);
    expose(e, t, ev->edge_mono_ns, ev->start_mono_ns, line ? e->line.drv->name : "freerun", NULL, -1, 0, &a, before);
}

void nc__serve_on_freerun(void *arg, const struct nc_trigger_event *ev) { on_event(arg, ev, 0); }
void nc__serve_on_line(void *arg, const struct nc_trigger_event *ev) { on_event(arg, ev, 1); }

/* ---- camera controls (output.h) ------------------------------------------- */

void nc__serve_acq_get(struct nc__emu *e, struct nc_acquisition *a)
{
    pthread_mutex_lock(&e->acq_lock);
    *a = e->acq;
    pthread_mutex_unlock(&e->acq_lock);
}

static void control_get(void *emu, struct nc_acquisition *a) { nc__serve_acq_get(emu, a); }

static int control_set(void *emu, const struct nc_acquisition *a)
{
    struct nc__emu *e = emu;
    if (!(a->exposure_s > 0 && a->exposure_s <= 3600) || !(a->gain_db >= -20 && a->gain_db <= 60) ||
        !(a->frame_rate_hz >= 1e-3 && a->frame_rate_hz <= 1000) || !(a->trigger_delay_s >= 0 && a->trigger_delay_s <= 10))
        return nc_error(NC_ERANGE, "acquisition settings out of range: exposure %g s, gain %g dB, rate %g Hz, delay %g s",
                        a->exposure_s, a->gain_db, a->frame_rate_hz, a->trigger_delay_s);
    if (a->source == NC_SOURCE_LINE && !e->have_line)
        return nc_error(NC_EUNSUPPORTED, "trigger source Line0: serve.trigger names no line (gpio, usb or timer)");
    pthread_mutex_lock(&e->acq_lock);
    struct nc_acquisition old = e->acq;
    int rc = 0;
    if (e->mode == NC__MODE_LOCKSTEP &&
        (a->triggered != old.triggered || a->source != old.source || a->frame_rate_hz != old.frame_rate_hz))
        rc = nc_error(NC_EUNSUPPORTED, "lock-step mode: frames follow the poses; the trigger mode, source and frame "
                                       "rate cannot change (exposure, gain, trigger activation and delay can)");
    if (rc >= 0 && a->frame_rate_hz != old.frame_rate_hz && e->have_freerun)
        rc = nc_trigger_control(&e->freerun, "rate_hz", (void *)&a->frame_rate_hz);
    if (rc >= 0) {
        e->acq = *a;
        nc__serve_enable_sources(e);
    }
    pthread_mutex_unlock(&e->acq_lock);
    return rc;
}

void nc__serve_enable_sources(struct nc__emu *e)
{
    const struct nc_acquisition *a = &e->acq;
    if (e->have_freerun)
        nc_trigger_enable(&e->freerun, !a->triggered);
    if (e->have_line) {
        nc_trigger_set_gate(&e->line, a->activation, llround(a->trigger_delay_s * 1e9));
        nc_trigger_enable(&e->line, a->triggered && a->source == NC_SOURCE_LINE);
    }
}

static void control_software_trigger(void *emu) { nc__serve_software(emu, NULL, -1, 0, nc_mono_ns()); }
static double control_resulting_rate(void *emu) { return nc__serve_resulting_rate_hz(emu); }

void nc__serve_init_control(struct nc__emu *e)
{
    e->control = (struct nc_camera_control){e, control_get, control_set, control_software_trigger,
                                            control_resulting_rate};
}
