/* bench/latency.c - the emulator's own cost: pose received to frame handed to
 * the outputs, against the bare render plus camera-model time of the same
 * frames. `navcam serve` runs in this process (lock-step mode, a null output,
 * the built-in default scene at 512x512, 1 sample per pixel, unless --set
 * says otherwise) and a
 * client sends poses over TCP on 127.0.0.1: at 10 Hz, then as fast as the
 * frames come back. Latency and render time are measured by the emulator per
 * frame (stats JSON); overhead = latency - (render + camera model), per frame.
 * The client's round trip (send to FRAME answer) is printed as well.
 * Usage: bench_latency [--frames N] [--set KEY=VALUE]...
 * Last line (the maximum-rate run; overhead_p99_ms is the worse of the two):
 *   render_ms=... latency_p50_ms=... latency_p99_ms=... overhead_p99_ms=...
 */
#include <errno.h>
#include <getopt.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench_util.h"
#include "core/error.h"
#include "navcam/client.h"
#include "drivers/registry.h"
#include "emulator/serve.h"

#define MAX_SETS 32

struct run {
    struct nc_serve_options opt;
    const char *sets[MAX_SETS];
    char port_sets[3][64];
    char json_path[256];
    int rc;
};

static void *serve_thread(void *arg)
{
    struct run *r = arg;
    r->rc = nc_serve(&r->opt);
    return NULL;
}

struct result {
    double render_ms, lat50, lat99, over99, rtt50, rtt99, achieved_hz;
};

/* One serve run: frames poses at rate_hz (0: as fast as answered). */
static int run_once(const char *const *user_sets, int nuser, int frames, double rate_hz, int port, struct result *res)
{
    static struct run r;
    memset(&r, 0, sizeof r);
    int n = 0;
    r.sets[n++] = "serve.mode=lockstep";
    r.sets[n++] = "serve.stats_interval_s=0";
    r.sets[n++] = "outputs=[{driver: null}]";
    r.sets[n++] = "camera.width_px=512";
    r.sets[n++] = "camera.height_px=512";
    r.sets[n++] = "render.samples_per_pixel=1";
    snprintf(r.port_sets[0], sizeof r.port_sets[0], "serve.tcp_port=%d", port);
    snprintf(r.port_sets[1], sizeof r.port_sets[1], "serve.udp_port=%d", port + 1);
    r.sets[n++] = r.port_sets[0];
    r.sets[n++] = r.port_sets[1];
    for (int i = 0; i < nuser && n < MAX_SETS; i++)
        r.sets[n++] = user_sets[i];
    snprintf(r.json_path, sizeof r.json_path, "/tmp/navcam_bench_latency_%d.json", (int)getpid());
    r.opt = (struct nc_serve_options){.sets = r.sets, .nsets = n, .max_frames = frames, .stats_json_path = r.json_path,
                                      .drivers = &nc_drivers};
    pthread_t t;
    if (pthread_create(&t, NULL, serve_thread, &r) != 0) {
        fprintf(stderr, "bench_latency: cannot start the emulator thread\n");
        return -1;
    }
    struct nc_client *c = NULL;
    for (int i = 0; i < 400 && nc_client_connect("127.0.0.1", port, 1, &c) < 0; i++)
        usleep(25000); /* the scene loads first */
    if (!c) {
        pthread_join(t, NULL);
        fprintf(stderr, "bench_latency: cannot connect to the emulator: %s\n", nc_errmsg());
        return -1;
    }
    double *rtt = calloc((size_t)frames, sizeof *rtt);
    double t_start = now_ms(), next = t_start;
    int done = 0;
    for (int i = 0; i < frames && rtt; i++) {
        if (rate_hz > 0) { /* absolute schedule: no drift */
            next += 1e3 / rate_hz;
            double wait = next - now_ms();
            if (wait > 0)
                usleep((useconds_t)(wait * 1e3));
        }
        double d = 6000 - 5 * i; /* closing in on the default asteroid */
        struct nc_pose_msg m = {.type = NC_MSG_POSE, .flags = NC_MSG_CAPTURE, .sim_time_ns = (int64_t)i * 100000000,
                                .cam_position_m = {0.08 * d, -d, 0.03 * d}, .cam_attitude_q = {1, 0, 0, 0},
                                .sun = {0.643, -0.766, 0}};
        nc_quat_look_at(m.cam_position_m, nc_v3(0, 0, 0), nc_v3(0, 0, 1), &m.cam_attitude_q);
        double t0 = now_ms();
        long seq = nc_client_send(c, &m);
        uint64_t frame;
        uint32_t status;
        if (seq < 0 || nc_client_wait_frame(c, (uint32_t)seq, 60000, &frame, &status) < 0) {
            fprintf(stderr, "bench_latency: frame %d: %s\n", i, nc_errmsg());
            break;
        }
        rtt[done++] = now_ms() - t0;
    }
    double elapsed_s = (now_ms() - t_start) * 1e-3;
    nc_client_close(c);
    pthread_join(t, NULL);
    if (r.rc < 0 || done < frames) {
        fprintf(stderr, "bench_latency: run failed (%d of %d frames): %s\n", done, frames, nc_errmsg());
        free(rtt);
        return -1;
    }
    char text[8192];
    read_text(r.json_path, text, sizeof text);
    unlink(r.json_path);
    res->render_ms = json_number(text, "render_camera_p50_ms");
    res->lat50 = json_number(text, "latency_p50_ms");
    res->lat99 = json_number(text, "latency_p99_ms");
    res->over99 = json_number(text, "overhead_p99_ms");
    res->achieved_hz = done / elapsed_s;
    qsort(rtt, (size_t)done, sizeof *rtt, nc__cmp_double);
    res->rtt50 = rtt[done / 2];
    res->rtt99 = rtt[(int)(0.99 * (done - 1))];
    free(rtt);
    return json_number(text, "frames_delivered") == frames ? 0 : -1;
}

int main(int argc, char **argv)
{
    int frames = 100, c;
    const char *sets[MAX_SETS];
    int nsets = 0;
    static const struct option opts[] = {{"frames", required_argument, NULL, 'n'},
                                         {"set", required_argument, NULL, 's'},
                                         {"help", no_argument, NULL, 'h'},
                                         {NULL, 0, NULL, 0}};
    while ((c = getopt_long(argc, argv, "n:s:h", opts, NULL)) != -1) {
        switch (c) {
        case 'n': frames = atoi(optarg); break;
        case 's':
            if (nsets < MAX_SETS - 8)
                sets[nsets++] = optarg;
            break;
        default: puts("Usage: bench_latency [--frames N] [--set KEY=VALUE]..."); return c == 'h' ? 0 : 2;
        }
    }
    if (frames < 10 || frames > 100000)
        frames = 100;
    int port = 40000 + (int)(getpid() % 10000) * 2;
    struct result slow, fast;
    if (run_once(sets, nsets, frames, 10, port, &slow) < 0 || run_once(sets, nsets, frames, 0, port + 2, &fast) < 0)
        return 1;
    const struct result *rs[2] = {&slow, &fast};
    const char *names[2] = {"10 Hz", "max rate"};
    for (int i = 0; i < 2; i++)
        printf("%-8s  %5.1f Hz achieved  render+camera p50 %7.2f ms  latency p50 %7.2f p99 %7.2f ms  "
               "overhead p99 %6.3f ms  client round trip p50 %7.2f p99 %7.2f ms\n",
               names[i], rs[i]->achieved_hz, rs[i]->render_ms, rs[i]->lat50, rs[i]->lat99, rs[i]->over99, rs[i]->rtt50,
               rs[i]->rtt99);
    printf("render_ms=%.3f latency_p50_ms=%.3f latency_p99_ms=%.3f overhead_p99_ms=%.3f\n", fast.render_ms, fast.lat50,
           fast.lat99, slow.over99 > fast.over99 ? slow.over99 : fast.over99);
    return 0;
}
