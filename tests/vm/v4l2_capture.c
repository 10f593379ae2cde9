/* v4l2_capture.c - a plain V4L2 capture reader, as flight software would
 * be: mmap streaming (REQBUFS, QBUF, STREAMON, poll, DQBUF). It waits for
 * the device to offer capture (v4l2loopback with exclusive_caps=1 does so
 * once a producer runs), then stores each frame as cap_NNNNNN.raw and a line
 * "n,sequence,bytesused,dequeued_mono_ns" in capture.csv.
 *
 * Usage: v4l2_capture DEVICE NFRAMES OUTDIR TIMEOUT_S [BUFFERS]
 * Exit 0 when NFRAMES were captured, 1 otherwise. OUTDIR/ready appears once
 * streaming is on.
 */
#include <errno.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static int xioctl(int fd, unsigned long req, void *arg)
{
    int r;
    while ((r = ioctl(fd, req, arg)) < 0 && errno == EINTR)
        ;
    return r;
}

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: v4l2_capture DEVICE NFRAMES OUTDIR TIMEOUT_S [BUFFERS]\n");
        return 2;
    }
    const char *dev = argv[1], *dir = argv[3];
    int nframes = atoi(argv[2]);
    int64_t deadline = now_ns() + (int64_t)(atof(argv[4]) * 1e9);
    unsigned nbuf = argc > 5 ? (unsigned)atoi(argv[5]) : 2;
    int fd = -1;
    struct v4l2_capability cap;
    /* Wait until the device captures. */
    for (;;) {
        fd = open(dev, O_RDWR | O_NONBLOCK);
        if (fd >= 0 && xioctl(fd, VIDIOC_QUERYCAP, &cap) == 0) {
            unsigned caps = cap.capabilities & V4L2_CAP_DEVICE_CAPS ? cap.device_caps : cap.capabilities;
            if (caps & V4L2_CAP_VIDEO_CAPTURE)
                break;
        }
        if (fd >= 0)
            close(fd);
        fd = -1;
        if (now_ns() > deadline) {
            fprintf(stderr, "v4l2_capture: %s never offered video capture\n", dev);
            return 1;
        }
        usleep(20000);
    }
    struct v4l2_format f = {.type = V4L2_BUF_TYPE_VIDEO_CAPTURE};
    if (xioctl(fd, VIDIOC_G_FMT, &f) < 0) {
        perror("v4l2_capture: VIDIOC_G_FMT");
        return 1;
    }
    char fc[5] = {0};
    memcpy(fc, &f.fmt.pix.pixelformat, 4);
    printf("v4l2_capture: %s card '%s' driver '%s': %ux%u %s bytesperline %u sizeimage %u\n", dev,
           (const char *)cap.card, (const char *)cap.driver, f.fmt.pix.width, f.fmt.pix.height, fc,
           f.fmt.pix.bytesperline, f.fmt.pix.sizeimage);
    struct v4l2_requestbuffers rb = {.count = nbuf, .type = V4L2_BUF_TYPE_VIDEO_CAPTURE, .memory = V4L2_MEMORY_MMAP};
    if (xioctl(fd, VIDIOC_REQBUFS, &rb) < 0 || rb.count < 1) {
        perror("v4l2_capture: VIDIOC_REQBUFS");
        return 1;
    }
    void *mem[32];
    size_t len[32];
    for (unsigned i = 0; i < rb.count && i < 32; i++) {
        struct v4l2_buffer b = {.type = V4L2_BUF_TYPE_VIDEO_CAPTURE, .memory = V4L2_MEMORY_MMAP, .index = i};
        if (xioctl(fd, VIDIOC_QUERYBUF, &b) < 0) {
            perror("v4l2_capture: VIDIOC_QUERYBUF");
            return 1;
        }
        len[i] = b.length;
        mem[i] = mmap(NULL, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, b.m.offset);
        if (mem[i] == MAP_FAILED || xioctl(fd, VIDIOC_QBUF, &b) < 0) {
            perror("v4l2_capture: mmap/VIDIOC_QBUF");
            return 1;
        }
    }
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd, VIDIOC_STREAMON, &type) < 0) {
        perror("v4l2_capture: VIDIOC_STREAMON");
        return 1;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/capture.csv", dir);
    FILE *csv = fopen(path, "w");
    snprintf(path, sizeof path, "%s/ready", dir);
    FILE *ready = fopen(path, "w");
    if (!csv || !ready) {
        perror("v4l2_capture: output files");
        return 1;
    }
    fclose(ready);
    int got = 0;
    while (got < nframes) {
        int64_t left = (deadline - now_ns()) / 1000000;
        if (left <= 0)
            break;
        struct pollfd p = {.fd = fd, .events = POLLIN};
        if (poll(&p, 1, (int)left) <= 0)
            continue;
        struct v4l2_buffer b = {.type = V4L2_BUF_TYPE_VIDEO_CAPTURE, .memory = V4L2_MEMORY_MMAP};
        if (xioctl(fd, VIDIOC_DQBUF, &b) < 0) {
            if (errno == EAGAIN)
                continue;
            perror("v4l2_capture: VIDIOC_DQBUF");
            break;
        }
        int64_t t = now_ns();
        snprintf(path, sizeof path, "%s/cap_%06d.raw", dir, got);
        FILE *o = fopen(path, "wb");
        if (!o || fwrite(mem[b.index], 1, b.bytesused, o) != b.bytesused || fclose(o)) {
            perror(path);
            return 1;
        }
        fprintf(csv, "%d,%u,%u,%lld\n", got, b.sequence, b.bytesused, (long long)t);
        fflush(csv);
        got++;
        if (xioctl(fd, VIDIOC_QBUF, &b) < 0) {
            perror("v4l2_capture: VIDIOC_QBUF");
            break;
        }
    }
    fclose(csv);
    xioctl(fd, VIDIOC_STREAMOFF, &type);
    for (unsigned i = 0; i < rb.count && i < 32; i++)
        munmap(mem[i], len[i]);
    close(fd);
    printf("v4l2_capture: %d of %d frames\n", got, nframes);
    return got == nframes ? 0 : 1;
}
