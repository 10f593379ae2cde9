/* serve_render.c - the render thread (serve_internal.h): a job -> the pose
 * at mid-exposure -> render with motion smear -> camera model (overlapping
 * the next render, on a thread of its own, outside lock-step) -> a slot for
 * the output thread. The only thread that renders. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "camera/load.h"
#include "camera/quality.h"
#include "camera/shot.h"
#include "emulator/serve_internal.h"

/* The next job, or 0 when the thread is to end (what is still queued then
 * is answered at shutdown, in order, after the frames made). */
static int next_job(struct nc__emu *e, struct nc__job *j)
{
    pthread_mutex_lock(&e->jlock);
    atomic_store(&e->readout_end_ns, 0); /* nothing in hand (the last job rendered or dropped) */
    while (e->jcount == 0 && atomic_load(&e->stop) < 2)
        pthread_cond_wait(&e->jcond, &e->jlock);
    if (e->jcount == 0 || atomic_load(&e->stop) >= 2) {
        pthread_mutex_unlock(&e->jlock);
        return 0;
    }
    *j = e->jobs[e->jhead];
    e->jhead = (e->jhead + 1) % e->queue_frames;
    e->jcount--;
    if (e->mode != NC__MODE_LOCKSTEP) {
        /* The camera is busy from now on: the job waits for its exposure's
         * end and then renders. Until the render starts (and refines it),
         * a trigger must already see that, or it would queue an exposure
         * behind this one and wait a whole render (too_late). */
        double est_ms = nc__serve_busy_ms(e, 0);
        atomic_store(&e->readout_end_ns, est_ms > 0 ? j->ready_mono_ns + llround(est_ms * 1e6) : INT64_MAX);
    }
    pthread_mutex_unlock(&e->jlock);
    return 1;
}

/* Triggered frames are made after the exposure has ended, as in a camera;
 * with serve.pose_wait_s a pose stream lagging the clock gets that much
 * longer to pass mid-exposure, so the pose is interpolated. Returns 0 when
 * shutting down. */
static int pose_for(struct nc__emu *e, const struct nc__job *j, struct nc_pose *pose, enum nc_pose_quality *q,
                    int64_t *gap)
{
    if (j->has_pose) { /* lock-step: exactly the pose sent */
        *pose = j->pose;
        *q = NC_POSE_INTERPOLATED;
        *gap = 0;
        return atomic_load(&e->stop) < 2;
    }
    pthread_mutex_lock(&e->tl_lock);
    for (;;) {
        int64_t now = nc_mono_ns(), until = j->ready_mono_ns;
        /* no pose yet at all: no stream to wait for (the scene's pose or no_pose) */
        if (now >= until && e->mode != NC__MODE_LOCKSTEP && !j->before_poses && e->have_anchor &&
            e->sim_anchor_ns < j->mid_sim_ns)
            until += e->pose_wait_ns;
        if (now >= until || atomic_load(&e->stop) >= 2)
            break;
        until = until < now + 50000000 ? until : now + 50000000; /* look at stop now and then */
        struct timespec ts = {(time_t)(until / 1000000000), (long)(until % 1000000000)};
        pthread_cond_timedwait(&e->tl_cond, &e->tl_lock, &ts);
    }
    if (atomic_load(&e->stop) >= 2) {
        pthread_mutex_unlock(&e->tl_lock);
        return 0;
    }
    *gap = 0;
    *q = j->before_poses ? NC_POSE_NONE : nc_timeline_at(&e->tl, j->mid_sim_ns, pose, gap);
    pthread_mutex_unlock(&e->tl_lock);
    if (*q == NC_POSE_NONE && e->no_pose_scene) {
        nc_scene_pose(&e->scene, j->mid_sim_ns, pose);
        *q = NC_POSE_SCENE;
    }
    return 1;
}

/* The job in hand when shutdown came: answered first at shutdown, before
 * what is still queued (it came before all of it). */
static void hold_job(struct nc__emu *e, const struct nc__job *j)
{
    e->held = *j;
    e->have_held = 1;
}

/* A free slot for the job's result. Lock-step waits for one (it never
 * drops). The other modes hand a frame only to an idle output thread, so
 * that it leaves at once: they wait for the frame before to be taken by
 * every output until the job is due (its exposure's end, plus one frame
 * period, plus render_ns, the render it took: the latency bound of
 * docs/emulator.md, the camera model's time aside) and else drop it
 * (output_busy: an output slower than the render). NULL: none (dropped).
 * The same at shutdown: the frame in flight is finished and delivered (the
 * output thread runs until the render thread has ended). */
static struct nc__slot *free_slot(struct nc__emu *e, const struct nc__job *j, int64_t render_ns)
{
    pthread_mutex_lock(&e->slock);
    while (e->mode == NC__MODE_LOCKSTEP && e->scount == e->nslots)
        pthread_cond_wait(&e->sfree, &e->slock);
    const int64_t due = j->ready_mono_ns + j->period_ns + render_ns;
    while (e->mode != NC__MODE_LOCKSTEP && e->scount > 0 && nc_mono_ns() < due) {
        struct timespec ts = {(time_t)(due / 1000000000), (long)(due % 1000000000)};
        pthread_cond_timedwait(&e->sfree, &e->slock, &ts);
    }
    const int room = e->mode == NC__MODE_LOCKSTEP ? e->scount < e->nslots : e->scount == 0;
    struct nc__slot *sl = room ? &e->slots[(e->shead + e->scount) % e->nslots] : NULL;
    pthread_mutex_unlock(&e->slock);
    if (!sl) /* past the due time (lock-step always has room here) */
        nc__serve_drop(e, j, NC__DROP_OUTPUT_BUSY);
    return sl;
}

static void fill_slot(struct nc__emu *e)
{
    pthread_mutex_lock(&e->slock);
    e->scount++;
    pthread_cond_signal(&e->scond);
    pthread_mutex_unlock(&e->slock);
}

/* A job that makes no frame. Lock-step answers it through the output
 * thread, after the frames before it; the other modes at once. */
static void drop_job(struct nc__emu *e, const struct nc__job *j, enum nc__drop_reason why)
{
    if (e->mode != NC__MODE_LOCKSTEP) {
        nc__serve_drop(e, j, why);
        return;
    }
    struct nc__slot *sl = free_slot(e, j, 0);
    if (!sl)
        return;
    sl->job = *j;
    sl->dropped = 1;
    sl->why = why;
    fill_slot(e);
}

/* A rendered frame on its way to the camera model. */
struct staged {
    struct nc__job j;
    struct nc_pose pose;
    enum nc_pose_quality q;
    int64_t gap, t0, t1; /* render start and end, CLOCK_MONOTONIC */
    int rc, ts, buf;
    unsigned long hits, back_hits; /* camera samples that met a surface, and its back side */
    long in_rock;                  /* the rock the camera is inside (of body in_rock_body), -1: none */
    int in_rock_body;
    struct nc_shot_detail detail; /* the levels of detail, the boulder cut, the fold */
    struct nc_sky_stats stars;
    struct nc_sun_view sun;
    struct nc_render_settings used; /* render.quality: auto's choice, or the scene's */
};

/* A frame whose camera samples mostly met the back, inner side of a
 * surface (a camera inside a body) is warned of in the log when it begins
 * and when it ends, not at every frame; each such frame's record says so. */
static void inside_warning(struct nc__emu *e, const struct staged *x)
{
    const int inside = x->rc >= 0 && (nc_rt_mostly_back(x->hits, x->back_hits) || x->in_rock >= 0);
    if (inside && !e->inside_warned && x->in_rock >= 0)
        nc_log_warn("emulator/render",
                    "frame of request %u: the camera is inside boulder %ld of body %d (rocks are one-sided: it sees "
                    "out of the rock as if it were not there). Logged again when this ends; every such frame's "
                    "record holds \"inside\"", x->j.sequence, x->in_rock, x->in_rock_body);
    else if (inside && !e->inside_warned)
        nc_log_warn("emulator/render",
                    "frame of request %u: %lu of the %lu camera-ray samples that met a surface met its back, inner "
                    "side: is the camera inside a body (or a mesh wound inward)? Logged again when this ends; every "
                    "such frame's record holds \"inside\"",
                    x->j.sequence, x->back_hits, x->hits);
    else if (!inside && e->inside_warned && x->rc >= 0)
        nc_log_info("emulator/render", "frame of request %u: the camera samples no longer meet back sides mostly, nor "
                                         "is the camera inside a boulder",
                    x->j.sequence);
    if (x->rc >= 0)
        e->inside_warned = inside;
}

/* The camera-model stage: in free-run and trigger modes (unless
 * serve.overlap_camera_model is false) its own thread, so that the camera
 * model of frame N runs while frame N+1 renders (two render buffers; the
 * render of N+2 waits until N's buffer is free). Lock-step runs it in the
 * render thread, so that its answers keep request order and a capture at
 * shutdown is answered in turn (hold_job). */
struct stage {
    struct nc__emu *e;
    struct nc_frame f[2];
    float *el;
    pthread_mutex_t lock;
    pthread_cond_t cond;
    struct staged item;
    int full, end, inuse[2];
};

/* A frame's metadata as image attributes into sl (rec.attrs): those of
 * navcam render's dn frame at its pose, with its camera model's settings,
 * its detail, and a WCS when the scene has stars. */
static int frame_attrs(const struct nc__emu *e, const struct staged *x, const struct nc_camsys *cs, uint64_t frame,
                       struct nc__slot *sl)
{
    struct nc_scene at = e->scene; /* shallow: shares meshes and materials */
    nc_scene_apply_pose(&at, &x->pose);
    at.render = x->used;
    int n = nc_frame_meta(&at, NC_Q_DN, sl->attrs, sl->attr_text, 24);
    n += nc_camsys_meta(cs, x->j.exposure_s, frame, sl->attrs + n, sl->attr_text + 24, 6);
    n += nc_shot_detail_attrs(&at, &x->detail, &sl->attr_detail, sl->attrs + n);
    nc_sun_view_text(&x->sun, sl->attr_sun, sizeof sl->attr_sun); /* in or near the field */
    if (sl->attr_sun[0])
        sl->attrs[n++] = (struct nc_image_attr){"navcam:sun_view", sl->attr_sun};
    if (e->sky.on)
        n += nc_shot_wcs_attrs(&at.camera, sl->attr_wcs, sl->attrs + n);
    return n;
}

/* The camera model of one rendered frame into a slot for the output thread. */
static void finish_frame(struct stage *st, const struct staged *x)
{
    struct nc__emu *e = st->e;
    const struct nc__job *j = &x->j;
    struct nc__slot *sl = free_slot(e, j, x->t1 - x->t0);
    if (!sl)
        return;
    int64_t t1 = nc_mono_ns();
    struct nc_camsys cs = e->cs; /* per-frame gain */
    cs.sensor.analog_gain_db = j->gain_db;
    /* The frame's number (which keys its noise) is taken only by a frame
     * made: a failed render leaves no gap in the numbers. */
    uint64_t frame = e->next_frame;
    int rc = x->rc;
    if (rc >= 0)
        rc = nc_camsys_electrons(&cs, st->f[x->buf].radiance, j->exposure_s, st->el);
    if (rc >= 0)
        rc = nc_camsys_digitise(&cs, st->el, j->exposure_s, frame, sl->dn);
    int64_t t2 = nc_mono_ns();
    if (rc < 0) {
        nc_log_error("emulator/render", "request %u at t_sim %.9f s: %s", j->sequence, j->trigger_sim_ns * 1e-9,
                     nc_errmsg());
        if (e->mode != NC__MODE_LOCKSTEP) {
            nc__serve_drop(e, j, NC__DROP_RENDER_ERROR);
            return;
        }
        sl->job = *j; /* the slot is ours: answer in order */
        sl->dropped = 1;
        sl->why = NC__DROP_RENDER_ERROR;
        fill_slot(e);
        return;
    }
    e->next_frame++;
    int64_t exp_ns, start_sim, start_mono;
    nc__job_exposure(j, &start_sim, &start_mono, &exp_ns);
    sl->job = *j;
    sl->dropped = 0;
    sl->render_start_mono_ns = x->t0;
    sl->rec = (struct nc_frame_record){
        .frame = frame, .request_sequence = j->sequence, .trigger_source = j->source,
        .trigger_sim_ns = j->trigger_sim_ns, .exposure_start_sim_ns = start_sim,
        .exposure_end_sim_ns = start_sim + exp_ns, .trigger_mono_ns = j->trigger_mono_ns,
        .exposure_start_mono_ns = start_mono, .exposure_end_mono_ns = start_mono + exp_ns, .pose = x->pose,
        .pose_quality = x->q, .pose_gap_ns = x->gap, .exposure_s = j->exposure_s, .gain_db = j->gain_db,
        .time_samples = x->ts, .lod_error_m = x->detail.lod_error_m, .boulder_min_m = x->detail.boulder_min_m,
        .boulder_mesh_px = x->detail.boulder_mesh_px,
        .rock_fold_theta_bar_deg = x->detail.fold_max_deg, .samples_per_pixel = x->used.samples_per_pixel,
        .bounces = x->used.bounces, .soft_shadows = x->used.soft_shadows, .quality_auto = x->used.quality_auto,
        .stars_on = e->sky.on, .star_limit_mag = x->stars.limit_mag, .stars_drawn = x->stars.drawn,
        .stars_hidden = x->stars.hidden, .sun_off_axis_deg = x->sun.off_axis_deg, .sun_edge_deg = x->sun.edge_deg,
        .sun_in_field = x->sun.in_field, .sun_near_field = x->sun.near_field, .sun_hidden = x->sun.hidden,
        .hit_samples = x->hits, .back_samples = x->back_hits, .in_rock1 = x->in_rock + 1,
        .in_rock_body = x->in_rock_body, .render_ms = (x->t1 - x->t0) * 1e-6,
        .camera_ms = (t2 - t1) * 1e-6, .width_px = cs.width_px, .height_px = cs.height_px,
        .adc_bits = cs.sensor.adc_bits, .dn = sl->dn, .attrs = sl->attrs};
    sl->rec.nattrs = frame_attrs(e, x, &cs, frame, sl);
    fill_slot(e);
}

static void *camera_thread(void *arg)
{
    struct stage *st = arg;
    pthread_mutex_lock(&st->lock);
    for (;;) {
        while (!st->full && !st->end)
            pthread_cond_wait(&st->cond, &st->lock);
        if (!st->full)
            break; /* ended, and nothing left */
        struct staged x = st->item;
        st->full = 0;
        pthread_cond_broadcast(&st->cond);
        pthread_mutex_unlock(&st->lock);
        finish_frame(st, &x);
        pthread_mutex_lock(&st->lock);
        st->inuse[x.buf] = 0;
        pthread_cond_broadcast(&st->cond);
    }
    pthread_mutex_unlock(&st->lock);
    return NULL;
}

/* Render buffer b, once the camera model is done with it. */
static struct nc_frame *take_buffer(struct stage *st, int b)
{
    pthread_mutex_lock(&st->lock);
    while (st->inuse[b])
        pthread_cond_wait(&st->cond, &st->lock);
    pthread_mutex_unlock(&st->lock);
    return &st->f[b];
}

static void hand_over(struct stage *st, const struct staged *x)
{
    pthread_mutex_lock(&st->lock);
    while (st->full)
        pthread_cond_wait(&st->cond, &st->lock);
    st->item = *x;
    st->full = 1;
    st->inuse[x->buf] = 1;
    pthread_cond_broadcast(&st->cond);
    pthread_mutex_unlock(&st->lock);
}

/* The render loop proper: jobs until shutdown, each rendered into the next
 * buffer and finished in line (lock-step) or handed to the camera thread. */
static void render_loop(struct nc__emu *e, struct stage *st, int overlap)
{
    struct nc__job j;
    int buf = 0;
    while (!e->have_held && next_job(e, &j)) {
        struct staged x = {.j = j};
        if (j.refused) {
            drop_job(e, &j, j.refused_why);
            continue;
        }
        if (!pose_for(e, &j, &x.pose, &x.q, &x.gap)) {
            hold_job(e, &j); /* shutting down: answered with the rest of the queue */
            break;
        }
        if (x.q == NC_POSE_NONE) {
            drop_job(e, &j, NC__DROP_NO_POSE);
            continue;
        }
        if (x.q == NC_POSE_STALE && !e->stale_render) {
            drop_job(e, &j, NC__DROP_STALE_POSE);
            continue;
        }
        struct nc_scene at = e->scene; /* shallow: shares meshes and materials */
        nc_scene_apply_pose(&at, &x.pose);
        nc_camsys_render_camera(&e->cs, &at.camera, &at.camera);
        struct nc_exposure ex = {.exposure_s = j.exposure_s, .rolling = e->cs.sensor.shutter == NC_SHUTTER_ROLLING,
                                 .line_time_s = e->cs.sensor.line_time_s};
        struct nc_frame *f = take_buffer(st, buf);
        x.ts = 1;
        x.buf = buf;
        x.t0 = nc_mono_ns(); /* from here on the frame is being read out */
        if (j.period_ns && x.t0 - j.ready_mono_ns > j.period_ns + e->pose_wait_ns) {
            /* The frame before ran longer than its estimate: this one would
             * leave more than a period late, so it is an overrun after all. */
            nc__serve_drop(e, &j, NC__DROP_OVERRUN);
            continue;
        }
        double est_ms = nc__serve_busy_ms(e, 0); /* 0: the warm-up failed, and no frame yet */
        atomic_store(&e->readout_end_ns, est_ms > 0 ? x.t0 + llround(est_ms * 1e6) : INT64_MAX);
        struct nc_quality_choice qc; /* render.quality: auto, per frame (its pilots count as render time) */
        x.rc = at.render.quality_auto ? nc_quality_auto(&e->renderer, &at, &e->cs, j.exposure_s, &qc) : 0;
        x.used = at.render;
        struct nc_rt_stats st0, st1;
        nc_rt_get_stats(e->renderer.rt, &st0);
        if (x.rc >= 0)
            x.rc = nc_render_exposure(&e->renderer, &at, &ex, f, &x.ts);
        nc_rt_get_stats(e->renderer.rt, &st1);
        x.hits = st1.camera_hits - st0.camera_hits;
        x.back_hits = st1.camera_back_hits - st0.camera_back_hits;
        x.in_rock = nc_rt_camera_in_rock(&st1, at.nbodies, &x.in_rock_body);
        inside_warning(e, &x);
        if (x.rc >= 0 && e->sky.on) /* stars at the mid-exposure time, through this frame's exposure */
            x.rc = nc_sky_draw(&e->sky, &e->renderer, &e->cs, &at, j.mid_sim_ns * 1e-9, j.exposure_s, f, &x.stars);
        if (x.rc >= 0) /* the Sun drawn if its disk reaches the frame; in the record if in or near it */
            x.rc = nc_render_sun(&e->renderer, &at, NC_SUN_NEAR_DEG, f, &x.sun);
        x.t1 = nc_mono_ns();
        nc_shot_detail_of(&e->renderer, at.nbodies, &x.detail);
        if (overlap) {
            atomic_store(&e->readout_end_ns, 0); /* the next exposure may start rendering */
            hand_over(st, &x);
            buf ^= 1;
        } else {
            finish_frame(st, &x);
            atomic_store(&e->readout_end_ns, 0);
        }
    }
}

void *nc__serve_render_thread(void *arg)
{
    struct nc__emu *e = arg;
    const size_t n = (size_t)e->cs.width_px * (size_t)e->cs.height_px;
    const int overlap = e->overlap;
    struct stage st = {.e = e, .el = malloc(n * sizeof(float))};
    pthread_mutex_init(&st.lock, NULL);
    pthread_cond_init(&st.cond, NULL);
    pthread_t cam;
    /* The camera model's render size: the sensor and the PSF's margin. */
    int ok = st.el && nc_frame_alloc(&st.f[0], e->cs.render_width_px, e->cs.render_height_px) >= 0 &&
             (!overlap || nc_frame_alloc(&st.f[1], e->cs.render_width_px, e->cs.render_height_px) >= 0);
    if (!ok)
        nc_log_error("emulator/render", "out of memory for frames");
    /* A warm-up frame of the configured pose, discarded: the first frame
     * served does not pay for first-touch memory, the render threads' start
     * and lazy library set-up (nc_serve starts the triggers after it). */
    if (ok) {
        struct nc_scene warm = e->scene;
        struct nc_pose p0;
        nc_scene_pose(&e->scene, 0, &p0);
        nc_scene_apply_pose(&warm, &p0);
        nc_camsys_render_camera(&e->cs, &warm.camera, &warm.camera);
        const int64_t t0 = nc_mono_ns();
        if (nc_render_frame(&e->renderer, &warm, &st.f[0]) >= 0) {
            const int64_t t1 = nc_mono_ns();
            nc_camsys_electrons(&e->cs, st.f[0].radiance, e->cs.exposure_s, st.el);
            /* the busy time until a frame served gives one (nc__serve_busy_ms): a slight overestimate, the
             * warm-up's first touches in it (infinite before: every trigger in the first frame's time an
             * overrun) */
            const double render_ms = (t1 - t0) * 1e-6, camera_ms = (nc_mono_ns() - t1) * 1e-6;
            e->warm_busy_ms = overlap ? fmax(render_ms, camera_ms) : render_ms + camera_ms;
        }
    }
    int err = ok && overlap ? pthread_create(&cam, NULL, camera_thread, &st) : 0;
    if (err) {
        nc_log_error("emulator/render", "cannot start the camera-model thread: %s", strerror(err));
        ok = 0;
    }
    if (!ok) {
        atomic_store(&e->failed, err ? -err : -ENOMEM);
        atomic_store(&e->stop, 2);
    } else {
        atomic_store(&e->warm, 1);
        render_loop(e, &st, overlap);
    }
    if (ok && overlap) {
        pthread_mutex_lock(&st.lock);
        st.end = 1;
        pthread_cond_broadcast(&st.cond);
        pthread_mutex_unlock(&st.lock);
        pthread_join(cam, NULL); /* it finishes the frame handed over last */
    }
    pthread_cond_destroy(&st.cond);
    pthread_mutex_destroy(&st.lock);
    nc_frame_free(&st.f[0]);
    nc_frame_free(&st.f[1]);
    free(st.el);
    return NULL;
}
