/* serve_output.c - the output thread (serve_internal.h): each finished frame
 * to every output driver, then the FRAME answer to the client that asked.
 * One failing output (a device gone) never stops the others. */
#include <errno.h>
#include <math.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "emulator/serve_internal.h"

/* At most one message a second per output, with the count of those skipped. */
static void report_failure(struct nc__emu *e, int i, uint64_t frame)
{
    int64_t now = nc_mono_ns();
    if (e->out_msg_ns[i] && now - e->out_msg_ns[i] < 1000000000) {
        e->out_quiet[i]++;
        return;
    }
    char more[64] = "";
    if (e->out_quiet[i])
        snprintf(more, sizeof more, " (and %lu more failures)", e->out_quiet[i]);
    char obj[64];
    snprintf(obj, sizeof obj, "output/%s", e->out[i].drv->name);
    nc_log_error(obj, "frame %llu: %s%s", (unsigned long long)frame, nc_errmsg(), more);
    e->out_msg_ns[i] = now;
    e->out_quiet[i] = 0;
}

/* The head slot is done: free it for the render thread. */
static void release(struct nc__emu *e)
{
    pthread_mutex_lock(&e->slock);
    e->shead = (e->shead + 1) % e->nslots;
    e->scount--;
    pthread_cond_signal(&e->sfree);
    pthread_mutex_unlock(&e->slock);
}

void *nc__serve_output_thread(void *arg)
{
    struct nc__emu *e = arg;
    for (;;) {
        pthread_mutex_lock(&e->slock);
        while (e->scount == 0 && atomic_load(&e->stop) < 3)
            pthread_cond_wait(&e->scond, &e->slock);
        if (e->scount == 0) {
            pthread_mutex_unlock(&e->slock);
            break;
        }
        struct nc__slot *sl = &e->slots[e->shead];
        pthread_mutex_unlock(&e->slock);
        if (sl->dropped) { /* lock-step: a drop answered in request order */
            nc__serve_drop(e, &sl->job, sl->why);
            release(e);
            continue;
        }
        /* Latency: pose received (lock-step) or exposure end (triggered) ->
         * frame handed to the outputs. */
        int64_t handed = nc_mono_ns();
        int took = 0;
        for (int i = 0; i < e->nout; i++) {
            int rc = nc_output_submit(&e->out[i], &sl->rec);
            took += rc >= 0;
            if (rc < 0 && rc != -EAGAIN) /* busy (no free buffer): counted, not logged */
                report_failure(e, i, sl->rec.frame);
        }
        if (e->nout > 0 && !took) { /* made, and lost on the way out */
            nc__serve_drop(e, &sl->job, NC__DROP_OUTPUT_FAILED);
            release(e);
            continue;
        }
        pthread_mutex_lock(&e->stat_lock);
        e->lat_ms[e->nlat % NC_SERVE_LAT_SAMPLES] = (handed - sl->job.ready_mono_ns) * 1e-6;
        e->render_ms[e->nlat % NC_SERVE_LAT_SAMPLES] = sl->rec.render_ms + sl->rec.camera_ms;
        e->busy_ms[e->nlat % NC_SERVE_LAT_SAMPLES] = !e->overlap
                                                         ? sl->rec.render_ms + sl->rec.camera_ms
                                                         : fmax(sl->rec.render_ms, sl->rec.camera_ms);
        e->wait_ms[e->nlat % NC_SERVE_LAT_SAMPLES] = (sl->render_start_mono_ns - sl->job.ready_mono_ns) * 1e-6;
        e->nlat++;
        pthread_mutex_unlock(&e->stat_lock);
        atomic_fetch_add(&e->delivered, 1);
        nc__serve_reply(e, &sl->job, sl->rec.frame, NC_FRAME_DELIVERED);
        release(e);
    }
    return NULL;
}
