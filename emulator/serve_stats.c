/* serve_stats.c - the emulator's statistics (serve_internal.h): latency and
 * render-time percentiles, the periodic line, the JSON summary. Reads the
 * counters; changes nothing. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>

#include "core/log.h"
#include "emulator/serve_internal.h"

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Per frame: latency = waiting (queue, pose) + render and camera model +
 * hand-off; overhead = latency - render and camera model. */
enum { Q_LAT, Q_REN, Q_WAIT, Q_OVER, Q_COUNT };
struct percentiles {
    double p50[Q_COUNT], p99[Q_COUNT];
};

static struct percentiles percentiles(struct nc__emu *e)
{
    struct percentiles p = {{0}, {0}};
    pthread_mutex_lock(&e->stat_lock);
    unsigned long n = e->nlat < NC_SERVE_LAT_SAMPLES ? e->nlat : NC_SERVE_LAT_SAMPLES;
    double *a = malloc((n ? n : 1) * Q_COUNT * sizeof *a);
    for (unsigned long i = 0; a && i < n; i++) {
        a[Q_LAT * n + i] = e->lat_ms[i];
        a[Q_REN * n + i] = e->render_ms[i];
        a[Q_WAIT * n + i] = e->wait_ms[i];
        a[Q_OVER * n + i] = e->lat_ms[i] - e->render_ms[i];
    }
    pthread_mutex_unlock(&e->stat_lock);
    if (n && a) {
        /* nearest rank: the smallest sample with at least q of them at or
         * below it (so p50 <= p99 for any n; with 2 samples, the two) */
        const size_t i50 = (size_t)ceil(0.5 * n) - 1, i99 = (size_t)ceil(0.99 * n) - 1;
        for (int k = 0; k < Q_COUNT; k++) {
            qsort(a + k * n, n, sizeof *a, cmpd);
            p.p50[k] = a[k * n + i50];
            p.p99[k] = a[k * n + i99];
        }
    }
    free(a);
    return p;
}

double nc__serve_busy_ms(struct nc__emu *e, int slowest)
{
    double r[16];
    pthread_mutex_lock(&e->stat_lock);
    unsigned long n = e->nlat < 16 ? e->nlat : 16;
    for (unsigned long i = 0; i < n; i++)
        r[i] = e->busy_ms[(e->nlat - 1 - i) % NC_SERVE_LAT_SAMPLES];
    pthread_mutex_unlock(&e->stat_lock);
    if (n == 0)
        return slowest ? 0.0 : e->warm_busy_ms;
    qsort(r, n, sizeof *r, cmpd);
    return r[slowest ? n - 1 : n / 2];
}

double nc__serve_resulting_rate_hz(struct nc__emu *e)
{
    struct nc_acquisition a;
    nc__serve_acq_get(e, &a);
    double want = a.triggered || e->mode == NC__MODE_LOCKSTEP ? INFINITY : a.frame_rate_hz;
    /* One exposure at a time (overrun rule 4): in free-run an exposure
     * spanning k periods takes every k-th tick; triggers come at most one an
     * exposure. */
    if (isfinite(want))
        want /= fmax(1.0, ceil(a.exposure_s * a.frame_rate_hz - 1e-9));
    else if (e->mode != NC__MODE_LOCKSTEP && a.exposure_s > 0)
        want = 1.0 / a.exposure_s;
    double r = nc__serve_busy_ms(e, 1), can = r > 0 ? 1000.0 / r : INFINITY;
    double got = fmin(want, can);
    return isfinite(got) ? got : 0.0;
}

void nc__serve_stats_line(struct nc__emu *e, double elapsed_s)
{
    struct percentiles p = percentiles(e);
    unsigned long rej = 0, drp = 0;
    for (int i = 1; i < NC_REJECT_COUNT; i++)
        rej += atomic_load(&e->rejected[i]);
    for (int i = 0; i < NC__DROP_COUNT; i++)
        drp += atomic_load(&e->dropped[i]);
    unsigned long delivered = atomic_load(&e->delivered);
    char why[320] = ""; /* every reason, by its name in the summary JSON */
    for (int i = 0; i < NC__DROP_COUNT; i++) {
        const size_t n = strlen(why);
        snprintf(why + n, sizeof why - n, "%s%s %lu", i ? ", " : "", nc__serve_drop_names[i],
                 atomic_load(&e->dropped[i]));
    }
    nc_log_info("emulator",
                "%.1f s: frames %lu (%.2f fps), dropped %lu (%s), messages %lu, rejected %lu, latency p50 %.2f ms "
                "p99 %.2f ms (render+camera p50 %.2f ms, waiting p99 %.2f ms)",
                elapsed_s, delivered, elapsed_s > 0 ? delivered / elapsed_s : 0.0, drp, why,
                atomic_load(&e->received), rej, p.p50[Q_LAT], p.p99[Q_LAT], p.p50[Q_REN], p.p99[Q_WAIT]);
}

void nc__serve_stats_json(struct nc__emu *e, double elapsed_s, FILE *f)
{
    struct percentiles p = percentiles(e);
    unsigned long delivered = atomic_load(&e->delivered);
    fprintf(f, "{\"elapsed_s\": %.3f, \"mode\": \"%s\", \"frames_delivered\": %lu, \"fps\": %.4f, \"messages\": %lu, ",
            elapsed_s, nc__serve_mode_names[e->mode], delivered, elapsed_s > 0 ? delivered / elapsed_s : 0.0,
            atomic_load(&e->received));
    fprintf(f, "\"rejected\": {");
    for (int i = 1; i < NC_REJECT_COUNT; i++)
        fprintf(f, "%s\"%s\": %lu", i > 1 ? ", " : "", nc_reject_key((enum nc_reject)i), atomic_load(&e->rejected[i]));
    fprintf(f, "}, \"dropped\": {");
    for (int i = 0; i < NC__DROP_COUNT; i++)
        fprintf(f, "%s\"%s\": %lu", i ? ", " : "", nc__serve_drop_names[i], atomic_load(&e->dropped[i]));
    pthread_mutex_lock(&e->client_lock);
    fprintf(f, "}, \"clients\": {\"refused\": %lu, \"unread_disconnected\": %lu}, ", e->refused_clients,
            e->slow_clients);
    pthread_mutex_unlock(&e->client_lock);
    if (e->have_line || e->software_configured) { /* the source serve.trigger configured */
        struct nc_trigger_counts c;
        if (e->have_line) {
            nc_trigger_counts(&e->line, &c);
        } else {
            pthread_mutex_lock(&e->acq_lock);
            c = e->software_counts;
            pthread_mutex_unlock(&e->acq_lock);
        }
        fprintf(f, "\"trigger\": {\"driver\": \"%s\", \"edges\": %lu, \"wrong_edge\": %lu, \"debounced\": %lu, "
                   "\"accepted\": %lu",
                e->have_line ? e->line.drv->name : "software", c.edges, c.wrong_edge, c.debounced, c.accepted);
        /* The driver's own counters, under its name, when it keeps any. */
        char *own = NULL;
        size_t len = 0;
        FILE *m = e->have_line ? open_memstream(&own, &len) : NULL;
        if (m) {
            int rc = nc_trigger_control(&e->line, "stats", m);
            fclose(m);
            if (rc == 0 && len)
                fprintf(f, ", \"%s\": %s", e->line.drv->name, own);
            free(own);
        }
        fprintf(f, "}, ");
    }
    if (e->have_freerun) {
        struct nc_trigger_counts c;
        nc_trigger_counts(&e->freerun, &c);
        fprintf(f, "\"freerun\": {\"ticks\": %lu}, ", c.accepted);
    }
    struct nc_acquisition a;
    nc__serve_acq_get(e, &a);
    fprintf(f, "\"frame_rate_hz\": %.4f, \"resulting_frame_rate_hz\": %.4f, ", a.frame_rate_hz,
            nc__serve_resulting_rate_hz(e));
    fprintf(f, "\"latency_p50_ms\": %.3f, \"latency_p99_ms\": %.3f, \"render_camera_p50_ms\": %.3f, "
               "\"render_camera_p99_ms\": %.3f, \"wait_p50_ms\": %.3f, \"wait_p99_ms\": %.3f, "
               "\"overhead_p99_ms\": %.3f, \"outputs\": [",
            p.p50[Q_LAT], p.p99[Q_LAT], p.p50[Q_REN], p.p99[Q_REN], p.p50[Q_WAIT], p.p99[Q_WAIT], p.p99[Q_OVER]);
    for (int i = 0; i < e->nout; i++)
        fprintf(f, "%s{\"driver\": \"%s\", \"submitted\": %lu, \"failed\": %lu}", i ? ", " : "", e->out[i].drv->name,
                e->out[i].submitted, e->out[i].failed);
    fprintf(f, "]}\n");
}
