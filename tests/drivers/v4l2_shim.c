/* v4l2_shim.c - an LD_PRELOAD library that makes /dev/null answer the V4L2
 * ioctls of an output device whose VIDIOC_REQBUFS succeeds but grants no
 * buffers (count 0, errno untouched), as a driver may. It lets the v4l2
 * output's set-up be tested on the host, without a kernel driver: the
 * output must refuse such a device with its own message instead of
 * reporting a stale errno (or success) with the device closed.
 * With NAVCAM_SHIM_UNPLUG set, /dev/null is instead a v4l2loopback-like
 * device taking frames by write(): the 3rd frame finds no free buffer
 * (EAGAIN), the 6th finds the device unplugged (ENODEV), and for 2.5 s
 * after that /dev/null cannot be opened (ENOENT), as a device that is
 * away; then it is back. It keeps the frame interval set (VIDIOC_S_PARM,
 * read back by G_PARM), and with NAVCAM_SHIM_WIDTH=N it keeps a width of N
 * whatever is asked, as v4l2loopback holding a reader's format does.
 * Everything else goes to the real calls. */
#define _GNU_SOURCE 1
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>
#include <linux/videodev2.h>
#include <stdarg.h>
#include <stdint.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

static struct v4l2_format kept;
static struct v4l2_streamparm parm;

static int is_dev_null(int fd)
{
    struct stat st;
    return fstat(fd, &st) == 0 && S_ISCHR(st.st_mode) && major(st.st_rdev) == 1 && minor(st.st_rdev) == 3;
}

static int frames;
static double away_until_s;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int unplug(void) { return getenv("NAVCAM_SHIM_UNPLUG") != NULL; }

static int away(const char *path) { return unplug() && !strcmp(path, "/dev/null") && now_s() < away_until_s; }

int open(const char *path, int flags, ...)
{
    va_list ap;
    va_start(ap, flags);
    const mode_t mode = (mode_t)va_arg(ap, int);
    va_end(ap);
    if (away(path)) {
        errno = ENOENT;
        return -1;
    }
    int (*real)(const char *, int, ...) = (int (*)(const char *, int, ...))dlsym(RTLD_NEXT, "open");
    return real(path, flags, mode);
}

ssize_t write(int fd, const void *buf, size_t n)
{
    ssize_t (*real)(int, const void *, size_t) = (ssize_t(*)(int, const void *, size_t))dlsym(RTLD_NEXT, "write");
    if (unplug() && n > 1000 && is_dev_null(fd)) { /* a frame, not a log line */
        if (++frames == 3) {
            errno = EAGAIN;
            return -1;
        }
        if (frames == 6) {
            away_until_s = now_s() + 2.5;
            errno = ENODEV;
            return -1;
        }
    }
    return real(fd, buf, n);
}


int ioctl(int fd, unsigned long request, ...)
{
    va_list ap;
    va_start(ap, request);
    void *arg = va_arg(ap, void *);
    va_end(ap);
    if (_IOC_TYPE(request) == 'V' && is_dev_null(fd)) {
        switch (request) {
        case VIDIOC_QUERYCAP: {
            struct v4l2_capability *c = arg;
            memset(c, 0, sizeof *c);
            strcpy((char *)c->driver, unplug() ? "v4l2 loopback" : "shim");
            strcpy((char *)c->card, unplug() ? "Unplugged" : "No Buffers");
            const uint32_t rw = unplug() ? V4L2_CAP_READWRITE : 0;
            c->capabilities = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING | rw | V4L2_CAP_DEVICE_CAPS;
            c->device_caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING | rw;
            return 0;
        }
        case VIDIOC_STREAMON: return 0;
        case VIDIOC_S_FMT:
            kept = *(struct v4l2_format *)arg;
            if (getenv("NAVCAM_SHIM_WIDTH"))
                kept.fmt.pix.width = (uint32_t)atoi(getenv("NAVCAM_SHIM_WIDTH"));
            return 0;
        case VIDIOC_G_FMT: *(struct v4l2_format *)arg = kept; return 0;
        case VIDIOC_S_PARM: parm = *(struct v4l2_streamparm *)arg; return 0;
        case VIDIOC_G_PARM: *(struct v4l2_streamparm *)arg = parm; return 0;
        case VIDIOC_REQBUFS: ((struct v4l2_requestbuffers *)arg)->count = 0; return 0;
        default: errno = ENOTTY; return -1;
        }
    }
    int (*real)(int, unsigned long, ...) = (int (*)(int, unsigned long, ...))dlsym(RTLD_NEXT, "ioctl");
    return real(fd, request, arg);
}
