/* v4l2_shim.c - an LD_PRELOAD library that makes /dev/null answer the V4L2
 * ioctls of an output device whose VIDIOC_REQBUFS succeeds but grants no
 * buffers (count 0, errno untouched), as a driver may. It lets the v4l2
 * output's set-up be tested on the host, without a kernel driver: the
 * output must refuse such a device with its own message instead of
 * reporting a stale errno (or success) with the device closed.
 * Everything else goes to the real ioctl(). */
#define _GNU_SOURCE 1
#include <dlfcn.h>
#include <errno.h>
#include <linux/videodev2.h>
#include <stdarg.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

static struct v4l2_format kept;

static int is_dev_null(int fd)
{
    struct stat st;
    return fstat(fd, &st) == 0 && S_ISCHR(st.st_mode) && major(st.st_rdev) == 1 && minor(st.st_rdev) == 3;
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
            strcpy((char *)c->driver, "shim");
            strcpy((char *)c->card, "No Buffers");
            c->capabilities = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING | V4L2_CAP_DEVICE_CAPS;
            c->device_caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
            return 0;
        }
        case VIDIOC_S_FMT: kept = *(struct v4l2_format *)arg; return 0;
        case VIDIOC_G_FMT: *(struct v4l2_format *)arg = kept; return 0;
        case VIDIOC_S_PARM: return 0;
        case VIDIOC_REQBUFS: ((struct v4l2_requestbuffers *)arg)->count = 0; return 0;
        default: errno = ENOTTY; return -1;
        }
    }
    int (*real)(int, unsigned long, ...) = (int (*)(int, unsigned long, ...))dlsym(RTLD_NEXT, "ioctl");
    return real(fd, request, arg);
}
