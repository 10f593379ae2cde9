/* gvsp.c - GVSP image blocks (gvsp.h): headers built in place, the payload
 * sent straight from the frame (two iovecs a packet), 8 packets a
 * sendmmsg() call. */
#include "drivers/gige/gvsp.h"

#include <arpa/inet.h>
#include <errno.h>
#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "core/error.h"

#define BATCH 8
#define LEADER_BYTES 44 /* header 8 + image leader 36 */
#define TRAILER_BYTES 16
#define OVERHEAD 36     /* IP 20 + UDP 8 + GVSP header 8 */
enum { FORMAT_LEADER = 1, FORMAT_TRAILER = 2, FORMAT_PAYLOAD = 3 };

static void be16(uint8_t *p, uint32_t v) { p[0] = (uint8_t)(v >> 8), p[1] = (uint8_t)v; }
static void be32(uint8_t *p, uint32_t v) { be16(p, v >> 16), be16(p + 2, v); }

static void header(uint8_t *p, uint16_t block, int format, uint32_t packet_id)
{
    be16(p, 0); /* status: success */
    be16(p + 2, block);
    be32(p + 4, packet_id & 0xffffffu);
    p[4] = (uint8_t)format; /* standard IDs: the extended-ID flag (bit 7) clear */
}

int nc__gvsp_open(struct nc__gvsp *s, const char *addr)
{
    memset(s, 0, sizeof *s);
    s->fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (s->fd < 0)
        return nc_error(-errno, "gige: stream socket: %s", strerror(errno));
    struct sockaddr_in sa = {.sin_family = AF_INET};
    int sndbuf = 8 << 20; /* a whole 1024x1024 Mono16 frame in flight */
    setsockopt(s->fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
    if (inet_pton(AF_INET, addr, &sa.sin_addr) != 1 || bind(s->fd, (struct sockaddr *)&sa, sizeof sa) < 0) {
        int err = errno;
        close(s->fd);
        s->fd = -1;
        return nc_error(-err, "gige: cannot bind the stream socket to %s: %s", addr, strerror(err));
    }
    s->packets_size = (size_t)BATCH * 16;
    if (!(s->packets = malloc(s->packets_size))) {
        nc__gvsp_close(s);
        return nc_error(-ENOMEM, "out of memory");
    }
    return 0;
}

/* Send n prepared messages, all of them (sendmmsg may take fewer). */
static int flush(struct nc__gvsp *s, struct mmsghdr *m, int n)
{
    for (int done = 0; done < n;) {
        int k = sendmmsg(s->fd, m + done, (unsigned)(n - done), 0);
        if (k < 0 && errno == EINTR)
            continue;
        if (k < 0 && (errno == ENOBUFS || errno == EAGAIN)) {
            usleep(50); /* the socket buffer is full: let the kernel drain it */
            continue;
        }
        if (k < 0)
            return nc_error(-errno, "gige: sending the stream: %s", strerror(errno));
        done += k;
    }
    return 0;
}

int nc__gvsp_send(struct nc__gvsp *s, const struct sockaddr_in *dest, uint32_t packet_size,
                  const struct nc__gvsp_image *im, int first)
{
    const long pause_ns = first ? NC_GVSP_FIRST_PAUSE_NS : 0;
    if (packet_size <= OVERHEAD + 4 || packet_size > 65500)
        return nc_error(NC_ERANGE, "gige: packet size %u bytes", packet_size);
    const size_t chunk = packet_size - OVERHEAD;
    if (++s->block_id == 0)
        s->block_id = 1;
    uint8_t leader[LEADER_BYTES], trailer[TRAILER_BYTES];
    header(leader, s->block_id, FORMAT_LEADER, 0);
    be16(leader + 8, 0);
    be16(leader + 10, 0x0001); /* payload type: image */
    be32(leader + 12, (uint32_t)(im->timestamp_ns >> 32));
    be32(leader + 16, (uint32_t)im->timestamp_ns);
    be32(leader + 20, im->pixel_format);
    be32(leader + 24, im->width);
    be32(leader + 28, im->height);
    be32(leader + 32, im->offset_x);
    be32(leader + 36, im->offset_y);
    be32(leader + 40, 0); /* x and y padding */
    struct mmsghdr m[BATCH];
    struct iovec iov[BATCH][2];
    memset(m, 0, sizeof m);
    int n = 0, rc = 0;
    size_t npay = (im->size + chunk - 1) / chunk;
    for (size_t id = 0; rc == 0 && id < npay + 2; id++) {
        if (id == 0) {
            iov[n][0] = (struct iovec){leader, sizeof leader};
            m[n].msg_hdr.msg_iovlen = 1;
        } else if (id <= npay) {
            uint8_t *h = s->packets + (size_t)n * 16;
            header(h, s->block_id, FORMAT_PAYLOAD, (uint32_t)id);
            size_t off = (id - 1) * chunk, len = im->size - off < chunk ? im->size - off : chunk;
            iov[n][0] = (struct iovec){h, 8};
            iov[n][1] = (struct iovec){(void *)(im->data + off), len};
            m[n].msg_hdr.msg_iovlen = 2;
        } else {
            header(trailer, s->block_id, FORMAT_TRAILER, (uint32_t)id);
            be16(trailer + 8, 0);
            be16(trailer + 10, 0x0001);
            be32(trailer + 12, im->height);
            iov[n][0] = (struct iovec){trailer, sizeof trailer};
            m[n].msg_hdr.msg_iovlen = 1;
        }
        m[n].msg_hdr.msg_iov = iov[n];
        m[n].msg_hdr.msg_name = (void *)dest;
        m[n].msg_hdr.msg_namelen = sizeof *dest;
        if (++n == BATCH || id == npay + 1 || (id == 0 && pause_ns > 0)) {
            size_t need = id * chunk < im->size ? id * chunk : im->size; /* the batch's last byte */
            while (im->ready && atomic_load_explicit(im->ready, memory_order_acquire) < need)
                sched_yield(); /* rarely: the packer runs 3 times faster than this sends */
            rc = flush(s, m, n);
            n = 0;
            if (id == 0 && pause_ns > 0 && rc == 0)
                nanosleep(&(struct timespec){pause_ns / 1000000000, pause_ns % 1000000000}, NULL);
        }
    }
    return rc;
}

void nc__gvsp_close(struct nc__gvsp *s)
{
    if (s->fd >= 0)
        close(s->fd);
    s->fd = -1;
    free(s->packets);
    s->packets = NULL;
}
