/* serve_stats.c - the emulator's statistics (serve_internal.h): latency and
 * render-time percentiles, the periodic line, the JSON summary. Reads the
 * counters; changes nothing. */
#include <stdio.h>
#include <stdlib.h>

#include "core/log.h"
#include "emulator/serve_internal.h"

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

struct percentiles {
    double lat50, lat99, ren50, over99;
};

static struct percentiles percentiles(struct nc__emu *e)
{
    struct percentiles p = {0};
    pthread_mutex_lock(&e->stat_lock);
    unsigned long n = e->nlat < NC_SERVE_LAT_SAMPLES ? e->nlat : NC_SERVE_LAT_SAMPLES;
    double *a = malloc((n ? n : 1) * 3 * sizeof *a);
    for (unsigned long i = 0; a && i < n; i++) {
        a[i] = e->lat_ms[i];
        a[n + i] = e->render_ms[i];
        a[2 * n + i] = e->lat_ms[i] - e->render_ms[i];
    }
    pthread_mutex_unlock(&e->stat_lock);
    if (n && a) {
        for (int k = 0; k < 3; k++)
            qsort(a + k * n, n, sizeof *a, cmpd);
        size_t i99 = (size_t)(0.99 * (n - 1));
        p = (struct percentiles){a[n / 2], a[i99], a[n + n / 2], a[2 * n + i99]};
    }
    free(a);
    return p;
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
    nc_log_info("emulator",
                "%.1f s: frames %lu (%.2f fps), dropped %lu (queue %lu, stale %lu, no pose %lu, output %lu), "
                "messages %lu, rejected %lu, latency p50 %.2f ms p99 %.2f ms",
                elapsed_s, delivered, elapsed_s > 0 ? delivered / elapsed_s : 0.0, drp,
                atomic_load(&e->dropped[NC__DROP_QUEUE_FULL]), atomic_load(&e->dropped[NC__DROP_STALE_POSE]),
                atomic_load(&e->dropped[NC__DROP_NO_POSE]), atomic_load(&e->dropped[NC__DROP_OUTPUT_BUSY]),
                atomic_load(&e->received), rej, p.lat50, p.lat99);
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
        fprintf(f, "%s\"%s\": %lu", i > 1 ? ", " : "", nc_reject_name((enum nc_reject)i), atomic_load(&e->rejected[i]));
    fprintf(f, "}, \"dropped\": {");
    for (int i = 0; i < NC__DROP_COUNT; i++)
        fprintf(f, "%s\"%s\": %lu", i ? ", " : "", nc__serve_drop_names[i], atomic_load(&e->dropped[i]));
    fprintf(f, "}, ");
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
                   "\"accepted\": %lu}, ",
                e->have_line ? e->line.drv->name : "software", c.edges, c.wrong_edge, c.debounced, c.accepted);
    }
    fprintf(f, "\"latency_p50_ms\": %.3f, \"latency_p99_ms\": %.3f, \"render_camera_p50_ms\": %.3f, "
               "\"overhead_p99_ms\": %.3f, \"outputs\": [",
            p.lat50, p.lat99, p.ren50, p.over99);
    for (int i = 0; i < e->nout; i++)
        fprintf(f, "%s{\"driver\": \"%s\", \"submitted\": %lu, \"failed\": %lu}", i ? ", " : "", e->out[i].drv->name,
                e->out[i].submitted, e->out[i].failed);
    fprintf(f, "]}\n");
}
