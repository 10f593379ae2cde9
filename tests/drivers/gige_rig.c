/* gige_rig.c - the test rig of test_gige.c (gige_rig.h). */
#include "gige_rig.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <zlib.h>

#include "core/error.h"
#include "render/image_io.h"
#include "testutil.h"

const char *navcam, *tmp;
unsigned long incomplete; /* buffers that arrived with missing packets */
unsigned long unfilled;   /* buffers Aravis gave back as they were (start()'s datagrams) */
uint64_t frame_id;        /* of the last frame next_frame returned */
uint64_t frame_arrived_ns; /* its system timestamp */
int rig_packet_size = 8192;

int rig_args(int argc, char **argv, const char *prog)
{
    static char exe[4096], dir[4096];
    if (argc != 3) {
        fprintf(stderr, "usage: %s NAVCAM TMPDIR\n", prog);
        return -1;
    }
    mkdir(argv[2], 0777);
    if (!realpath(argv[1], exe) || !realpath(argv[2], dir)) {
        fprintf(stderr, "%s: %s or %s: %s\n", prog, argv[1], argv[2], strerror(errno));
        return -1;
    }
    navcam = exe;
    tmp = dir;
    signal(SIGPIPE, SIG_IGN);
    setvbuf(stdout, NULL, _IOLBF, 0);
    return 0;
}

double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Start `navcam serve` in dir with the common small, noise-free scene plus
 * extra --set arguments; stderr goes to dir/serve.log. */
pid_t serve(const char *dir, const char *const *extra, int nextra)
{
    static const char *const common[] = {
        "camera.width_px=128", "camera.height_px=96", "bodies.0.shape.subdivisions=4", "render.samples_per_pixel=1",
        "sensor.shot_noise=false", "sensor.read_noise_e=0", "sensor.dark_current_e_s=0", "sensor.dsnu_e_s=0",
        "sensor.prnu=0", "serve.stats_interval_s=0", "serve.udp_port=0", "serve.tcp_port=0", "serve.frame_rate_hz=10",
    };
    const int nc = (int)(sizeof common / sizeof common[0]);
    const char *argv[64];
    int n = 0;
    argv[n++] = navcam;
    argv[n++] = "serve";
    for (int i = 0; i < nc; i++)
        argv[n++] = "--set", argv[n++] = common[i];
    for (int i = 0; i < nextra; i++)
        argv[n++] = "--set", argv[n++] = extra[i];
    argv[n++] = "--max-seconds";
    argv[n++] = "60";
    argv[n] = NULL;
    return dir ? nc_test_spawn(dir, argv) : -1;
}

int stop(pid_t pid)
{
    int st = 0;
    kill(pid, SIGTERM);
    waitpid(pid, &st, 0);
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

/* The camera at 127.0.0.1 once the device answers (up to 15 s). */
ArvCamera *open_camera(void)
{
    for (double t0 = now_s(); now_s() - t0 < 15;) {
        GError *err = NULL;
        ArvCamera *c = arv_camera_new("127.0.0.1", &err);
        /* The control channel (a loaded machine can miss the first ack). */
        for (int i = 0; c && i < 5 && !arv_gv_device_is_controller(ARV_GV_DEVICE(arv_camera_get_device(c))); i++)
            arv_gv_device_take_control(ARV_GV_DEVICE(arv_camera_get_device(c)), NULL);
        if (c && arv_gv_device_is_controller(ARV_GV_DEVICE(arv_camera_get_device(c)))) {
            if (rig_packet_size)
                arv_camera_gv_set_packet_size(c, rig_packet_size, NULL);
            return c;
        }
        if (c)
            g_object_unref(c);
        g_clear_error(&err);
        usleep(200000);
    }
    return NULL;
}

/* serve in tmp/name with one output map, and a camera opened on it; NULL
 * (serve stopped) when no camera answers. */
ArvCamera *begin(const char *name, const char *outputs, const char *more, pid_t *pid, char *dir,
                  size_t dirlen)
{
    snprintf(dir, dirlen, "%s/%s", tmp, name);
    const char *extra[] = {"serve.mode=freerun", outputs, more};
    *pid = serve(dir, extra, more ? 3 : 2);
    ArvCamera *c = open_camera();
    CHECK(c != NULL, "%s: no GigE Vision camera at 127.0.0.1", name);
    if (!c) {
        stop(*pid);
        return NULL;
    }
    return c;
}

static atomic_int flooding;

/* Datagrams shaped like GigE Vision commands (WRITEMEM, 0x0086) across lo,
 * as fast as they go while flooding is set, to a socket of their own that
 * never reads them (a closed port would answer with ICMP messages, which
 * such a packet socket also takes for stream blocks: Aravis 0.8.26 then
 * asked for 34 GB and aborted). */
static void *flood(void *arg)
{
    (void)arg;
    static const uint8_t cmd[16] = {0x42, 0x01, 0x00, 0x86, 0x00, 0x08, 0x12, 0x34};
    struct sockaddr_in to = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    socklen_t len = sizeof to;
    int sink = socket(AF_INET, SOCK_DGRAM, 0), fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (sink >= 0 && fd >= 0 && bind(sink, (struct sockaddr *)&to, sizeof to) == 0 &&
        getsockname(sink, (struct sockaddr *)&to, &len) == 0)
        while (atomic_load(&flooding))
            sendto(fd, cmd, sizeof cmd, MSG_DONTWAIT, (struct sockaddr *)&to, sizeof to);
    if (fd >= 0)
        close(fd);
    if (sink >= 0)
        close(sink);
    return NULL;
}

int start(ArvCamera *c, struct stream *st)
{
    GError *err = NULL;
    st->payload = (size_t)arv_camera_get_payload(c, &err);
    /* Every stream opens while control-shaped datagrams cross lo: Aravis,
     * run as root, receives through a packet socket that captures every
     * packet until its filter is attached, and takes the first one for a
     * stream block whose id (here 0x86) it then expects to grow: it
     * discards as late the blocks with ids up to 99 below it. The device
     * numbers each stream channel's blocks from 1, out of that reach
     * (docs/gige.md, "Block ids"). */
    pthread_t flooder;
    atomic_store(&flooding, 1);
    const int flood_on = err == NULL && pthread_create(&flooder, NULL, flood, NULL) == 0;
    st->s = err ? NULL : arv_camera_create_stream(c, NULL, NULL, &err);
    atomic_store(&flooding, 0);
    if (flood_on)
        pthread_join(flooder, NULL);
    if (!st->s) {
        fprintf(stderr, "stream: %s\n", err ? err->message : "?");
        g_clear_error(&err);
        return -1;
    }
    for (int i = 0; i < 8; i++)
        arv_stream_push_buffer(st->s, arv_buffer_new(st->payload, NULL));
    arv_camera_start_acquisition(c, &err);
    return err ? (g_clear_error(&err), -1) : 0;
}

void finish(ArvCamera *c, struct stream *st)
{
    arv_camera_stop_acquisition(c, NULL);
    if (st->s)
        g_object_unref(st->s);
    st->s = NULL;
}

/* The next complete frame within timeout_s, copied into out (payload bytes);
 * its GVSP timestamp in *ts. Returns 0, or -1 on timeout. */
int next_frame(struct stream *st, double timeout_s, uint8_t *out, uint64_t *ts)
{
    for (double t0 = now_s(); now_s() - t0 < timeout_s;) {
        ArvBuffer *b = arv_stream_timeout_pop_buffer(st->s, 100000);
        if (!b)
            continue;
        const ArvBufferStatus status = arv_buffer_get_status(b);
        const int ok = status == ARV_BUFFER_STATUS_SUCCESS;
        unfilled += status == ARV_BUFFER_STATUS_CLEARED;
        incomplete += !ok && status != ARV_BUFFER_STATUS_CLEARED;
        if (ok) {
            size_t size;
            const void *d = arv_buffer_get_data(b, &size);
            memcpy(out, d, size < st->payload ? size : st->payload);
            if (ts)
                *ts = arv_buffer_get_timestamp(b);
            frame_id = arv_buffer_get_frame_id(b);
            frame_arrived_ns = arv_buffer_get_system_timestamp(b);
        }
        arv_stream_push_buffer(st->s, b);
        if (ok)
            return 0;
    }
    return -1;
}

uint64_t le64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

double f64(const uint8_t *p)
{
    uint64_t u = le64(p);
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

/* The metadata row's 48-byte core: magic, CRC; frame number, exposure and
 * gain out. */
int meta(const uint8_t *row, uint64_t *frame, double *exposure_s, double *gain_db)
{
    uint32_t crc = (uint32_t)row[44] | (uint32_t)row[45] << 8 | (uint32_t)row[46] << 16 | (uint32_t)row[47] << 24;
    if (memcmp(row, "NCMD", 4) || crc != (uint32_t)crc32(0L, row, 44))
        return -1;
    *frame = le64(row + 8);
    *exposure_s = f64(row + 24);
    *gain_db = f64(row + 32);
    return 0;
}

/* The file output's DN frame number n (EXR: exact float DN). */
float *file_frame(const char *dir, uint64_t n)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/frames/frame_%06llu.exr", dir, (unsigned long long)n);
    float *px = NULL;
    int w, h;
    for (int i = 0; i < 50 && access(path, R_OK) != 0; i++)
        usleep(20000);
    if (nc_image_read(path, &px, &w, &h) < 0 || w != W || h != H) {
        free(px);
        return NULL;
    }
    return px;
}

/* Pixels of a received frame (after the metadata row) against the file:
 * format bits per pixel, shift, ROI. Returns the number of differences. */
long compare(const uint8_t *img, const float *dn, int bpp, int shift, int ox, int oy, int w, int rows)
{
    long bad = 0;
    for (int y = 0; y < rows; y++)
        for (int x = 0; x < w; x++) {
            const uint8_t *p = img + ((size_t)(y + 1) * w + x) * bpp;
            unsigned got = bpp == 1 ? p[0] : (unsigned)(p[0] | p[1] << 8);
            unsigned d = (unsigned)dn[(size_t)(oy + y) * W + ox + x];
            unsigned want = shift >= 0 ? d << shift : d >> -shift;
            bad += got != want;
        }
    return bad;
}

