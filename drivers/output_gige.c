/* output_gige.c - the GigE Vision output: NavCam as a GenICam camera that
 * any GigE Vision client (Aravis, vendor viewers) opens by address. It
 * embeds Aravis's GigE Vision device (ArvGvFakeCamera) for the control
 * protocol, with NavCam's own GenICam description
 * (drivers/gige/navcam-genicam.xml, compiled in), and streams frames itself.
 *
 * Who does what:
 * - The device thread (Aravis) answers GVCP: registers, acquisition start
 *   and stop, heartbeats. It never streams: its own trigger stays in
 *   software mode and its latch is never raised.
 * - submit() packs each finished frame as the stream carries it (ROI and
 *   pixel format as the registers say, the optional metadata row) into one
 *   of three buffers, and the sender thread sends it at once (gige/gvsp.c),
 *   the exposure start as GVSP timestamp (the device's counter: CLOCK_MONOTONIC
 *   ns since a client's GevTimestampControlReset, gige_regs.h). A frame whose exposure started
 *   before the client's AcquisitionStart is never sent; a newer frame
 *   replaces one not yet sent.
 * - NavCam's poll thread reads what clients wrote (ExposureTime, Gain,
 *   AcquisitionFrameRate, TriggerMode/Source/Activation/Delay) poll_hz times
 *   a second and hands changes to the emulator (struct nc_camera_control),
 *   so they act on the next exposure; at AcquisitionStart it applies the
 *   settings first, then opens the stream to exposures from then on.
 *   TriggerSoftware fires the emulator's software trigger;
 *   AcquisitionResultingFrameRate is kept up to date. Within one poll it
 *   takes writes in a GenICam client's order (settings, AcquisitionStart,
 *   TriggerSoftware) and first undoes those a camera's firmware refuses
 *   (gige_regs.h: the registers, their checks).
 */
#include <arpa/inet.h>
#include <arv.h>
#include <errno.h>
#include <math.h>
#include <net/if.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <zlib.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "drivers/gige/gige_check.h"
#include "drivers/gige/gige_image.h"
#include "drivers/gige/gige_net.h"
#include "drivers/gige/gige_regs.h"
#include "drivers/gige/gvsp.h"
#include "drivers/navcam_genicam_xml.h"
#include "emulator/output.h"
#include "core/version.h"

struct gige {
    ArvGvFakeCamera *gv;
    ArvFakeCamera *fc;
    const struct nc_camera_control *ctl;
    int W, H, adc_bits, meta_rows;
    char iface[IF_NAMESIZE], addr[INET_ADDRSTRLEN];
    /* Frames as the stream carries them, in three buffers: submit() packs
     * into buf[fill] and swaps it with buf[ready]; the sender swaps
     * buf[ready] with buf[send] and sends that one. */
    pthread_mutex_t lock;
    pthread_cond_t cond; /* a frame is ready, or stop */
    uint8_t *buf[3];
    atomic_size_t packed[3]; /* bytes of buf[k] packed so far */
    struct nc__gvsp_image im[3];
    struct nc_frame_record rec[3]; /* only its times and numbers: not dn */
    int fill, ready, send, pending;
    uint64_t submitted;
    unsigned long sent, skipped, not_acquiring, before_start, send_failed;
    struct nc__gvsp gvsp;
    atomic_llong acq_start_ns; /* CLOCK_MONOTONIC of AcquisitionStart (settings applied); 0: stopped */
    struct nc__gige_clock clock; /* the GVSP timestamps' counter */
    atomic_int channel_closed;    /* GevSCPHostPort read 0 since the last frame sent */
    struct sockaddr_in last_dest; /* of the last frame sent: a new one opens a channel, block ids from 1 */
    /* the poll and sender threads */
    pthread_t thread, sender;
    atomic_int stop;
    int running, sending;
    double poll_hz;
    struct nc_acquisition applied; /* what the registers said last time */
    uint32_t held[NC_GIGE_HELD];     /* the image registers' last values that held */
    unsigned long rejected_settings;
    int probe_fd;    /* the heartbeat check's socket (gige_net.h), or -1 */
    int controlled;  /* a client held the control at the last poll */
};

/* The registers a client sees, from the emulator's settings. */
static void publish(struct gige *g, const struct nc_acquisition *a)
{
    nc__gige_publish(g->fc, a);
    g->applied = *a;
}

static void refused(void *arg, const char *what)
{
    struct gige *g = arg;
    if (++g->rejected_settings <= 10)
        nc_log_warn("output/gige", "a client's setting was refused (the registers show what holds): %s%s", what,
                    g->rejected_settings == 10 ? " (from now on refusals are only counted)" : "");
}

/* The checks a camera's firmware makes on what clients write (gige_regs.h). */
static void check_registers(struct gige *g)
{
    nc__gige_check_registers(g->fc, g->W, g->H, g->meta_rows, g->held, &g->applied, refused, g);
}

/* Client-written settings to the emulator (gige_regs.h). */
static void apply_settings(struct gige *g)
{
    if (g->ctl)
        nc__gige_apply(g->fc, g->ctl, &g->applied, refused, g);
}

/* The controlling client released the device, or its heartbeat ran out (the device found it so at a message:
 * nc__gige_probe sends one four times a second while a client holds the control): as a GigE Vision camera does,
 * the acquisition stops and the stream channel closes, so that no frame goes to a client that is gone, nor to it
 * again when another client takes the control. */
static void control_ended(struct gige *g)
{
    const int acquiring = arv_fake_camera_get_acquisition_status(g->fc) != 0;
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_ACQUISITION, 0);
    nc__gige_reg_set(g->fc, REG_ACQ_COMMAND, REG_ACQ_NONE); /* nor a command of the client gone */
    nc__gige_reg_set(g->fc, REG_HOST_PORT, 0);
    nc_log_info("output/gige", "the controlling client released the device or its heartbeat (%u ms) ran out%s",
                nc__gige_reg(g->fc, REG_HEARTBEAT), acquiring ? ": acquisition stopped, stream channel closed" : "");
}

static void *poll_thread(void *arg)
{
    struct gige *g = arg;
    const long period_ns = (long)(1e9 / g->poll_hz);
    int64_t next_rate_ns = 0, next_probe_ns = 0;
    while (!atomic_load(&g->stop)) {
        nanosleep(&(struct timespec){period_ns / 1000000000, period_ns % 1000000000}, NULL); /* poll_hz 1: 1 s */
        /* What a client wrote within one period is taken in a GenICam client's order: settings, AcquisitionStart,
         * TriggerSoftware. So the settings apply before the stream opens to exposures from now on, and a trigger
         * right after the start or a setting makes a frame that is sent, with that setting. */
        const int controlled = arv_fake_camera_get_control_channel_privilege(g->fc) != 0;
        if (g->controlled && !controlled)
            control_ended(g);
        g->controlled = controlled;
        if ((nc__gige_reg(g->fc, REG_HOST_PORT) & 0xffff) == 0)
            atomic_store(&g->channel_closed, 1);
        int64_t now = nc_mono_ns();
        nc__gige_clock_poll(g->fc, &g->clock, now);
        if (controlled && g->probe_fd >= 0 && now >= next_probe_ns) {
            nc__gige_probe(g->probe_fd);
            next_probe_ns = now + 250000000;
        }
        /* AcquisitionStart and Stop write a command the device takes here, the last one written: so a Stop
         * and a Start since the last look are a restart (the status register alone, 1 before and after, hid
         * it: frames exposed before the Start went out after it). */
        const uint32_t cmd = nc__gige_reg(g->fc, REG_ACQ_COMMAND);
        if (cmd != REG_ACQ_NONE) {
            /* what the senders go by (sending_from) decided before the command is cleared: a Start sends
             * nothing until its settings are applied and its time taken below, a Stop nothing at once.
             * (A command written between the read above and the clear is lost, as a TriggerSoftware latch
             * can be: Aravis's registers are plain memory, with no exchange.) */
            atomic_store(&g->acq_start_ns, cmd == 1 ? INT64_MAX : 0);
            nc__gige_reg_set(g->fc, REG_ACQ_COMMAND, REG_ACQ_NONE);
            nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_ACQUISITION, cmd == 1);
        }
        int acquiring = controlled && arv_fake_camera_get_acquisition_status(g->fc) != 0;
        check_registers(g);
        apply_settings(g);
        if (acquiring && (cmd == 1 || !atomic_load(&g->acq_start_ns)))
            atomic_store(&g->acq_start_ns, nc_mono_ns());
        else if (!acquiring)
            atomic_store(&g->acq_start_ns, 0);
        if (nc__gige_reg(g->fc, REG_TRIGGER_SW) == 1) {
            nc__gige_reg_set(g->fc, REG_TRIGGER_SW, 0);
            if (g->ctl)
                g->ctl->software_trigger(g->ctl->emu);
        }
        if (g->ctl && g->ctl->resulting_rate_hz && now >= next_rate_ns) {
            nc__gige_reg_set_double(g->fc, REG_RESULTING_RATE, g->ctl->resulting_rate_hz(g->ctl->emu));
            next_rate_ns = now + 100000000;
        }
    }
    return NULL;
}

/* ---- frames ----------------------------------------------------------------- */

/* The layout of frame r in buf[fill] as the registers ask for it now (ROI,
 * pixel format, the metadata row on top); pack() fills it. Returns 0, or -1
 * while a client's write the device will undo stands (a region beyond the
 * sensor, a format it lacks, nc__gige_check_registers): nothing is sent
 * then (docs/gige.md). */
static int layout(struct gige *g, const struct nc_frame_record *r)
{
    uint32_t v[NC_GIGE_HELD]; /* Width, Height, OffsetX, OffsetY, PixelFormat, ... */
    nc__gige_hold(g->fc, v);
    if (!nc__gige_holds(v, g->W, g->H, g->meta_rows))
        return -1;
    const uint32_t w = v[0], h = v[1], ox = v[2], oy = v[3], pf = v[4];
    const int bpp = pf == PF_MONO8 ? 1 : 2, k = g->fill;
    atomic_store(&g->packed[k], 0);
    g->im[k] = (struct nc__gvsp_image){.pixel_format = pf, .width = w, .height = h, .offset_x = ox,
                                       .offset_y = oy, .data = g->buf[k], .size = (size_t)w * h * bpp,
                                       /* the GVSP timestamp: the exposure's start on the device's counter */
                                       .timestamp_ns = nc__gige_clock_at(&g->clock, r->exposure_start_mono_ns),
                                       .ready = &g->packed[k]};
    g->rec[k] = *r;
    g->rec[k].dn = NULL, g->rec[k].attrs = NULL, g->rec[k].nattrs = 0; /* the submit's alone */
    return 0;
}

/* Frame r into buf[k] as layout() set it, announcing the rows done. */
static void pack(struct gige *g, const struct nc_frame_record *r, int k)
{
    const struct nc__gvsp_image *im = &g->im[k];
    nc__gige_image(r->dn, g->W, g->H, g->adc_bits, g->meta_rows ? r : NULL, im->pixel_format, im->width, im->height,
                   (int)im->offset_x, (int)im->offset_y, g->buf[k], &g->packed[k]);
}

/* Where the client wants the stream (GevSCDA, GevSCPHostPort); 0 if nowhere. */
static int stream_dest(struct gige *g, struct sockaddr_in *dest)
{
    GSocketAddress *sa = arv_fake_camera_get_stream_address(g->fc);
    int ok = sa && g_socket_address_to_native(sa, dest, sizeof *dest, NULL) && dest->sin_family == AF_INET &&
             dest->sin_port != 0;
    g_clear_object(&sa);
    return ok;
}

/* Since when frames are sent (CLOCK_MONOTONIC; 0: none): a command the
 * poll thread has not taken yet decides, a Stop at once, a Start (a restart)
 * from its look on (the settings written before it apply from then). */
static int64_t sending_from(struct gige *g)
{
    const uint32_t cmd = nc__gige_reg(g->fc, REG_ACQ_COMMAND);
    return cmd == 0 ? 0 : cmd == 1 ? INT64_MAX : atomic_load(&g->acq_start_ns);
}

/* Each frame packed is sent at once, unless no client acquires or it was
 * exposed before AcquisitionStart. */
static void *sender_thread(void *arg)
{
    struct gige *g = arg;
    pthread_mutex_lock(&g->lock);
    while (!atomic_load(&g->stop)) {
        if (!g->pending) {
            pthread_cond_wait(&g->cond, &g->lock);
            continue;
        }
        int k = g->ready;
        g->ready = g->send;
        g->send = k;
        g->pending = 0;
        int64_t start = sending_from(g);
        struct sockaddr_in dest;
        if (!start || !stream_dest(g, &dest)) {
            g->not_acquiring++;
            continue;
        }
        if (g->rec[k].exposure_start_mono_ns < start) {
            g->before_start++; /* the client asked for frames exposed from AcquisitionStart on */
            continue;
        }
        const int opened = atomic_exchange(&g->channel_closed, 0) || dest.sin_port != g->last_dest.sin_port ||
                           dest.sin_addr.s_addr != g->last_dest.sin_addr.s_addr;
        if (opened) {
            g->gvsp.block_id = 0; /* a stream channel opened: block ids from 1 (gige.md, "Block ids") */
            g->last_dest = dest;
        }
        uint32_t packet = nc__gige_reg(g->fc, REG_PACKET_SIZE) & 0xffff;
        pthread_mutex_unlock(&g->lock); /* submit() may pack and hand over the next frame meanwhile */
        int rc = nc__gvsp_send(&g->gvsp, &dest, packet, &g->im[k], opened);
        pthread_mutex_lock(&g->lock);
        if (rc < 0 && g->send_failed++ == 0)
            nc_log_warn("output/gige", "frame %llu: %s", (unsigned long long)g->rec[k].frame, nc_errmsg());
        g->sent += rc == 0;
    }
    pthread_mutex_unlock(&g->lock);
    return NULL;
}

/* ---- open, submit, close ------------------------------------------------------ */

static void gige_close(void *priv);

static const char *const formats[] = {"Mono8", "Mono12", "Mono16", NULL};

static const struct nc_param gige_params[] = {
    NC_P_STRING("interface", "lo", "network interface the camera lives on (its IPv4 address)"),
    NC_P_STRING("serial", "NAVCAM0001", "serial number, 1 to 15 characters"),
    NC_P_STRING("model", "NavCam emulator", "model name the device reports (DeviceModelName, at most 31 characters)"),
    NC_P_STRING("xml", NULL, "a GenICam description file to serve instead of NavCam's own (relative to the config "
                             "file)"),
    NC_P_ENUM("pixel_format", "Mono16", formats, "initial pixel format (clients may change it)"),
    NC_P_DOUBLE("poll_hz", "1000", 1, 10000, "Hz", "how often client-written settings are read"),
    NC_P_INT("packet_size", NULL, 576, 65000, "bytes",
             "GVSP packet size, a multiple of 4 (default 65000 on lo, 1400 elsewhere)"),
    NC_P_INT("metadata_row", "0", 0, 1, "", "1: a first row (row 0) with the frame's metadata, above the image"),
    NC_P_END,
};

static int gige_open(void *priv, struct nc_cfg_node *opts, const struct nc_output_ctx *ctx)
{
    struct gige *g = priv;
    const char *iface = NULL, *serial = NULL, *model = NULL, *xml = NULL;
    long packet = -1, meta = 0;
    int fmt = 0, rc;
    g->probe_fd = -1;
    if ((rc = nc_param_string(opts, gige_params, "interface", &iface)) < 0 ||
        (rc = nc_param_string(opts, gige_params, "serial", &serial)) < 0 ||
        (rc = nc_param_string(opts, gige_params, "model", &model)) < 0 ||
        (rc = nc_param_string(opts, gige_params, "xml", &xml)) < 0 ||
        (rc = nc_param_enum(opts, gige_params, "pixel_format", &fmt)) < 0 ||
        (rc = nc_param_double(opts, gige_params, "poll_hz", &g->poll_hz)) < 0 ||
        (rc = nc_param_int(opts, gige_params, "packet_size", &packet)) < 0 ||
        (rc = nc_param_int(opts, gige_params, "metadata_row", &meta)) < 0)
        return rc;
    if (strlen(serial) == 0 || strlen(serial) > 15)
        return nc_cfg_key_error(opts, "serial", "expected 1 to 15 characters");
    if (strlen(model) > 31) /* DeviceModelName: 32 bytes, the last a NUL */
        return nc_cfg_key_error(opts, "model", "expected at most 31 characters, not %zu", strlen(model));
    if (packet > 0 && packet % 4)
        return nc_cfg_key_error(opts, "packet_size", "expected a multiple of 4 (GevSCPSPacketSize's step)");
    if (strlen(iface) >= sizeof g->iface)
        return nc_cfg_key_error(opts, "interface", "interface name too long");
    if (ctx->adc_bits > 16 || ctx->adc_bits < 8)
        return nc_error(NC_EUNSUPPORTED, "gige: ADC depth %d bits: GigE output takes 8 to 16", ctx->adc_bits);
    snprintf(g->iface, sizeof g->iface, "%s", iface);
    g->W = ctx->width_px;
    g->H = ctx->height_px;
    g->adc_bits = ctx->adc_bits;
    g->meta_rows = (int)meta;
    g->ctl = ctx->control;
    /* The GenICam description: NavCam's own, or the configured file. */
    char *xml_text = NULL;
    size_t xml_len = 0;
    char path[4096];
    if (xml) {
        if (xml[0] == '/' || !ctx->config_dir)
            snprintf(path, sizeof path, "%s", xml);
        else
            snprintf(path, sizeof path, "%s/%s", ctx->config_dir, xml);
        GError *err = NULL;
        if (!g_file_get_contents(path, &xml_text, &xml_len, &err)) {
            rc = nc_cfg_key_error(opts, "xml", "gige: %s", err ? err->message : "cannot read");
            g_clear_error(&err);
            return rc;
        }
        rc = nc__gige_check_xml(path, xml_text, xml_len);
        g_free(xml_text);
        if (rc < 0) {
            char why[1024]; /* nc_cfg_error writes nc_errmsg's buffer */
            snprintf(why, sizeof why, "%s", nc_errmsg());
            return nc_cfg_key_error(opts, "xml", "%s", why);
        }
    } else {
        if ((rc = nc__gige_check_xml("(built in)", navcam_genicam_xml, sizeof navcam_genicam_xml)) < 0)
            return rc;
        /* The device reads its description from a file. */
        snprintf(path, sizeof path, "%s/navcam-genicam-XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
        int fd = mkstemp(path);
        if (fd < 0)
            return nc_error(-errno, "gige: %s: %s", path, strerror(errno));
        ssize_t n = write(fd, navcam_genicam_xml, sizeof navcam_genicam_xml);
        close(fd);
        if (n != (ssize_t)sizeof navcam_genicam_xml) {
            unlink(path);
            return nc_error(-EIO, "gige: cannot write %s", path);
        }
    }
    if ((rc = nc__gige_check_interface(g->iface, nc_cfg_get(opts, "interface") ? nc_cfg_get(opts, "interface") : opts, g->addr, sizeof g->addr)) < 0) {
        if (!xml)
            unlink(path);
        return rc;
    }
    int nbuf = 0;
    while (nbuf < 3 && (g->buf[nbuf] = calloc((size_t)g->W * (g->H + 1), 2)))
        nbuf++;
    if (nbuf < 3 || (rc = nc__gvsp_open(&g->gvsp, g->addr)) < 0) {
        if (!xml)
            unlink(path);
        for (int i = 0; i < 3; i++)
            free(g->buf[i]);
        memset(g->buf, 0, sizeof g->buf);
        return rc < 0 ? rc : nc_error(-ENOMEM, "out of memory");
    }
    g->fill = 0, g->ready = 1, g->send = 2;
    pthread_mutex_init(&g->lock, NULL);
    pthread_cond_init(&g->cond, NULL);
    const int loopback = !strncmp(g->addr, "127.", 4);
    int before[16], nbefore = nc__gige_discovery_fds(before, 16);
    g->gv = arv_gv_fake_camera_new_full(g->iface, serial, path);
    if (loopback) /* no discovery broadcasts from other interfaces */
        nc__gige_quiet_discovery(before, nbefore);
    g->probe_fd = nc__gige_probe_open(g->addr);
    if (!xml)
        unlink(path); /* read at construction */
    if (!g->gv || !arv_gv_fake_camera_is_running(g->gv)) {
        gige_close(g);
        return nc_error(NC_ECONFIG, "gige: the GigE Vision device did not start on %s", g->iface);
    }
    g->fc = arv_gv_fake_camera_get_fake_camera(g->gv);
    nc__gige_reg_set_string(g->fc, REG_VENDOR, 32, "NavCam");
    nc__gige_reg_set_string(g->fc, REG_MODEL, 32, model);
    nc__gige_reg_set_string(g->fc, REG_VERSION, 32, NC_VERSION_STRING);
    nc__gige_reg_set_string(g->fc, REG_INFO, 48, "navcam serve: a rendered camera");
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_SENSOR_WIDTH, (uint32_t)g->W);
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_SENSOR_HEIGHT, (uint32_t)g->H);
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_WIDTH, (uint32_t)g->W);
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_HEIGHT, (uint32_t)(g->H + g->meta_rows));
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_X_OFFSET, 0);
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_Y_OFFSET, 0);
    nc__gige_reg_set(g->fc, REG_META_ROWS, (uint32_t)g->meta_rows);
    static const uint32_t pfs[] = {PF_MONO8, PF_MONO12, PF_MONO16};
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT, pfs[fmt]);
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_ACQUISITION_MODE, 1);
    nc__gige_reg_set(g->fc, REG_ACQ_COMMAND, REG_ACQ_NONE);
    /* Loopback carries big packets; real links start at the safe 1400. */
    nc__gige_reg_set(g->fc, REG_PACKET_SIZE, (uint32_t)(packet > 0 ? packet : !strcmp(g->iface, "lo") ? 65000 : 1400));
    /* Internal: the device itself never streams (its software trigger is
     * never raised; it looks for it 10 times a second); the sender does. */
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_TRIGGER_MODE, 1);
    nc__gige_reg_set(g->fc, ARV_FAKE_CAMERA_REGISTER_TRIGGER_SOURCE, 1);
    arv_fake_camera_set_trigger_frequency(g->fc, 10);
    nc__gige_hold(g->fc, g->held);
    struct nc_acquisition a = {.frame_rate_hz = 10, .exposure_s = 1e-3};
    if (g->ctl)
        g->ctl->get(g->ctl->emu, &a);
    publish(g, &a);
    int err = pthread_create(&g->sender, NULL, sender_thread, g);
    g->sending = !err;
    if (!err)
        err = pthread_create(&g->thread, NULL, poll_thread, g);
    g->running = !err;
    if (err) {
        gige_close(g);
        return nc_error(-err, "gige: cannot start its threads: %s", strerror(err));
    }
    nc_log_info("output/gige", "GigE Vision camera '%s' (serial %s) on %s (%s), %dx%d %s; open it by address, "
                "e.g. arv-tool-0.8 -a %s features",
            model, serial, g->addr, g->iface, g->W, g->H, formats[fmt], g->addr);
    return 0;
}

static int gige_submit(void *priv, const struct nc_frame_record *r)
{
    struct gige *g = priv;
    if (r->width_px != g->W || r->height_px != g->H)
        return nc_error(NC_ERANGE, "gige: frame %dx%d, camera %dx%d", r->width_px, r->height_px, g->W, g->H);
    /* buf[fill] is submit()'s alone: laid out, handed over, then packed
     * while the sender streams the rows already done. Only submit() swaps
     * fill, so no one writes buf[k] meanwhile. */
    int64_t start = sending_from(g);
    int early = start && r->exposure_start_mono_ns < start;
    int ok = start && !early && layout(g, r) == 0, k = g->fill;
    pthread_mutex_lock(&g->lock);
    g->submitted++;
    if (!start) {
        g->not_acquiring++;
    } else if (early) {
        g->before_start++; /* the client asked for frames exposed from AcquisitionStart on */
    } else if (!ok) {
        g->send_failed++;
    } else {
        if (g->pending)
            g->skipped++; /* replaced by a newer one while the sender was busy */
        g->fill = g->ready;
        g->ready = k;
        g->pending = 1;
        pthread_cond_signal(&g->cond); /* the sender starts now */
    }
    pthread_mutex_unlock(&g->lock);
    if (ok)
        pack(g, r, k);
    return 0;
}

static void gige_close(void *priv)
{
    struct gige *g = priv;
    atomic_store(&g->stop, 1);
    if (g->running)
        pthread_join(g->thread, NULL);
    if (g->sending) {
        pthread_mutex_lock(&g->lock);
        pthread_cond_broadcast(&g->cond);
        pthread_mutex_unlock(&g->lock);
        pthread_join(g->sender, NULL);
    }
    if (g->running)
        nc_log_info("output/gige", "%llu frames handed over, %lu sent (%lu replaced by newer ones while sending, "
                    "%lu while no client acquired, %lu exposed before AcquisitionStart, %lu failed), "
                    "%lu client settings refused",
                    (unsigned long long)g->submitted, g->sent, g->skipped, g->not_acquiring, g->before_start,
                    g->send_failed, g->rejected_settings);
    if (g->gv)
        g_object_unref(g->gv); /* stops and joins the device thread */
    if (g->probe_fd >= 0)
        close(g->probe_fd);
    if (g->buf[0]) {
        pthread_mutex_destroy(&g->lock);
        pthread_cond_destroy(&g->cond);
        nc__gvsp_close(&g->gvsp);
    }
    for (int i = 0; i < 3; i++)
        free(g->buf[i]);
}

const struct nc_output_driver nc_output_gige = {
    .name = "gige",
    .description = "a GigE Vision camera (GenICam, Aravis) on a network interface (default lo)",
    .caps = NC_OUTPUT_CAP_DN16,
    .priv_size = sizeof(struct gige),
    .params = gige_params,
    .open = gige_open,
    .submit = gige_submit,
    .close = gige_close,
};
