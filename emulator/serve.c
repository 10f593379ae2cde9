/* serve.c - the emulator's life cycle (serve.h, serve_internal.h): set-up,
 * the threads, the supervising loop (limits, periodic statistics, the
 * caller's stop flag) and an orderly shutdown.
 *
 * net thread     serve_net.c: poses into the timeline, requests into jobs
 * triggers       the free-run timer and the line of serve.trigger fire
 *                events through their gates (trigger.h) into serve_jobs.c
 * render thread  serve_render.c: job -> pose -> render -> camera model -> slot
 * output thread  serve_output.c: slot -> every output driver -> FRAME answer
 * this thread    supervises; it installs no signal handler (the program does)
 */
#include <errno.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "camera/camsys.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "core/proc.h"
#include "emulator/serve_internal.h"

/* Scene, camera model, serve section and outputs from the configuration. */
static int setup(struct nc__emu *e, const struct nc_serve_options *opt, int *have_scene, int *have_cs)
{
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    char dir[4096] = ".";
    if (opt->scene_path) {
        char path[4096]; /* dirname may return a pointer into its argument */
        snprintf(path, sizeof path, "%s", opt->scene_path);
        snprintf(dir, sizeof dir, "%s", dirname(path));
    }
    int rc = nc_cfg_load_scene(&cfg, opt->scene_path, opt->sets, opt->nsets);
    if (rc >= 0) /* the serve section, trigger and outputs checked before the scene is built */
        rc = nc__serve_config(&cfg, e, dir, 1);
    /* Then every section but the bodies, each checked, and the bodies last. */
    if (rc >= 0 && (rc = nc_scene_read_view(&cfg, &e->scene)) >= 0)
        *have_scene = 1;
    if (rc >= 0 &&
        (rc = nc_camsys_from_config(cfg.root, &e->scene.camera, e->scene.camera.focal_length_m, &e->cs)) >= 0)
        *have_cs = 1;
    if (rc >= 0)
        rc = nc_camsys_check_sections(&cfg);
    if (rc >= 0)
        rc = nc_sky_from_config(&cfg, &e->sky);
    if (rc >= 0)
        rc = nc_scene_check_sections(&cfg);
    if (rc >= 0)
        rc = nc_scene_read_bodies(&cfg, &e->scene);
    if (rc >= 0)
        rc = nc__serve_config(&cfg, e, dir, 0);
    if (rc >= 0)
        rc = nc_cfg_check_unused(&cfg);
    nc_cfg_free(&cfg);
    if (rc >= 0 && !(e->cs.sensor.pixel_pitch_m > 0))
        rc = nc_error(NC_ECONFIG,
                      "serve needs the camera model: give camera.focal_length_m and pixel_pitch_m, or sensor.pixel_pitch_m");
    if (rc >= 0 && (e->scene.camera.flip_rows || e->scene.camera.flip_cols))
        nc_log_warn("camera", "the SUM file's K-MATRIX mirrors its image (%s), but serve delivers the view "
                    "unmirrored, +X along CX and +Y along CY (docs/sumfiles.md)",
                    e->scene.camera.flip_rows ? (e->scene.camera.flip_cols ? "K11 < 0 and K22 < 0" : "K22 < 0")
                                              : "K11 < 0");
    /* the frames are the view: nothing mirrored, a rolling shutter reading the view's rows from the top */
    e->scene.camera.flip_rows = e->scene.camera.flip_cols = 0;
    if (rc >= 0)
        rc = nc_sky_prepare(&e->sky, &e->cs, &e->scene.camera);
    if (rc >= 0)
        rc = nc_renderer_init(&e->renderer, &e->scene, opt->threads);
    if (rc >= 0 && !(e->clients = calloc((size_t)e->max_clients, sizeof *e->clients)))
        rc = nc_error(-ENOMEM, "out of memory");
    for (int i = 0; rc >= 0 && i < e->max_clients; i++)
        e->clients[i].fd = -1;
    if (rc >= 0)
        rc = nc__serve_open_sockets(e);
    if (rc < 0)
        return rc;
    /* Lock-step queues what the simulator asks for; a triggered camera holds
     * one exposure waiting for readout, and one finished frame may wait
     * while the outputs send the one before (docs/emulator.md, overload). */
    e->job_cap = e->mode == NC__MODE_LOCKSTEP ? e->queue_frames : 1;
    e->nslots = e->mode == NC__MODE_LOCKSTEP ? e->queue_frames + 1 : 2;
    e->jobs = calloc((size_t)e->queue_frames, sizeof *e->jobs);
    e->slots = calloc((size_t)e->nslots, sizeof *e->slots);
    if (!e->jobs || !e->slots)
        return nc_error(-ENOMEM, "out of memory");
    const size_t dn_bytes = (size_t)e->scene.camera.width_px * e->scene.camera.height_px * sizeof(uint16_t);
    for (int i = 0; i < e->nslots; i++) {
        if (!(e->slots[i].dn = malloc(dn_bytes)))
            return nc_error(-ENOMEM, "out of memory");
        nc_touch_pages(e->slots[i].dn, dn_bytes); /* faulted in now, not by the first frames (nc_frame_alloc) */
    }
    return 0;
}

static void init_sync(struct nc__emu *e)
{
    pthread_mutex_init(&e->tl_lock, NULL);
    pthread_mutex_init(&e->jlock, NULL);
    pthread_mutex_init(&e->slock, NULL);
    pthread_mutex_init(&e->client_lock, NULL);
    pthread_mutex_init(&e->stat_lock, NULL);
    pthread_cond_init(&e->jcond, NULL);
    pthread_cond_init(&e->scond, NULL);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&e->sfree, &ca);
    pthread_cond_init(&e->tl_cond, &ca);
    pthread_condattr_destroy(&ca);
}

/* Until a limit, the stop flag or a thread's fatal error. */
static void supervise(struct nc__emu *e, const struct nc_serve_options *opt)
{
    double next_stats = e->stats_interval_s;
    while (!(opt->stop && *opt->stop) && atomic_load(&e->stop) == 0) {
        struct timespec ts = {0, 20000000};
        nanosleep(&ts, NULL);
        double el = (nc_mono_ns() - e->start_mono_ns) * 1e-9;
        unsigned long done = atomic_load(&e->delivered);
        for (int i = 0; i < NC__DROP_COUNT; i++)
            done += i == NC__DROP_IGNORED ? 0 : atomic_load(&e->dropped[i]);
        if ((opt->max_frames > 0 && (long)done >= opt->max_frames) || (opt->max_seconds > 0 && el >= opt->max_seconds))
            break;
        if (e->stats_interval_s > 0 && el >= next_stats) {
            nc__serve_stats_line(e, el);
            next_stats += e->stats_interval_s;
        }
    }
}

/* Every request still queued is answered "dropped", in request order,
 * after the frames before it; then the answers are sent (up to 1 s). */
static void answer_the_rest(struct nc__emu *e)
{
    if (e->have_held)
        nc__serve_drop(e, &e->held, NC__DROP_SHUTDOWN);
    e->have_held = 0;
    pthread_mutex_lock(&e->jlock);
    while (e->jcount > 0) {
        struct nc__job j = e->jobs[e->jhead];
        e->jhead = (e->jhead + 1) % e->queue_frames;
        e->jcount--;
        pthread_mutex_unlock(&e->jlock);
        nc__serve_drop(e, &j, NC__DROP_SHUTDOWN);
        pthread_mutex_lock(&e->jlock);
    }
    pthread_mutex_unlock(&e->jlock);
    nc__serve_answer_unread(e);
    for (int tries = 0; tries < 100; tries++) {
        int pending = 0;
        pthread_mutex_lock(&e->client_lock);
        for (int i = 0; i < e->max_clients; i++)
            if (e->clients[i].fd >= 0 && e->clients[i].out_len) {
                nc__serve_flush_client(e, &e->clients[i]);
                pending |= e->clients[i].out_len > 0;
            }
        pthread_mutex_unlock(&e->client_lock);
        if (!pending)
            break;
        nanosleep(&(struct timespec){0, 10000000}, NULL);
    }
}

/* Stop input, finish the frame in flight and the frames made, answer what
 * is queued as dropped, flush. */
static void shutdown_threads(struct nc__emu *e, pthread_t *threads, int nthreads)
{
    atomic_store(&e->stop, 1);
    if (nthreads > 2)
        pthread_join(threads[2], NULL); /* net */
    if (e->have_freerun)
        nc_trigger_stop(&e->freerun);
    if (e->have_line)
        nc_trigger_stop(&e->line);
    atomic_store(&e->stop, 2);
    pthread_mutex_lock(&e->jlock);
    pthread_cond_broadcast(&e->jcond);
    pthread_mutex_unlock(&e->jlock);
    if (nthreads > 1)
        pthread_join(threads[1], NULL); /* render */
    atomic_store(&e->stop, 3);
    pthread_mutex_lock(&e->slock);
    pthread_cond_broadcast(&e->scond);
    pthread_mutex_unlock(&e->slock);
    if (nthreads > 0)
        pthread_join(threads[0], NULL); /* output */
    answer_the_rest(e);
    for (int i = 0; i < e->nout; i++)
        nc_output_control(&e->out[i], "flush", NULL);
}

static void teardown(struct nc__emu *e, int have_scene, int have_cs)
{
    for (int i = 0; i < e->nout; i++)
        nc_output_close(&e->out[i]);
    if (e->have_freerun)
        nc_trigger_close(&e->freerun);
    if (e->have_line)
        nc_trigger_close(&e->line);
    nc__serve_close_sockets(e);
    free(e->clients);
    for (int i = 0; e->slots && i < e->nslots; i++)
        free(e->slots[i].dn);
    free(e->slots);
    free(e->jobs);
    nc_timeline_free(&e->tl);
    if (e->renderer.rt)
        nc_renderer_free(&e->renderer);
    if (have_cs)
        nc_camsys_free(&e->cs);
    nc_sky_free(&e->sky);
    if (have_scene)
        nc_scene_free(&e->scene);
    free(e);
}

int nc_serve(const struct nc_serve_options *opt)
{
    if (!opt->drivers)
        return nc_error(NC_EUSAGE, "serve: no driver registry given");
    struct nc__emu *e = calloc(1, sizeof *e);
    if (!e)
        return nc_error(-ENOMEM, "out of memory");
    e->drivers = opt->drivers;
    e->udp_fd = e->tcp_fd = -1;
    pthread_mutex_init(&e->acq_lock, NULL);
    nc__serve_init_control(e);
    int have_scene = 0, have_cs = 0;
    int rc = setup(e, opt, &have_scene, &have_cs);
    if (rc < 0) {
        teardown(e, have_scene, have_cs);
        return rc;
    }
    init_sync(e);
    e->start_mono_ns = nc_mono_ns();
    void *(*const fns[])(void *) = {nc__serve_output_thread, nc__serve_render_thread, nc__serve_net_thread};
    static const char *const names[] = {"output", "render", "network"};
    pthread_t threads[3];
    int nthreads = 0;
    for (; nthreads < 3 && rc >= 0; nthreads++) {
        int err = pthread_create(&threads[nthreads], NULL, fns[nthreads], e);
        if (err) {
            rc = nc_error(-err, "serve: cannot start the %s thread: %s", names[nthreads], strerror(err));
            break;
        }
    }
    while (rc >= 0 && !atomic_load(&e->warm) && atomic_load(&e->stop) < 2)
        usleep(1000); /* the render thread's warm-up frame (serve_render.c) */
    if (rc >= 0 && atomic_load(&e->failed) < 0) /* not started: no triggers, no banner */
        rc = nc_error(atomic_load(&e->failed), "serve: the emulator could not start (the error above says why)");
    if (rc >= 0 && e->have_freerun)
        rc = nc_trigger_start(&e->freerun);
    if (rc >= 0 && e->have_line)
        rc = nc_trigger_start(&e->line);
    if (rc >= 0) {
        int trig = e->mode == NC__MODE_TRIGGER;
        nc_log_info("emulator", "%s mode%s%s%s, %dx%d, UDP %s:%d, TCP %s:%d, %d output%s; SIGINT or SIGTERM stops",
                    nc__serve_mode_names[e->mode], trig ? " (" : "", trig ? (e->have_line ? e->line.drv->name : "software") : "",
                    trig ? " trigger)" : "", e->scene.camera.width_px, e->scene.camera.height_px, e->bind, e->udp_port,
                    e->bind, e->tcp_port, e->nout, e->nout == 1 ? "" : "s");
        supervise(e, opt);
    }
    shutdown_threads(e, threads, nthreads);
    if (rc >= 0 && atomic_load(&e->failed) < 0)
        rc = nc_error(atomic_load(&e->failed), "serve: the emulator could not go on (the error above says why)");
    if (rc >= 0) {
        double el = (nc_mono_ns() - e->start_mono_ns) * 1e-9;
        nc__serve_stats_line(e, el);
        nc__serve_stats_json(e, el, stdout);
        FILE *f = opt->stats_json_path ? fopen(opt->stats_json_path, "w") : NULL;
        if (opt->stats_json_path && !f)
            rc = nc_error(-errno, "--stats-json %s: %s", opt->stats_json_path, strerror(errno));
        if (f) {
            nc__serve_stats_json(e, el, f);
            const int bad = ferror(f);
            if ((fclose(f) != 0 || bad) && rc >= 0)
                rc = nc_error(-EIO, "--stats-json %s: write failed", opt->stats_json_path);
        }
    }
    teardown(e, have_scene, have_cs);
    return rc;
}
