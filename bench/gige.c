/* bench/gige.c - the GigE Vision output over loopback, 1024x1024 Mono16,
 * received by a libaravis client in this process (by address 127.0.0.1):
 *  1. pre-rendered: the gige driver alone, fed one fixed frame at --rate Hz
 *     (default 100): delivered fps, frames lost, and latency from the frame
 *     handed to the driver to the frame complete at the client;
 *  2. render-limited: `navcam serve` (in this process) rendering the default
 *     scene at 1024x1024, 1 sample per pixel, free-run asking 30 Hz:
 *     delivered fps and frames lost.
 * Frames are identified by the metadata row (docs/gige.md).
 * Also: the CPU time of the whole process per second in run 1 (the device
 * polls its trigger latch at --poll-hz, default 200, as `navcam serve`).
 * Usage: bench_gige [--seconds S] [--rate HZ] [--poll-hz HZ] [--packet-size BYTES]
 * Last line (the pre-rendered run):
 *   fps=... lost_frames=... latency_p50_ms=... latency_p99_ms=...
 */
#include <arv.h>
#include <getopt.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "bench_util.h"
#include "core/config.h"
#include "core/error.h"
#include "emulator/output.h"
#include "drivers/registry.h"
#include "emulator/serve.h"

#define W 1024
#define H 1024
#define MAXF 100000

static double submit_ms[MAXF];
static atomic_int feeding;

static uint64_t frame_of(const uint8_t *row)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | row[8 + i];
    return memcmp(row, "NCMD", 4) ? UINT64_MAX : v;
}

static ArvCamera *open_camera(int packet)
{
    for (int i = 0; i < 100; i++) {
        ArvCamera *c = arv_camera_new("127.0.0.1", NULL);
        if (c) {
            arv_camera_gv_set_packet_size(c, packet, NULL);
            return c;
        }
        usleep(100000);
    }
    return NULL;
}

struct result {
    double fps, lat50, lat99;
    long received, made, lost;
};

/* Receive for `seconds`; latencies need submit_ms (pre-rendered run). */
static int receive(ArvCamera *c, double seconds, int with_latency, struct result *r)
{
    GError *err = NULL;
    size_t payload = (size_t)arv_camera_get_payload(c, NULL);
    ArvStream *s = arv_camera_create_stream(c, NULL, NULL, &err);
    if (!s) {
        fprintf(stderr, "bench_gige: stream: %s\n", err ? err->message : "?");
        return -1;
    }
    for (int i = 0; i < 16; i++)
        arv_stream_push_buffer(s, arv_buffer_new(payload, NULL));
    arv_camera_start_acquisition(c, NULL);
    double *lat = calloc(MAXF, sizeof *lat);
    uint64_t first = UINT64_MAX, last = 0;
    long n = 0, nlat = 0;
    double t0 = now_ms(), t_first = 0, t_last = 0;
    while (now_ms() - t0 < seconds * 1e3) {
        ArvBuffer *b = arv_stream_timeout_pop_buffer(s, 200000);
        if (!b)
            continue;
        double t = now_ms();
        if (arv_buffer_get_status(b) == ARV_BUFFER_STATUS_SUCCESS) {
            uint64_t f = frame_of(arv_buffer_get_data(b, NULL));
            if (f != UINT64_MAX && now_ms() - t0 > 500) { /* past the start-up */
                if (first == UINT64_MAX)
                    first = f, t_first = t;
                last = f, t_last = t;
                n++;
                if (with_latency && f < MAXF && submit_ms[f] > 0 && nlat < MAXF)
                    lat[nlat++] = t - submit_ms[f];
            }
        }
        arv_stream_push_buffer(s, b);
    }
    arv_camera_stop_acquisition(c, NULL);
    g_object_unref(s);
    r->received = n;
    r->made = first == UINT64_MAX ? 0 : (long)(last - first + 1);
    r->lost = r->made - n;
    r->fps = n > 1 ? (n - 1) / ((t_last - t_first) * 1e-3) : 0;
    r->lat50 = nlat ? median(lat, (int)nlat) : 0; /* sorts lat */
    r->lat99 = nlat ? lat[(long)(0.99 * (nlat - 1))] : 0;
    free(lat);
    return 0;
}

struct feed {
    struct nc_output *out;
    double rate;
    uint16_t *dn;
};

static void *feeder(void *arg)
{
    struct feed *fd = arg;
    struct nc_frame_record r = {.width_px = W, .height_px = H, .adc_bits = 12, .dn = fd->dn, .exposure_s = 1e-3,
                                .trigger_source = "bench"};
    double next = now_ms();
    for (uint64_t i = 0; atomic_load(&feeding) && i < MAXF; i++) {
        next += 1e3 / fd->rate;
        double wait = next - now_ms();
        if (wait > 0)
            usleep((useconds_t)(wait * 1e3));
        r.frame = i;
        submit_ms[i] = now_ms();
        nc_output_submit(fd->out, &r);
    }
    return NULL;
}

static struct nc_serve_options serve_opt;
static void *serve_thread(void *arg)
{
    *(int *)arg = nc_serve(&serve_opt);
    return NULL;
}

int main(int argc, char **argv)
{
    double seconds = 4, rate = 100, poll_hz = 200;
    int packet = 65000, c;
    static const struct option opts[] = {{"seconds", required_argument, NULL, 's'},
                                         {"rate", required_argument, NULL, 'r'},
                                         {"packet-size", required_argument, NULL, 'p'},
                                         {"poll-hz", required_argument, NULL, 'P'},
                                         {"help", no_argument, NULL, 'h'},
                                         {NULL, 0, NULL, 0}};
    while ((c = getopt_long(argc, argv, "s:r:p:h", opts, NULL)) != -1) {
        switch (c) {
        case 's': seconds = atof(optarg); break;
        case 'r': rate = atof(optarg); break;
        case 'p': packet = atoi(optarg); break;
        case 'P': poll_hz = atof(optarg); break;
        default: puts("Usage: bench_gige [--seconds S] [--rate HZ] [--packet-size BYTES]"); return c == 'h' ? 0 : 2;
        }
    }
    if (!(seconds >= 1 && seconds <= 600) || !(rate > 0 && rate <= 1000) || packet < 576 || packet > 65000)
        return fprintf(stderr, "bench_gige: --seconds 1..600, --rate 0..1000, --packet-size 576..65000\n"), 2;

    /* 1. The driver alone, fed a pre-rendered frame. */
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    struct nc_output out;
    struct nc_output_ctx ctx = {.width_px = W, .height_px = H, .adc_bits = 12};
    char yaml[200];
    snprintf(yaml, sizeof yaml, "{driver: gige, pixel_format: Mono16, metadata_row: 1, trigger_poll_hz: %g}", poll_hz);
    int rc = nc_cfg_load_string(&cfg, yaml, "bench");
    const struct nc_output_driver *drv = nc_registry_output(&nc_drivers, "gige");
    if (rc >= 0 && !drv)
        rc = nc_error(NC_EUNSUPPORTED, "this build has no gige driver");
    if (rc >= 0)
        rc = nc_output_open(&out, drv, cfg.root, &ctx);
    if (rc < 0) {
        fprintf(stderr, "bench_gige: %s\n", nc_errmsg());
        return 1;
    }
    uint16_t *dn = malloc((size_t)W * H * sizeof *dn);
    for (size_t i = 0; i < (size_t)W * H; i++)
        dn[i] = (uint16_t)((i * 7) & 4095);
    struct feed fd = {&out, rate, dn};
    ArvCamera *cam = open_camera(packet);
    if (!cam) {
        fprintf(stderr, "bench_gige: no camera at 127.0.0.1\n");
        return 1;
    }
    atomic_store(&feeding, 1);
    pthread_t ft;
    if (pthread_create(&ft, NULL, feeder, &fd) != 0) {
        fprintf(stderr, "bench_gige: cannot start the feeder thread\n");
        return 1;
    }
    struct result pre = {0}, ren = {0};
    struct rusage u0, u1;
    getrusage(RUSAGE_SELF, &u0);
    double w0 = now_ms();
    rc = receive(cam, seconds, 1, &pre);
    getrusage(RUSAGE_SELF, &u1);
    double cpu_s = (u1.ru_utime.tv_sec - u0.ru_utime.tv_sec) + (u1.ru_stime.tv_sec - u0.ru_stime.tv_sec) +
                   1e-6 * ((u1.ru_utime.tv_usec - u0.ru_utime.tv_usec) + (u1.ru_stime.tv_usec - u0.ru_stime.tv_usec));
    double cpu_share = cpu_s / ((now_ms() - w0) * 1e-3);
    atomic_store(&feeding, 0);
    pthread_join(ft, NULL);
    g_object_unref(cam);
    nc_output_close(&out);
    nc_cfg_free(&cfg);
    free(dn);
    if (rc < 0)
        return 1;

    /* 2. navcam serve rendering the default scene. */
    static const char *const sets[] = {"outputs=[{driver: gige, pixel_format: Mono16, metadata_row: 1}]",
                                       "render.samples_per_pixel=1", "serve.mode=freerun", "serve.frame_rate_hz=30",
                                       "serve.stats_interval_s=0", "serve.udp_port=0", "serve.tcp_port=0"};
    serve_opt = (struct nc_serve_options){.sets = sets, .nsets = 7, .max_seconds = seconds + 4, .drivers = &nc_drivers};
    int serve_rc = 0;
    pthread_t st;
    if (pthread_create(&st, NULL, serve_thread, &serve_rc) != 0) {
        fprintf(stderr, "bench_gige: cannot start the emulator thread\n");
        return 1;
    }
    cam = open_camera(packet);
    if (cam) {
        receive(cam, seconds, 0, &ren);
        g_object_unref(cam);
    }
    pthread_join(st, NULL);

    printf("pre-rendered frame fed at %.0f Hz, device polling at %.0f Hz: %.1f fps delivered, %ld of %ld frames lost, "
           "latency (handed to the driver -> complete at the client) p50 %.2f ms p99 %.2f ms, process CPU %.2f cores\n",
           rate, poll_hz, pre.fps, pre.lost, pre.made, pre.lat50, pre.lat99, cpu_share);
    printf("render-limited (default scene 1024x1024, 1 spp, asking 30 Hz): %.1f fps delivered, %ld of %ld frames "
           "lost\n",
           ren.fps, ren.lost, ren.made);
    printf("fps=%.1f lost_frames=%ld latency_p50_ms=%.3f latency_p99_ms=%.3f\n", pre.fps, pre.lost, pre.lat50,
           pre.lat99);
    return 0;
}
