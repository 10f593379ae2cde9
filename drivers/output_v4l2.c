/* output_v4l2.c - the V4L2 output: frames written to a video output device
 * (v4l2loopback, so that any V4L2 reader sees a camera) with write().
 *
 * The device is chosen by path, by card label, or as the first
 * output-capable device. The format is set and read back: GREY for ADCs of
 * up to 8 bits, Y16 (little-endian) otherwise, the DN MSB-aligned
 * (DN << (16 - adc_bits), as GigE Mono16) or, with y16_align: lsb, as is
 * (as the file output writes them). A device that fails
 * mid-run is closed, the failure is counted (as failed frames) and named on
 * stderr, and the device is looked for again every reopen_interval_s; the
 * other outputs keep running meanwhile.
 *
 * v4l2loopback 0.12.7 (Debian 12) behaviour this follows
 * (../shared/notes/kernel-drivers-in-qemu.md): output streaming with mmap
 * tears frames, so frames go through write(), which copies into the
 * driver's ring; with exclusive_caps=1 the device loses both capabilities
 * after a plain write() producer closes, unless VIDIOC_STREAMON(OUTPUT) was
 * called once after S_FMT; Y10 is sized wrongly, so it is not offered.
 * Options: v4l2_params below (docs/v4l2-gpio.md).
 */
#include <errno.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "emulator/output.h"

#define MAX_VIDEO_NODES 64
#define MMAP_BUFFERS 4

enum io_method { IO_AUTO, IO_WRITE, IO_MMAP };

struct v4l2_out {
    /* what to look for */
    char want_path[256], want_card[32]; /* v4l2_capability.card: 31 characters and a NUL */
    uint32_t fourcc;
    int msb;
    double fps;
    int64_t reopen_ns;
    long reopen_limit;
    /* the frame: height counts the metadata row, when there is one (row 0) */
    int width, height, bits, meta;
    size_t bytesperline, size;
    unsigned char *buf;
    /* the open device */
    int fd;
    char path[256], card[33], driver[17];
    uint32_t caps;
    enum io_method io_opt, io;
    struct { void *mem; size_t len; int queued; } mbuf[MMAP_BUFFERS]; /* mmap streaming's buffers */
    unsigned nmbuf;
    /* failures */
    int64_t next_try_ns;
    long tries;
    unsigned long written, lost, reopened;
    unsigned long lost_at_close; /* lost when the device was closed: the outage's own count is lost less this */
    /* the frame interval the driver kept (0/0: it keeps none), and how often a reader changed it */
    struct v4l2_fract interval;
    unsigned long interval_resets;
};

static int xioctl(int fd, unsigned long req, void *arg)
{
    int r;
    while ((r = ioctl(fd, req, arg)) < 0 && errno == EINTR)
        ;
    return r;
}

static const char *fourcc_text(uint32_t f, char buf[5])
{
    for (int i = 0; i < 4; i++)
        buf[i] = (char)((f >> (8 * i)) & 0xff);
    buf[4] = 0;
    for (int i = 3; i > 0 && buf[i] == ' '; i--) /* "Y16 " */
        buf[i] = 0;
    return buf;
}

/* Open path; 1 with *cap filled when it is a video output device (write()
 * or streaming I/O), 0 when it is another kind of device, -errno on
 * failure. */
static int probe(const char *path, int *fd_out, struct v4l2_capability *cap, uint32_t *caps_out)
{
    int fd = open(path, O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return -errno;
    memset(cap, 0, sizeof *cap);
    if (xioctl(fd, VIDIOC_QUERYCAP, cap) < 0) {
        int err = -errno;
        close(fd);
        return err;
    }
    uint32_t caps = cap->capabilities & V4L2_CAP_DEVICE_CAPS ? cap->device_caps : cap->capabilities;
    if (!(caps & V4L2_CAP_VIDEO_OUTPUT) || !(caps & (V4L2_CAP_READWRITE | V4L2_CAP_STREAMING))) {
        close(fd);
        return 0;
    }
    *fd_out = fd;
    *caps_out = caps;
    return 1;
}

/* Find and open the device; on failure the message lists what was seen. */
static int find_device(struct v4l2_out *v)
{
    struct v4l2_capability cap;
    int fd = -1, r;
    if (v->want_path[0]) {
        r = probe(v->want_path, &fd, &cap, &v->caps);
        if (r < 0)
            return nc_error(r, "v4l2 output: %s: %s", v->want_path, strerror(-r));
        if (r == 0)
            return nc_error(NC_EUNSUPPORTED, "v4l2 output: %s (card '%s', driver '%s') is not a video output device "
                                             "(for v4l2loopback with exclusive_caps=1: is another program writing "
                                             "to it?)",
                            v->want_path, (const char *)cap.card, (const char *)cap.driver);
        snprintf(v->path, sizeof v->path, "%s", v->want_path);
    } else {
        char seen[512] = "";
        size_t len = 0;
        for (int i = 0; i < MAX_VIDEO_NODES && fd < 0; i++) {
            char path[32];
            snprintf(path, sizeof path, "/dev/video%d", i);
            r = probe(path, &fd, &cap, &v->caps);
            if (r < 0)
                continue;
            if (len + 80 < sizeof seen)
                len += (size_t)snprintf(seen + len, sizeof seen - len, "%s%s '%s'%s", len ? ", " : "", path,
                                        (const char *)cap.card, r ? "" : " (not an output)");
            if (r == 1 && v->want_card[0] && strcmp((const char *)cap.card, v->want_card)) {
                close(fd);
                fd = -1;
                continue;
            }
            if (r == 1)
                snprintf(v->path, sizeof v->path, "%s", path);
        }
        if (fd < 0)
            return nc_error(-ENODEV, "v4l2 output: no video output device%s%s%s (seen: %s; is v4l2loopback "
                            "loaded%s? docs/setup.md)", v->want_card[0] ? " with card label '" : "", v->want_card,
                            v->want_card[0] ? "'" : "", len ? seen : "no /dev/video* device",
                            v->want_card[0] ? " with that card_label" : "");
    }
    v->fd = fd;
    snprintf(v->card, sizeof v->card, "%s", (const char *)cap.card);
    snprintf(v->driver, sizeof v->driver, "%s", (const char *)cap.driver);
    return 0;
}

/* Stop streaming, unmap, close. */
static void disconnect(struct v4l2_out *v)
{
    if (v->fd < 0)
        return;
    if (v->io == IO_MMAP) {
        int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        xioctl(v->fd, VIDIOC_STREAMOFF, &type);
        for (unsigned i = 0; i < v->nmbuf; i++)
            munmap(v->mbuf[i].mem, v->mbuf[i].len);
        struct v4l2_requestbuffers rb = {.count = 0, .type = V4L2_BUF_TYPE_VIDEO_OUTPUT, .memory = V4L2_MEMORY_MMAP};
        xioctl(v->fd, VIDIOC_REQBUFS, &rb);
        v->nmbuf = 0;
    }
    close(v->fd);
    v->fd = -1;
}

/* Close the device and record why it cannot be used. */
static int fail_setup(struct v4l2_out *v, int code, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int fail_setup(struct v4l2_out *v, int code, const char *fmt, ...)
{
    char msg[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    int rc = nc_error(code, "v4l2 output: %s (card '%s'): %s", v->path, v->card, msg);
    disconnect(v);
    return rc;
}

/* Format, frame interval and (v4l2loopback) STREAMON on the open device. */
static int setup(struct v4l2_out *v)
{
    struct v4l2_format f = {.type = V4L2_BUF_TYPE_VIDEO_OUTPUT};
    f.fmt.pix.width = (uint32_t)v->width;
    f.fmt.pix.height = (uint32_t)v->height;
    f.fmt.pix.pixelformat = v->fourcc;
    f.fmt.pix.field = V4L2_FIELD_NONE;
    f.fmt.pix.bytesperline = (uint32_t)v->bytesperline;
    f.fmt.pix.sizeimage = (uint32_t)v->size;
    f.fmt.pix.colorspace = V4L2_COLORSPACE_RAW;
    if (xioctl(v->fd, VIDIOC_S_FMT, &f) < 0)
        return fail_setup(v, -errno, "VIDIOC_S_FMT: %s", strerror(errno));
    memset(&f, 0, sizeof f);
    f.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    if (xioctl(v->fd, VIDIOC_G_FMT, &f) < 0)
        return fail_setup(v, -errno, "VIDIOC_G_FMT: %s", strerror(errno));
    /* What the driver kept must be what NavCam writes. */
    if (f.fmt.pix.pixelformat != v->fourcc) {
        char a[5], b[5];
        return fail_setup(v, NC_EUNSUPPORTED, "the driver set pixel format %s instead of %s (v4l2loopback: a reader "
                          "still streaming, or keep_format=1, holds the last producer's format)",
                          fourcc_text(f.fmt.pix.pixelformat, a), fourcc_text(v->fourcc, b));
    }
    if ((int)f.fmt.pix.width != v->width || (int)f.fmt.pix.height != v->height)
        return fail_setup(v, NC_EUNSUPPORTED, "the driver set %ux%u, the camera has %dx%d (v4l2loopback: max_width or "
                          "max_height, or a reader still streaming, or keep_format=1, holds the last producer's "
                          "format)",
                          f.fmt.pix.width, f.fmt.pix.height, v->width, v->height);
    if (f.fmt.pix.field != V4L2_FIELD_NONE)
        return fail_setup(v, NC_EUNSUPPORTED, "the driver set field order %u, NavCam writes progressive frames "
                          "(V4L2_FIELD_NONE)", f.fmt.pix.field);
    if (f.fmt.pix.bytesperline != v->bytesperline)
        return fail_setup(v, NC_EUNSUPPORTED, "the driver set bytesperline %u, NavCam writes %zu",
                          f.fmt.pix.bytesperline, v->bytesperline);
    if (f.fmt.pix.sizeimage < v->size)
        return fail_setup(v, NC_EUNSUPPORTED, "the driver set sizeimage %u, a frame is %zu bytes",
                          f.fmt.pix.sizeimage, v->size);
    /* The frame interval is what readers see as the frame rate; drivers
     * that do not keep one (ENOTTY) are fine. */
    struct v4l2_streamparm p = {.type = V4L2_BUF_TYPE_VIDEO_OUTPUT};
    nc_period_fraction(v->fps, &p.parm.output.timeperframe.numerator, &p.parm.output.timeperframe.denominator);
    if (xioctl(v->fd, VIDIOC_S_PARM, &p) < 0 && errno != ENOTTY && errno != EINVAL)
        return fail_setup(v, -errno, "VIDIOC_S_PARM: %s", strerror(errno));
    v->interval = xioctl(v->fd, VIDIOC_G_PARM, &p) == 0 ? p.parm.output.timeperframe : (struct v4l2_fract){0, 0};
    /* write() for v4l2loopback (its mmap output tears frames) and for
     * devices without streaming I/O; mmap streaming otherwise (the vb2
     * write() emulation of Linux 6.1 queues output buffers with a zero
     * payload, which drivers such as vivid reject). */
    int loopback = !strcmp(v->driver, "v4l2 loopback");
    v->io = v->io_opt != IO_AUTO ? v->io_opt : loopback || !(v->caps & V4L2_CAP_STREAMING) ? IO_WRITE : IO_MMAP;
    if (v->io == IO_WRITE && !(v->caps & V4L2_CAP_READWRITE))
        return fail_setup(v, NC_EUNSUPPORTED, "the device does not take write() (use io: mmap)");
    if (v->io == IO_MMAP && !(v->caps & V4L2_CAP_STREAMING))
        return fail_setup(v, NC_EUNSUPPORTED, "the device has no streaming I/O (use io: write)");
    if (v->io == IO_MMAP) {
        struct v4l2_requestbuffers rb = {.count = MMAP_BUFFERS, .type = V4L2_BUF_TYPE_VIDEO_OUTPUT,
                                         .memory = V4L2_MEMORY_MMAP};
        if (xioctl(v->fd, VIDIOC_REQBUFS, &rb) < 0)
            return fail_setup(v, -errno, "VIDIOC_REQBUFS: %s", strerror(errno));
        if (rb.count < 1) /* success with no buffers: errno says nothing here */
            return fail_setup(v, NC_EUNSUPPORTED, "VIDIOC_REQBUFS granted no buffers");
        for (unsigned i = 0; i < rb.count && i < MMAP_BUFFERS; i++) {
            struct v4l2_buffer b = {.type = V4L2_BUF_TYPE_VIDEO_OUTPUT, .memory = V4L2_MEMORY_MMAP, .index = i};
            if (xioctl(v->fd, VIDIOC_QUERYBUF, &b) < 0)
                return fail_setup(v, -errno, "VIDIOC_QUERYBUF: %s", strerror(errno));
            if (b.length < v->size)
                return fail_setup(v, NC_EUNSUPPORTED, "buffer %u holds %u bytes, a frame is %zu", i, b.length, v->size);
            void *m = mmap(NULL, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, v->fd, b.m.offset);
            if (m == MAP_FAILED)
                return fail_setup(v, -errno, "mmap: %s", strerror(errno));
            v->mbuf[i].mem = m;
            v->mbuf[i].len = b.length;
            v->mbuf[i].queued = 0;
            v->nmbuf = i + 1;
        }
    }
    if (loopback || v->io == IO_MMAP) {
        int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
        if (xioctl(v->fd, VIDIOC_STREAMON, &type) < 0)
            return fail_setup(v, -errno, "VIDIOC_STREAMON: %s", strerror(errno));
    }
    return 0;
}

static int connect_device(struct v4l2_out *v)
{
    int rc = find_device(v);
    if (rc >= 0)
        rc = setup(v);
    return rc;
}

static const char *const formats[] = {"auto", "GREY", "Y16", NULL};
static const char *const aligns[] = {"msb", "lsb", NULL};
static const char *const ios[] = {"auto", "write", "mmap", NULL};

static const struct nc_param v4l2_params[] = {
    NC_P_STRING("device", NULL, "device node, e.g. /dev/navcam0 (default: `card`, else the first output device)"),
    NC_P_STRING("card", NULL, "the device's card label, e.g. NavCam (at most 31 characters)"),
    NC_P_ENUM("format", "auto", formats, "GREY for ADCs up to 8 bits, else Y16 (auto)"),
    NC_P_ENUM("y16_align", "msb", aligns, "where Y16 puts the ADC's bits in each 16-bit word"),
    NC_P_ENUM("io", "auto", ios, "write() for v4l2loopback, mmap streaming elsewhere (auto)"),
    NC_P_DOUBLE("frame_rate_hz", NULL, 1e-3, 1000, "Hz", "frame interval announced to readers (default serve.frame_rate_hz)"),
    NC_P_DOUBLE("reopen_interval_s", "1", 0, 3600, "s", "how often a lost device is looked for again (0: never)"),
    NC_P_INT("reopen_limit", "0", 0, 1000000000, "", "give up after this many attempts (0: never)"),
    NC_P_INT("metadata_row", "0", 0, 1, "", "1: a first row (row 0) with the frame's metadata, above the image"),
    NC_P_END,
};

static int v4l2_open(void *priv, struct nc_cfg_node *opts, const struct nc_output_ctx *ctx)
{
    struct v4l2_out *v = priv;
    const char *device = NULL, *card = NULL;
    int fmt = 0, align = 0, io = 0, rc;
    double reopen_s = 0;
    long limit = 0, meta = 0;
    v->fd = -1;
    v->fps = 10;
    if (ctx->control) {
        struct nc_acquisition a;
        ctx->control->get(ctx->control->emu, &a);
        v->fps = a.frame_rate_hz;
    }
    if ((rc = nc_param_string(opts, v4l2_params, "device", &device)) < 0 ||
        (rc = nc_param_string(opts, v4l2_params, "card", &card)) < 0 ||
        (rc = nc_param_enum(opts, v4l2_params, "format", &fmt)) < 0 ||
        (rc = nc_param_enum(opts, v4l2_params, "y16_align", &align)) < 0 ||
        (rc = nc_param_enum(opts, v4l2_params, "io", &io)) < 0 ||
        (rc = nc_param_double(opts, v4l2_params, "frame_rate_hz", &v->fps)) < 0 ||
        (rc = nc_param_double(opts, v4l2_params, "reopen_interval_s", &reopen_s)) < 0 ||
        (rc = nc_param_int(opts, v4l2_params, "reopen_limit", &limit)) < 0 ||
        (rc = nc_param_int(opts, v4l2_params, "metadata_row", &meta)) < 0)
        return rc;
    if (device && card)
        return nc_cfg_key_error(opts, "card", "give either `device` or `card`, not both");
    if (card && strlen(card) >= sizeof v->want_card)
        return nc_cfg_key_error(opts, "card", "a V4L2 card label has at most 31 characters");
    snprintf(v->want_path, sizeof v->want_path, "%s", device ? device : "");
    snprintf(v->want_card, sizeof v->want_card, "%s", card ? card : "");
    if (fmt == 0)
        fmt = ctx->adc_bits <= 8 ? 1 : 2;
    if (fmt == 1 && ctx->adc_bits > 8)
        return nc_cfg_key_error(opts, "format", "GREY holds 8 bits; the camera's ADC has %d (use Y16)", ctx->adc_bits);
    v->fourcc = fmt == 1 ? V4L2_PIX_FMT_GREY : V4L2_PIX_FMT_Y16;
    v->msb = align == 0 && fmt == 2;
    v->io_opt = (enum io_method)io;
    v->reopen_ns = llround(reopen_s * 1e9);
    v->reopen_limit = limit;
    v->width = ctx->width_px;
    v->meta = (int)meta;
    v->height = ctx->height_px + v->meta;
    v->bits = ctx->adc_bits;
    v->bytesperline = (size_t)v->width * (fmt == 1 ? 1 : 2);
    v->size = v->bytesperline * (size_t)v->height;
    if (!(v->buf = malloc(v->size)))
        return nc_error(-ENOMEM, "v4l2 output: out of memory");
    if ((rc = connect_device(v)) < 0) { /* close is not called when open fails */
        free(v->buf);
        return rc;
    }
    char fc[5], rate[96]; /* the interval the device keeps (vivid keeps its own), not the one asked for */
    const unsigned num = v->interval.numerator, den = v->interval.denominator;
    if (num && den)
        snprintf(rate, sizeof rate, "frame interval %u/%u s (%g Hz)", num, den, (double)den / num);
    else
        snprintf(rate, sizeof rate, "no frame interval kept (%g Hz asked)", v->fps);
    nc_log_info("output/v4l2", "%s (card '%s', driver '%s'): %dx%d %s, %s, through %s%s", v->path, v->card, v->driver,
            v->width, v->height, fourcc_text(v->fourcc, fc), rate, v->io == IO_MMAP ? "mmap streaming" : "write()",
            v->meta ? ", row 0 the frame's metadata" : "");
    return 0;
}

/* The frame in the device's pixel format, into dst (v->size bytes), below
 * its metadata row when there is one. */
static void pack(const struct v4l2_out *v, const struct nc_frame_record *r, unsigned char *dst)
{
    if (v->meta) {
        nc_frame_metadata_row(r, dst, v->bytesperline);
        dst += v->bytesperline;
    }
    const uint16_t *dn = r->dn;
    size_t n = (size_t)v->width * (size_t)(v->height - v->meta);
    if (v->fourcc == V4L2_PIX_FMT_GREY) {
        for (size_t i = 0; i < n; i++)
            dst[i] = (unsigned char)(dn[i] > 255 ? 255 : dn[i]);
        return;
    }
    int shift = v->msb ? 16 - v->bits : 0;
    for (size_t i = 0; i < n; i++) {
        unsigned x = (unsigned)dn[i] << shift;
        dst[2 * i] = (unsigned char)(x & 0xff);
        dst[2 * i + 1] = (unsigned char)((x >> 8) & 0xff);
    }
}

/* One frame through write(): 0, -EAGAIN (no free buffer) or a failure. */
static int put_write(struct v4l2_out *v, const struct nc_frame_record *r)
{
    pack(v, r, v->buf);
    ssize_t n = write(v->fd, v->buf, v->size);
    if (n == (ssize_t)v->size)
        return 0;
    if (n < 0 && errno == EAGAIN)
        return -EAGAIN;
    if (n >= 0)
        return nc_error(-EIO, "short write (%zd of %zu bytes)", n, v->size);
    return nc_error(-errno, "write: %s", strerror(errno));
}

/* One frame through streaming I/O: take back the buffers the driver is
 * done with, fill a free one, queue it. */
static int put_mmap(struct v4l2_out *v, const struct nc_frame_record *r)
{
    for (;;) {
        struct v4l2_buffer b = {.type = V4L2_BUF_TYPE_VIDEO_OUTPUT, .memory = V4L2_MEMORY_MMAP};
        if (xioctl(v->fd, VIDIOC_DQBUF, &b) < 0) {
            if (errno == EAGAIN)
                break;
            return nc_error(-errno, "VIDIOC_DQBUF: %s", strerror(errno));
        }
        if (b.index < v->nmbuf)
            v->mbuf[b.index].queued = 0;
    }
    unsigned k = 0;
    while (k < v->nmbuf && v->mbuf[k].queued)
        k++;
    if (k == v->nmbuf)
        return -EAGAIN;
    pack(v, r, v->mbuf[k].mem); /* straight into the driver's buffer */
    struct v4l2_buffer b = {.type = V4L2_BUF_TYPE_VIDEO_OUTPUT, .memory = V4L2_MEMORY_MMAP, .index = k,
                            .bytesused = (uint32_t)v->size, .field = V4L2_FIELD_NONE};
    if (xioctl(v->fd, VIDIOC_QBUF, &b) < 0)
        return nc_error(-errno, "VIDIOC_QBUF: %s", strerror(errno));
    v->mbuf[k].queued = 1;
    return 0;
}

/* v4l2loopback keeps one frame interval for the device, which any reader may set (VIDIOC_S_PARM on the capture
 * side) for every reader: it is read back after each frame and set again where it changed. */
static void keep_interval(struct v4l2_out *v)
{
    struct v4l2_streamparm p = {.type = V4L2_BUF_TYPE_VIDEO_OUTPUT};
    if (!v->interval.numerator || !v->interval.denominator || xioctl(v->fd, VIDIOC_G_PARM, &p) < 0)
        return;
    const struct v4l2_fract got = p.parm.output.timeperframe;
    if (got.numerator == v->interval.numerator && got.denominator == v->interval.denominator)
        return;
    if (!v->interval_resets++)
        nc_log_warn("output/v4l2", "%s: a reader set the frame interval to %u/%u s; set back to %u/%u s (%g Hz), as "
                    "whenever it changes", v->path, got.numerator, got.denominator, v->interval.numerator,
                    v->interval.denominator, (double)v->interval.denominator / v->interval.numerator);
    p.parm.output.timeperframe = v->interval;
    xioctl(v->fd, VIDIOC_S_PARM, &p);
}

static int v4l2_submit(void *priv, const struct nc_frame_record *r)
{
    struct v4l2_out *v = priv;
    if (v->fd < 0) {
        int64_t now = nc_mono_ns();
        const int gave_up = v->reopen_limit && v->tries >= v->reopen_limit;
        if (!v->reopen_ns || gave_up || now < v->next_try_ns) {
            v->lost++;
            return nc_error(-ENODEV, "v4l2 output: no device (%s)%s; %lu frames lost so far", v->path,
                            gave_up ? ", not looked for any more (reopen_limit)" : "", v->lost);
        }
        v->tries++;
        v->next_try_ns = now + v->reopen_ns;
        if (connect_device(v) < 0) {
            char why[256];
            snprintf(why, sizeof why, "%s", nc_errmsg());
            v->lost++;
            if (v->reopen_limit && v->tries >= v->reopen_limit)
                nc_log_error("output/v4l2", "%s (card '%s'): %ld attempts to reopen it failed (reopen_limit): "
                             "given up, its frames are lost from now on", v->path, v->card, v->tries);
            return nc_error(-ENODEV, "v4l2 output: reopening failed (attempt %ld): %s", v->tries, why);
        }
        v->reopened++;
        nc_log_info("output/v4l2", "%s (card '%s') reopened after %lu lost frames", v->path, v->card,
                    v->lost - v->lost_at_close);
        v->tries = 0;
    }
    int rc = v->io == IO_MMAP ? put_mmap(v, r) : put_write(v, r);
    if (rc == 0) {
        v->written++;
        keep_interval(v);
        return 0;
    }
    v->lost++;
    if (rc == -EAGAIN) /* the device has no free buffer: this frame only */
        return nc_error(-EAGAIN, "v4l2 output: %s: no free buffer (the device is not keeping up), frame dropped",
                        v->path);
    char why[128];
    snprintf(why, sizeof why, "%s", nc_errmsg());
    disconnect(v);
    v->lost_at_close = v->lost - 1; /* this frame is the outage's first */
    v->next_try_ns = nc_mono_ns() + v->reopen_ns;
    char again[96] = "it is not reopened (reopen_interval_s: 0)";
    if (v->reopen_ns)
        snprintf(again, sizeof again, "looking for it again every %g s", v->reopen_ns * 1e-9);
    return nc_error(rc, "v4l2 output: %s (card '%s') failed: %s; closed, %s", v->path, v->card, why, again);
}

static void v4l2_close(void *priv)
{
    struct v4l2_out *v = priv;
    disconnect(v);
    if (v->lost || v->reopened || v->interval_resets)
        nc_log_info("output/v4l2", "%lu frames written, %lu lost, %lu reopens, frame interval set back %lu times",
                    v->written, v->lost, v->reopened, v->interval_resets);
    free(v->buf);
}

const struct nc_output_driver nc_output_v4l2 = {
    .name = "v4l2",
    .description = "a V4L2 video output device (v4l2loopback, or any output device)",
    .caps = NC_OUTPUT_CAP_DN16,
    .priv_size = sizeof(struct v4l2_out),
    .params = v4l2_params,
    .open = v4l2_open,
    .submit = v4l2_submit,
    .close = v4l2_close,
};
