/* test_gige_control.c - `navcam serve`'s GigE Vision device and its
 * clients (test_gige.c's rig): a client killed mid-stream: its stream port
 * gets packets in the first second and none once its heartbeat ran out (the
 * device stops the acquisition and closes the stream channel), then a new
 * client streams and reads GevHeartbeatTimeout; in lock-step, refused
 * settings written with one that is not are undone alone, TLParamsLocked
 * locks the payload's features, every bound reads; the timestamp
 * counter's latch and reset; at poll_hz 1 the device idles between its
 * checks, and frames of a region beyond the sensor are not sent; a Stop
 * and a Start at once send no frame exposed before the Start; each
 * stream's first frame arrives whole at a client that reads through its
 * UDP socket and lets Aravis size its buffer; clear
 * errors for a missing
 * interface, a taken port 3956, an invalid XML (also one named relative to
 * a configuration file in another directory), a model name too long, a
 * packet size off its step.
 * Usage: test_gige_control NAVCAM TMPDIR
 */
#include <arpa/inet.h>
#include <arv.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "gige_rig.h"
#include "testutil.h"

/* UDP packets arriving at 127.0.0.1:port within seconds. */
static int packets_at(int port, double seconds)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0), n = 0;
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) < 0) {
        CHECK(0, "bind 127.0.0.1:%d: %s", port, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    struct timeval tv = {0, 100000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    char buf[9000];
    for (double t0 = now_s(); now_s() - t0 < seconds;)
        n += recv(fd, buf, sizeof buf, 0) > 0;
    close(fd);
    return n;
}

static void test_client_killed(void)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/killed", tmp);
    const char *extra[] = {"serve.mode=freerun", "outputs=[{driver: gige, pixel_format: Mono16}]"};
    pid_t pid = serve(dir, extra, 2);
    int fds[2];
    CHECK(pipe(fds) == 0, "pipe");
    pid_t child = fork();
    if (child == 0) { /* a client that dies mid-stream, its stream's port told first */
        ArvCamera *c = open_camera();
        uint8_t *img = malloc((size_t)W * H * 2);
        struct stream st = {0};
        if (!c || start(c, &st) < 0 || next_frame(&st, 5, img, NULL) < 0)
            _exit(1);
        int port = (int)arv_device_get_integer_feature_value(arv_camera_get_device(c), "GevSCPHostPort", NULL);
        if (write(fds[1], &port, sizeof port) != sizeof port)
            _exit(1);
        kill(getpid(), SIGKILL);
    }
    close(fds[1]);
    int cst = 0, port = 0;
    const int got_port = read(fds[0], &port, sizeof port) == sizeof port;
    close(fds[0]);
    waitpid(child, &cst, 0);
    double t_kill = now_s();
    CHECK(WIFSIGNALED(cst) && WTERMSIG(cst) == SIGKILL && got_port && port > 0,
          "the first client did not stream before it was killed (port %d)", port);
    /* No one talks to the device now: the stream goes on to the dead
     * client's port until its 3 s heartbeat runs out, then the device
     * stops the acquisition and closes the stream channel. */
    int before = port > 0 ? packets_at(port, 1.0) : -1;
    while (now_s() - t_kill < 4.0)
        usleep(50000);
    int after = port > 0 ? packets_at(port, 2.0) : -1;
    printf("after a client was killed: %d packets to its port in the first second, %d from 4 to 6 s\n", before,
           after);
    CHECK(before > 0 && after == 0, "a killed client's port: %d packets in the first second, %d from 4 to 6 s (want "
          "some, then none)", before, after);
    double t0 = now_s();
    ArvCamera *c = NULL;
    struct stream st = {0};
    int ok = 0;
    uint8_t *img = malloc((size_t)W * H * 2);
    while (!ok && now_s() - t0 < 12) {
        c = open_camera();
        if (c && start(c, &st) == 0 && next_frame(&st, 2, img, NULL) == 0 && next_frame(&st, 2, img, NULL) == 0)
            ok = 1;
        if (c && ok) {
            GError *err = NULL;
            gint64 hb = arv_device_get_integer_feature_value(arv_camera_get_device(c), "GevHeartbeatTimeout", &err);
            CHECK(!err && hb == 3000, "GevHeartbeatTimeout %lld ms, want 3000 (%s)", (long long)hb,
                  err ? err->message : "");
            g_clear_error(&err);
        }
        if (c) {
            finish(c, &st);
            g_object_unref(c);
        }
        if (!ok)
            usleep(500000);
    }
    printf("then a new client streamed after %.1f s more\n", now_s() - t0);
    CHECK(ok, "no new client could stream after a client was killed");
    free(img);
    CHECK(stop(pid) == 0, "serve did not exit cleanly");
}

/* Lock-step refuses AcquisitionFrameRate and TriggerMode On: written back to
 * back with ExposureTime, they are undone and the exposure stands. The
 * packet size on lo is 65000 until a client sets it. */
static void test_lockstep_units(void)
{
    char dir[4096];
    pid_t pid;
    rig_packet_size = 0;
    ArvCamera *c = begin("lockstep", "outputs=[{driver: gige, poll_hz: 4}]", "serve.mode=lockstep", &pid, dir,
                         sizeof dir);
    rig_packet_size = 8192;
    if (!c)
        return;
    ArvDevice *d = arv_camera_get_device(c);
    gint64 packet = arv_device_get_integer_feature_value(d, "GevSCPSPacketSize", NULL);
    printf("GevSCPSPacketSize on lo by default: %lld bytes\n", (long long)packet);
    CHECK(packet == 65000, "GevSCPSPacketSize %lld bytes by default on lo, want 65000", (long long)packet);
    double rate0 = arv_camera_get_frame_rate(c, NULL);
    arv_device_set_float_feature_value(d, "ExposureTime", 2500, NULL);
    arv_device_set_float_feature_value(d, "AcquisitionFrameRate", rate0 + 2, NULL);
    arv_device_set_string_feature_value(d, "TriggerMode", "On", NULL);
    usleep(600000); /* the device checks 4 times a second here: the three writes meet one check */
    double ex = arv_device_get_float_feature_value(d, "ExposureTime", NULL);
    double rate = arv_camera_get_frame_rate(c, NULL);
    const char *mode = arv_device_get_string_feature_value(d, "TriggerMode", NULL);
    printf("lock-step, ExposureTime 2500 us, AcquisitionFrameRate %.0f Hz and TriggerMode On at once: %.0f us, "
           "%.0f Hz, %s\n", rate0 + 2, ex, rate, mode ? mode : "?");
    CHECK(ex == 2500 && rate == rate0 && mode && !strcmp(mode, "Off"),
          "lock-step: ExposureTime %g us (want 2500), AcquisitionFrameRate %g Hz (want %g), TriggerMode %s (want Off)",
          ex, rate, rate0, mode ? mode : "?");
    /* The XML: the payload's features locked by TLParamsLocked (GenApi clients refuse writes while it is 1), and
     * bounds a client can read (GevTimestampTickFrequency had none: Aravis's bounds query failed) */
    GError *err = NULL;
    gint64 lo = 0, hi = 0;
    arv_device_get_integer_feature_bounds(d, "GevTimestampTickFrequency", &lo, &hi, &err);
    CHECK(!err && lo <= 1000000000 && hi >= 1000000000, "GevTimestampTickFrequency bounds: %s",
          err ? err->message : "out of range");
    g_clear_error(&err);
    arv_device_set_integer_feature_value(d, "TLParamsLocked", 1, NULL);
    int locked = 0;
    for (int i = 0; i < 3; i++) {
        static const char *const name[] = {"Width", "Height", "PixelFormat"};
        ArvGcNode *node = arv_device_get_feature(d, name[i]);
        locked += node && arv_gc_feature_node_is_locked(ARV_GC_FEATURE_NODE(node), NULL);
    }
    arv_device_set_integer_feature_value(d, "TLParamsLocked", 0, NULL);
    CHECK(locked == 3, "TLParamsLocked 1: %d of Width, Height and PixelFormat locked", locked);
    g_object_unref(c);
    CHECK(stop(pid) == 0, "serve did not exit cleanly");
}

/* The timestamp counter: CLOCK_MONOTONIC in ns, read after a latch within
 * a poll period (1 ms; 50 ms allowed for a loaded machine) before the read
 * and never after it; after GevTimestampControlReset it counts from 0, and
 * the GVSP timestamps of frames exposed after the reset are on it. */
static void test_timestamps(void)
{
    char dir[4096];
    pid_t pid;
    ArvCamera *c = begin("timestamps", "outputs=[{driver: gige}]", "serve.frame_rate_hz=20", &pid, dir, sizeof dir);
    if (!c)
        return;
    ArvDevice *d = arv_camera_get_device(c);
    struct timespec ts;
    int64_t worst_ns = 0, late = 0;
    for (int k = 0; k < 20; k++) {
        clock_gettime(CLOCK_MONOTONIC, &ts);
        const int64_t t0 = ts.tv_sec * 1000000000LL + ts.tv_nsec;
        arv_device_execute_command(d, k % 2 ? "TimestampLatch" : "GevTimestampControlLatch", NULL);
        const int64_t v = arv_device_get_integer_feature_value(d, k % 2 ? "TimestampLatchValue" : "GevTimestampValue",
                                                               NULL);
        clock_gettime(CLOCK_MONOTONIC, &ts);
        const int64_t t1 = ts.tv_sec * 1000000000LL + ts.tv_nsec;
        late += v > t1;
        worst_ns = v < t0 && t0 - v > worst_ns ? t0 - v : worst_ns;
    }
    printf("timestamp latch: 20 reads at most %.3f ms before the latch, %lld after the read\n", worst_ns * 1e-6,
           (long long)late);
    CHECK(late == 0 && worst_ns < 50000000, "latched counter: %lld reads after the read, one %.3f ms before the latch",
          (long long)late, worst_ns * 1e-6);
    arv_device_execute_command(d, "GevTimestampControlReset", NULL);
    usleep(100000);
    struct stream st = {0};
    CHECK(start(c, &st) == 0, "stream");
    uint8_t *img = malloc((size_t)W * H * 2);
    uint64_t frame_ts = 0;
    const int got = img && next_frame(&st, 3, img, &frame_ts) == 0;
    arv_device_execute_command(d, "GevTimestampControlLatch", NULL);
    const int64_t after = arv_device_get_integer_feature_value(d, "GevTimestampValue", NULL);
    printf("after a reset: a frame's GVSP timestamp %.3f ms, the counter %.3f ms\n", frame_ts * 1e-6, after * 1e-6);
    CHECK(got && after >= 100000000 && after < 10000000000LL && frame_ts >= 100000000 &&
              (int64_t)frame_ts <= after,
          "after GevTimestampControlReset and 0.1 s: counter %lld ns, frame %llu ns (want 0.1 s <= frame <= counter "
          "< 10 s)", (long long)after, (unsigned long long)frame_ts);
    finish(c, &st);
    free(img);
    g_object_unref(c);
    CHECK(stop(pid) == 0, "serve did not exit cleanly");
}

/* navcam serve with extra settings must fail (exit 1) with needle in stderr. */
static void expect_fail(const char *name, const char *const *extra, int n, const char *needle)
{
    char dir[4096], log[4200];
    snprintf(dir, sizeof dir, "%s/%s", tmp, name);
    pid_t pid = serve(dir, extra, n);
    int st = 0;
    for (double t0 = now_s(); now_s() - t0 < 20 && waitpid(pid, &st, WNOHANG) == 0;)
        usleep(50000);
    if (kill(pid, 0) == 0) {
        stop(pid);
        st = 0;
    }
    snprintf(log, sizeof log, "%s/serve.log", dir);
    size_t got;
    char *text = nc_test_read(log, &got);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 1 && text && strstr(text, needle), "%s: exit %d, stderr '%s', want '%s'",
          name, WIFEXITED(st) ? WEXITSTATUS(st) : -1, text ? text : "", needle);
    printf("%s: %s", name, text ? text : "");
    free(text);
}

static void test_errors(void)
{
    const char *noif[] = {"outputs=[{driver: gige, interface: nosuch0}]"};
    expect_fail("no_interface", noif, 1, "network interface 'nosuch0' not found");
    char xml[4200], set[4300];
    snprintf(xml, sizeof xml, "%s/bad.xml", tmp);
    nc_test_write(xml, "<RegisterDescription><Integer Name=\"Width\"></RegisterDescription>");
    snprintf(set, sizeof set, "outputs=[{driver: gige, xml: %s}]", xml);
    const char *badxml[] = {set};
    expect_fail("bad_xml", badxml, 1, "GenICam XML");
    const char *model[] = {"outputs=[{driver: gige, model: A model name longer than thirty-one characters}]"};
    expect_fail("long_model", model, 1, "outputs[0].model: expected at most 31 characters");
    const char *packet[] = {"outputs=[{driver: gige, packet_size: 8190}]"};
    expect_fail("packet_step", packet, 1, "outputs[0].packet_size: expected a multiple of 4");
    /* An xml path relative to the configuration file, whose directory is
     * not the one serve runs in. */
    char cfgdir[4200], cfg[4300], rel[4300], log[4300];
    snprintf(cfgdir, sizeof cfgdir, "%s/xmlrel", tmp);
    mkdir(cfgdir, 0777);
    snprintf(cfg, sizeof cfg, "%s/c.yaml", cfgdir);
    snprintf(rel, sizeof rel, "%s/rel.xml", cfgdir);
    nc_test_write(cfg, "base: builtin:default\noutputs:\n  - driver: gige\n    xml: rel.xml\n");
    nc_test_write(rel, "<RegisterDescription></RegisterDescription>");
    const char *argv[] = {navcam, "serve", cfg, "--max-seconds", "20", NULL};
    snprintf(log, sizeof log, "%s/run", cfgdir);
    int st = 0;
    waitpid(nc_test_spawn(log, argv), &st, 0);
    snprintf(log, sizeof log, "%s/run/serve.log", cfgdir);
    size_t got;
    char *text = nc_test_read(log, &got);
    CHECK(text && strstr(text, rel) && strstr(text, "is invalid"), "xml relative to %s: '%s'", cfg, text ? text : "");
    free(text);
    /* Port 3956 taken by a first camera, whose configured gain the Gain
     * register cannot show: the log says a write of what it shows is not
     * seen. */
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/first", tmp);
    const char *gige[] = {"outputs=[{driver: gige}]", "sensor.analog_gain_db=-6"};
    pid_t first = serve(dir, gige, 2);
    ArvCamera *c = open_camera();
    CHECK(c != NULL, "first camera");
    if (c)
        g_object_unref(c);
    expect_fail("port_taken", gige, 1, "UDP port 3956 (GigE Vision control) on 127.0.0.1 (lo) is already in use");
    CHECK(stop(first) == 0, "first serve did not exit cleanly");
    snprintf(log, sizeof log, "%s/serve.log", dir);
    text = nc_test_read(log, &got);
    CHECK(text && strstr(text, "the gain -6 dB shows as Gain 0.00 dB; frames take -6 dB until a client writes another "
                               "value (a write of 0.00 dB is not seen)"), "no warning of the gain shown: '%s'",
          text ? text : "");
    free(text);
}

/* Until register reg reads v (up to s seconds); 1 when it did. */
static int reads(ArvDevice *d, guint32 reg, guint32 v, double s)
{
    guint32 x = ~v;
    for (double t0 = now_s(); now_s() - t0 < s; usleep(5000))
        if (arv_device_read_register(d, reg, &x, NULL) && x == v)
            return 1;
    return 0;
}

/* poll_hz 1, its minimum: the device checks what clients write once a
 * second, its poll thread asleep between (it spun: a second of nanoseconds
 * is no timespec). A region beyond the sensor (OffsetX 100 beside the full
 * Width) stands until the next check; the frames made meanwhile are not
 * sent (the output's stop line counts them failed), none with a region the
 * sensor lacks. */
static void test_slow_poll(void)
{
    char dir[4096];
    pid_t pid;
    ArvCamera *c = begin("slowpoll", "outputs=[{driver: gige, poll_hz: 1}]", "serve.frame_rate_hz=20", &pid, dir,
                         sizeof dir);
    if (!c)
        return;
    ArvDevice *d = arv_camera_get_device(c);
    struct stream st;
    const int streaming = start(c, &st) == 0;
    arv_device_write_register(d, 0x130, 100, NULL);
    const int undone = reads(d, 0x130, 0, 2.5); /* a check has just run */
    const double cpu0 = nc_test_cpu_s(pid), t0 = now_s();
    arv_device_write_register(d, 0x130, 100, NULL);
    usleep(500000);
    guint32 ox = 0;
    arv_device_read_register(d, 0x130, &ox, NULL);
    const int again = reads(d, 0x130, 0, 1.5);
    const double cpu = nc_test_cpu_s(pid) - cpu0, wall = now_s() - t0;
    printf("poll_hz 1: OffsetX 100 undone %d, stood %.2f s (%u after 0.5 s); serve used %.2f s of CPU in it\n",
           undone && again, wall, ox, cpu);
    CHECK(undone && again && ox == 100 && wall > 0.5,
          "poll_hz 1: the write stood %.2f s (%u after 0.5 s), undone %d %d", wall, ox, undone, again);
    CHECK(cpu >= 0 && cpu < 0.5 * wall, "poll_hz 1: serve used %.2f s of CPU in %.2f s", cpu, wall);
    if (streaming)
        finish(c, &st);
    g_object_unref(c);
    CHECK(stop(pid) == 0, "serve did not exit cleanly");
    char path[4200];
    size_t len = 0;
    snprintf(path, sizeof path, "%s/serve.log", dir);
    char *log = nc_test_read(path, &len);
    const char *at = log ? strstr(log, "exposed before AcquisitionStart, ") : NULL;
    long failed = at ? strtol(at + 33, NULL, 10) : -1;
    printf("frames made while the region stood beyond the sensor, not sent: %ld\n", failed);
    CHECK(failed >= 5, "frames with OffsetX 100 beside Width %d: %ld not sent, want those of the second it stood", W,
          failed);
    free(log);
}

/* A restart at once: AcquisitionStop; ExposureTime=X; AcquisitionStart
 * with no pause (the device's poll, 1 ms apart, sees at most the last),
 * at 30 phases of the 100 ms frame period, the render slowed to 64 samples a
 * pixel so that a frame is being made at many of them: no frame exposed
 * before the start arrives well after it (its first packet received more
 * than 15 ms after the call: a frame sent before the Stop can be taken
 * late by a client's thread on a loaded machine, 4.5 ms seen), and the
 * first frame exposed after it has exposure X. Before,
 * the device saw no restart (its acquisition register read 1 before and
 * after) and sent frames exposed up to 20 ms before the start 12-37 ms
 * after it (an outside check: 8 of 45 restarts). */
static void test_quick_restart(void)
{
    char dir[4096];
    pid_t pid;
    ArvCamera *c = begin("quick_restart", "outputs=[{driver: gige, pixel_format: Mono12, metadata_row: 1}]",
                         "render.samples_per_pixel=64", &pid, dir, sizeof dir);
    if (!c)
        return;
    uint8_t *img = malloc((size_t)W * (H + 1) * 2);
    struct stream st = {0};
    CHECK(start(c, &st) == 0, "stream");
    int late = 0, wrong = 0, after = 0;
    for (int k = 0; k < 30; k++) {
        next_frame(&st, 3, img, NULL);
        usleep((useconds_t)(k * 3400)); /* 0 to 99 ms after a frame */
        const double x_us = k % 2 ? 1000 : 2000;
        arv_camera_stop_acquisition(c, NULL);
        arv_camera_set_exposure_time(c, x_us, NULL);
        struct timespec rt;
        clock_gettime(CLOCK_REALTIME, &rt);
        const uint64_t t_start = (uint64_t)(now_s() * 1e9), real_ns = (uint64_t)rt.tv_sec * 1000000000u + rt.tv_nsec;
        arv_camera_start_acquisition(c, NULL);
        /* the frames up to the first exposed after the start (frames come in order), 2 s at most: a
         * sanitized build renders 64 samples slowly (a window of 0.25 s saw 10 and then 1 of them) */
        for (double t0 = now_s(); now_s() - t0 < 2;) {
            uint64_t ts, frame;
            double ex, gain;
            if (next_frame(&st, 0.1, img, &ts) < 0 || meta(img, &frame, &ex, &gain) < 0)
                continue;
            if (ts < t_start && frame_arrived_ns > real_ns + 15000000) {
                late++;
                printf("frame %llu exposed %.3f ms before AcquisitionStart, received %.3f ms after it\n",
                       (unsigned long long)frame, (t_start - ts) * 1e-6, (frame_arrived_ns - real_ns) * 1e-6);
            }
            wrong += ts >= t_start && fabs(ex - x_us * 1e-6) > 1e-9;
            if (ts >= t_start) {
                after++;
                break;
            }
        }
    }
    printf("30 restarts at once: a frame exposed after %d of them, %d with the old exposure; %d exposed "
           "before a start and received after it\n", after, wrong, late);
    CHECK(late == 0 && wrong == 0 && after >= 20, "restarts at once: %d late, %d with the old exposure, %d after",
          late, wrong, after);
    finish(c, &st);
    free(img);
    g_object_unref(c);
    CHECK(stop(pid) == 0, "serve did not exit cleanly");
}

/* net.core.rmem_max (bytes) read, and set to v if v > 0; -1 if it cannot be */
static long rmem_max(long v)
{
    FILE *f = fopen("/proc/sys/net/core/rmem_max", v > 0 ? "w" : "r");
    long got = -1;
    if (f && (v > 0 ? fprintf(f, "%ld\n", v) > 0 : fscanf(f, "%ld", &got) == 1))
        got = v > 0 ? v : got;
    if (f && fclose(f) != 0)
        got = -1;
    return got;
}

/* A client set up as docs/gige.md says, receiving through its UDP socket (no packet socket) with a socket buffer
 * of 4 MiB, which Aravis sets when a frame's leader comes: the device sends each stream channel's first payload
 * 5 ms after its leader, so the first frame of each stream arrives whole. 512x512 Mono16 frames (2.5 times the
 * kernel's default buffer; an outside check lost the first frame of 4 streams in 4 before, at 1024x1024). The
 * buffer takes net.core.rmem_max: raised to 4 MiB for the check where it is lower. */
static void test_first_frames(void)
{
    const long max0 = rmem_max(0), raised = max0 >= 0 && max0 < (4L << 20) ? rmem_max(4L << 20) : 0;
    CHECK(max0 >= (4L << 20) || raised > 0, "net.core.rmem_max is %ld and cannot be raised to 4 MiB", max0);
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/first_frames", tmp);
    const char *extra[] = {"serve.mode=freerun", "outputs=[{driver: gige}]", "camera.width_px=512",
                           "camera.height_px=512"};
    const pid_t pid = serve(dir, extra, 4);
    ArvCamera *c = open_camera();
    CHECK(c != NULL, "first frames: no GigE Vision camera at 127.0.0.1");
    int whole = 0;
    for (int k = 0; c && k < 3; k++) {
        arv_gv_device_set_stream_options(ARV_GV_DEVICE(arv_camera_get_device(c)),
                                         ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
        const size_t payload = (size_t)arv_camera_get_payload(c, NULL);
        ArvStream *s = arv_camera_create_stream(c, NULL, NULL, NULL);
        if (s)
            g_object_set(s, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size", 4 << 20, NULL);
        for (int i = 0; s && i < 4; i++)
            arv_stream_push_buffer(s, arv_buffer_new(payload, NULL));
        arv_camera_start_acquisition(c, NULL);
        ArvBuffer *b = s ? arv_stream_timeout_pop_buffer(s, 5000000) : NULL;
        const int ok = b && arv_buffer_get_status(b) == ARV_BUFFER_STATUS_SUCCESS && arv_buffer_get_frame_id(b) == 1;
        printf("stream %d: its first buffer %s (status %d, frame id %llu)\n", k,
               !b ? "none in 5 s" : ok ? "whole" : "not whole", b ? (int)arv_buffer_get_status(b) : -1,
               b ? (unsigned long long)arv_buffer_get_frame_id(b) : 0ULL);
        whole += ok;
        arv_camera_stop_acquisition(c, NULL);
        if (s)
            g_object_unref(s);
    }
    CHECK(whole == 3, "the first frame of %d of 3 streams arrived whole", whole);
    if (c)
        g_object_unref(c);
    CHECK(stop(pid) == 0, "serve did not exit cleanly");
    if (raised > 0)
        rmem_max(max0);
}

int main(int argc, char **argv)
{
    if (rig_args(argc, argv, "test_gige_control") < 0)
        return 2;
    test_client_killed();
    test_lockstep_units();
    test_timestamps();
    test_slow_poll();
    test_quick_restart();
    test_first_frames();
    test_errors();
    return nc_test_end();
}
