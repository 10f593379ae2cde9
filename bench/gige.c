/* bench/gige.c - the GigE Vision output over loopback, received by a
 * libaravis client in this process (by address 127.0.0.1), 1024x1024 Mono16:
 *  1. delivery: the gige driver alone, fed one pre-rendered frame at --rate
 *     Hz (default 100): frames lost, and the time from the frame handed to
 *     the driver to the frame complete at the client (deliver_*_ms);
 *  2. the lab's run: `navcam serve` (in this process) rendering the default
 *     scene (its 4 samples per pixel, shadows, the full camera model) at
 *     1024x1024 in free-run at --serve-rate Hz (default 10) for --seconds:
 *     fps at the client, drops (the emulator's, by reason, plus frames lost
 *     on the way), and latency from each frame's exposure end (its metadata
 *     row: exposure start on CLOCK_MONOTONIC plus exposure time) to the frame
 *     complete at the client.
 * Frames are identified by the metadata row (docs/gige.md).
 * Usage: bench_gige [--seconds S] [--rate HZ] [--serve-rate HZ] [--packet-size BYTES]
 * Last line:
 *   fps=... drops=... latency_p50_ms=... latency_p99_ms=... deliver_p99_ms=...
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

/* packet_socket: 0 makes the client receive through its UDP socket rather
 * than the packet socket Aravis opens when it may (root). */
static ArvCamera *open_camera(int packet, int packet_socket)
{
    for (int i = 0; i < 100; i++) {
        ArvCamera *c = arv_camera_new("127.0.0.1", NULL);
        if (c) {
            arv_camera_gv_set_packet_size(c, packet, NULL);
            if (!packet_socket)
                arv_gv_device_set_stream_options(ARV_GV_DEVICE(arv_camera_get_device(c)),
                                                 ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
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

static double le_f64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | p[i];
    double d;
    memcpy(&d, &v, sizeof d);
    return d;
}

/* Receive for `seconds`. Latency: from the hand-over (submit_ms, run 1) or
 * from the exposure's end in the metadata row (run 2). */
static int receive(ArvCamera *c, double seconds, int from_submit, struct result *r)
{
    GError *err = NULL;
    size_t payload = (size_t)arv_camera_get_payload(c, NULL);
    ArvStream *s = arv_camera_create_stream(c, NULL, NULL, &err);
    if (!s) {
        fprintf(stderr, "bench_gige: stream: %s\n", err ? err->message : "?");
        return -1;
    }
    /* A socket buffer for a whole frame (vendors' advice for 1 Mpx+ on a
     * UDP socket; Aravis's automatic sizing comes after the first frame). */
    g_object_set(s, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size", 4 << 20, NULL);
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
                const uint8_t *m = arv_buffer_get_data(b, NULL);
                double start_mono_ns = 0;
                for (int i = 7; i >= 0; i--)
                    start_mono_ns = start_mono_ns * 256 + m[64 + i];
                double end_ms = start_mono_ns * 1e-6 + le_f64(m + 24) * 1e3;
                if (from_submit && f < MAXF && submit_ms[f] > 0 && nlat < MAXF)
                    lat[nlat++] = t - submit_ms[f];
                else if (!from_submit && nlat < MAXF)
                    lat[nlat++] = t - end_ms;
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
    struct timespec ts;
    double next = now_ms();
    for (uint64_t i = 0; atomic_load(&feeding) && i < MAXF; i++) {
        next += 1e3 / fd->rate;
        double wait = next - now_ms();
        if (wait > 0)
            usleep((useconds_t)(wait * 1e3));
        r.frame = i;
        submit_ms[i] = now_ms();
        clock_gettime(CLOCK_MONOTONIC, &ts); /* "exposed" now: sent only after AcquisitionStart */
        r.exposure_start_mono_ns = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
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

/* Run 1: the driver alone, fed a pre-rendered frame at rate Hz. */
static int run_delivery(double rate, double seconds, int packet, int packet_socket, struct result *pre,
                        double *cpu_share)
{
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    struct nc_output out;
    struct nc_output_ctx ctx = {.width_px = W, .height_px = H, .adc_bits = 12};
    int rc = nc_cfg_load_string(&cfg, "{driver: gige, pixel_format: Mono16, metadata_row: 1}", "bench");
    const struct nc_output_driver *drv = nc_registry_output(&nc_drivers, "gige");
    if (rc >= 0 && !drv)
        rc = nc_error(NC_EUNSUPPORTED, "this build has no gige driver");
    if (rc >= 0)
        rc = nc_output_open(&out, drv, cfg.root, &ctx);
    if (rc < 0) {
        fprintf(stderr, "bench_gige: %s\n", nc_errmsg());
        nc_cfg_free(&cfg);
        return -1;
    }
    uint16_t *dn = malloc((size_t)W * H * sizeof *dn);
    for (size_t i = 0; i < (size_t)W * H; i++)
        dn[i] = (uint16_t)((i * 7) & 4095);
    struct feed fd = {&out, rate, dn};
    ArvCamera *cam = open_camera(packet, packet_socket);
    pthread_t ft;
    atomic_store(&feeding, 1);
    if (!cam || pthread_create(&ft, NULL, feeder, &fd) != 0) {
        fprintf(stderr, "bench_gige: no camera at 127.0.0.1, or no feeder thread\n");
        exit(1);
    }
    struct rusage u0, u1;
    getrusage(RUSAGE_SELF, &u0);
    double w0 = now_ms();
    rc = receive(cam, seconds, 1, pre);
    getrusage(RUSAGE_SELF, &u1);
    double cpu_s = (u1.ru_utime.tv_sec - u0.ru_utime.tv_sec) + (u1.ru_stime.tv_sec - u0.ru_stime.tv_sec) +
                   1e-6 * ((u1.ru_utime.tv_usec - u0.ru_utime.tv_usec) + (u1.ru_stime.tv_usec - u0.ru_stime.tv_usec));
    *cpu_share = cpu_s / ((now_ms() - w0) * 1e-3);
    atomic_store(&feeding, 0);
    pthread_join(ft, NULL);
    g_object_unref(cam);
    nc_output_close(&out);
    nc_cfg_free(&cfg);
    free(dn);
    memset(submit_ms, 0, sizeof submit_ms);
    return rc;
}

int main(int argc, char **argv)
{
    double seconds = 10, rate = 100, serve_rate = 10;
    int packet = 65000, c;
    static const struct option opts[] = {{"seconds", required_argument, NULL, 's'},
                                         {"rate", required_argument, NULL, 'r'},
                                         {"serve-rate", required_argument, NULL, 'R'},
                                         {"packet-size", required_argument, NULL, 'p'},
                                         {"help", no_argument, NULL, 'h'},
                                         {NULL, 0, NULL, 0}};
    while ((c = getopt_long(argc, argv, "s:r:R:p:h", opts, NULL)) != -1) {
        switch (c) {
        case 's': seconds = atof(optarg); break;
        case 'r': rate = atof(optarg); break;
        case 'R': serve_rate = atof(optarg); break;
        case 'p': packet = atoi(optarg); break;
        default:
            puts("Usage: bench_gige [--seconds S] [--rate HZ] [--serve-rate HZ] [--packet-size BYTES]");
            return c == 'h' ? 0 : 2;
        }
    }
    if (!(seconds >= 2 && seconds <= 600) || !(rate > 0 && rate <= 1000) || !(serve_rate > 0 && serve_rate <= 1000) ||
        packet < 576 || packet > 65000)
        return fprintf(stderr, "bench_gige: --seconds 2..600, --rate and --serve-rate 0..1000, --packet-size 576..65000\n"), 2;

    /* 1. Delivery, through the client's UDP socket and its packet socket. */
    struct result pre = {0}, pre_ps = {0}, ren = {0};
    double cpu_share = 0, cpu_ps = 0;
    if (run_delivery(rate, seconds < 4 ? seconds : 4, packet, 0, &pre, &cpu_share) < 0 ||
        run_delivery(rate, seconds < 4 ? seconds : 4, packet, 1, &pre_ps, &cpu_ps) < 0)
        return 1;

    /* 2. navcam serve: the default scene as configured, free-run. */
    char rate_set[64], json_path[64];
    snprintf(rate_set, sizeof rate_set, "serve.frame_rate_hz=%g", serve_rate);
    snprintf(json_path, sizeof json_path, "/tmp/navcam_bench_gige_%d.json", (int)getpid());
    const char *const sets[] = {"outputs=[{driver: gige, pixel_format: Mono16, metadata_row: 1}]", "serve.mode=freerun",
                                rate_set, "serve.stats_interval_s=0", "serve.udp_port=0", "serve.tcp_port=0"};
    serve_opt = (struct nc_serve_options){.sets = sets, .nsets = 6, .max_seconds = seconds + 3,
                                          .stats_json_path = json_path, .drivers = &nc_drivers};
    int serve_rc = 0;
    pthread_t st;
    if (pthread_create(&st, NULL, serve_thread, &serve_rc) != 0) {
        fprintf(stderr, "bench_gige: cannot start the emulator thread\n");
        return 1;
    }
    ArvCamera *cam = open_camera(packet, 0);
    if (cam) {
        receive(cam, seconds, 0, &ren);
        g_object_unref(cam);
    }
    pthread_join(st, NULL);
    char text[8192];
    read_text(json_path, text, sizeof text);
    unlink(json_path);
    if (serve_rc < 0 || !cam || !text[0]) {
        fprintf(stderr, "bench_gige: the emulator run failed: %s\n", nc_errmsg());
        return 1;
    }
    long serve_drops = 0;
    const char *d = strstr(text, "\"dropped\": {");
    for (const char *p = d; p && *p && *p != '}'; p++)
        if (*p == ':' && p > d + 11)
            serve_drops += atol(p + 1);
    long drops = serve_drops - (long)json_number(text, "shutdown") + ren.lost;

    printf("delivery: a pre-rendered frame fed at %.0f Hz, %d-byte packets: %.1f fps received, %ld of %ld frames lost, "
           "handed to the driver -> complete at the client p50 %.2f ms p99 %.2f ms, process CPU %.2f cores\n",
           rate, packet, pre.fps, pre.lost, pre.made, pre.lat50, pre.lat99, cpu_share);
    printf("delivery, the client receiving through its packet socket (root): %.1f fps, %ld of %ld lost, p50 %.2f ms "
           "p99 %.2f ms, process CPU %.2f cores\n",
           pre_ps.fps, pre_ps.lost, pre_ps.made, pre_ps.lat50, pre_ps.lat99, cpu_ps);
    printf("free-run %g Hz, default scene 1024x1024 (render+camera p50 %.1f ms p99 %.1f ms): %.2f fps received over "
           "%.0f s, %ld frames lost on the way, emulator drops (shutdown excluded) %ld, resulting rate %.2f Hz, "
           "exposure end -> complete at the client p50 %.1f ms p99 %.1f ms\n",
           serve_rate, json_number(text, "render_camera_p50_ms"), json_number(text, "render_camera_p99_ms"), ren.fps,
           seconds, ren.lost, serve_drops - (long)json_number(text, "shutdown"),
           json_number(text, "resulting_frame_rate_hz"), ren.lat50, ren.lat99);
    printf("fps=%.2f drops=%ld latency_p50_ms=%.2f latency_p99_ms=%.2f deliver_p99_ms=%.3f\n", ren.fps, drops, ren.lat50,
           ren.lat99, pre.lat99);
    return 0;
}
