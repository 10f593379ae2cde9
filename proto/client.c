/* client.c - navcam/client.h: sockets and framing for simulators. */
#include "navcam/client.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "core/error.h"

/* A FRAME answer read and not yet returned: nc_client_wait_frame passes
 * over answers to other requests and keeps them for the calls after it. */
struct answer {
    uint32_t sequence, status;
    uint64_t frame;
};

struct nc_client {
    int fd, tcp;
    uint32_t next_sequence;
    uint8_t buf[4 + NC_PROTO_MAX_BYTES];
    size_t have;
    struct answer *held; /* in the order NavCam sent them */
    size_t nheld, held_cap;
};

int nc_client_connect(const char *host, int port, int tcp, struct nc_client **out)
{
    if (port < 1 || port > 65535)
        return nc_error(-EINVAL, "port %d: expected 1 to 65535", port);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    if (!host || inet_pton(AF_INET, host, &a.sin_addr) != 1)
        return nc_error(-EINVAL, "'%s' is not a numeric IPv4 address", host);
    struct nc_client *c = calloc(1, sizeof *c);
    if (!c)
        return nc_error(-ENOMEM, "out of memory");
    c->tcp = tcp;
    c->next_sequence = 1;
    c->fd = socket(AF_INET, (tcp ? SOCK_STREAM : SOCK_DGRAM) | SOCK_CLOEXEC, 0);
    int one = 1;
    if (c->fd < 0 || (tcp && setsockopt(c->fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one) < 0) ||
        connect(c->fd, (struct sockaddr *)&a, sizeof a) < 0) {
        int rc = nc_error(-errno, "%s %s:%d: connect: %s", tcp ? "TCP" : "UDP", host, port, strerror(errno));
        if (c->fd >= 0)
            close(c->fd);
        free(c);
        return rc;
    }
    *out = c;
    return 0;
}

long nc_client_send(struct nc_client *c, struct nc_pose_msg *m)
{
    uint8_t buf[4 + NC_PROTO_MAX_BYTES];
    if (m->type != NC_MSG_POSE && m->type != NC_MSG_TRIGGER) /* FRAME goes the other way */
        return nc_error(-EINVAL, "message type %d: a simulator sends POSE (%d) or TRIGGER (%d)", (int)m->type,
                        (int)NC_MSG_POSE, (int)NC_MSG_TRIGGER);
    m->sequence = c->next_sequence;
    size_t n = nc_msg_encode(m, buf + 4, NC_PROTO_MAX_BYTES);
    if (!n)
        return nc_error(-EINVAL, "message not encodable: flags 0x%x are not those of message type %d "
                                 "(docs/protocol.md)", m->flags, (int)m->type);
    c->next_sequence++; /* used only by a message that goes out */
    for (int i = 0; i < 4; i++)
        buf[i] = (uint8_t)(n >> (8 * i));
    const uint8_t *p = c->tcp ? buf : buf + 4;
    size_t len = c->tcp ? n + 4 : n;
    int refused = 0;
    while (len > 0) {
        ssize_t w = send(c->fd, p, len, MSG_NOSIGNAL);
        if (w < 0) {
            /* UDP: a refusal is the port unreachable that an earlier
             * datagram met, reported now; this one is sent anyway, fire and
             * forget. */
            if (errno == EINTR || (!c->tcp && errno == ECONNREFUSED && !refused++))
                continue;
            return nc_error(-errno, "send: %s", strerror(errno));
        }
        p += w;
        len -= (size_t)w;
    }
    return (long)m->sequence;
}

/* The next FRAME answer from the connection (not from those held). */
static int read_answer(struct nc_client *c, int timeout_ms, uint32_t *sequence, uint64_t *frame, uint32_t *status)
{
    if (!c->tcp)
        return nc_error(-EOPNOTSUPP, "frames are answered over TCP only");
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int polled = 0;; polled = 1) {
        while (c->have >= 4) {
            uint32_t len = (uint32_t)c->buf[0] | (uint32_t)c->buf[1] << 8 | (uint32_t)c->buf[2] << 16 |
                           (uint32_t)c->buf[3] << 24;
            if (len > NC_PROTO_MAX_BYTES)
                return nc_error(-EPROTO, "bad frame answer length %u", len);
            if (c->have < 4 + len)
                break;
            struct nc_pose_msg m;
            enum nc_reject r = nc_msg_decode(c->buf + 4, len, &m);
            memmove(c->buf, c->buf + 4 + len, c->have - 4 - len);
            c->have -= 4 + len;
            if (r != NC_REJECT_NONE || m.type != NC_MSG_FRAME)
                continue;
            if (m.status == NC_FRAME_REFUSED)
                return nc_error(-ECONNREFUSED, "navcam serve refused this connection: all %llu of its client slots "
                                               "are in use (serve.max_clients)",
                                (unsigned long long)m.frame);
            *sequence = m.sequence;
            *frame = m.frame;
            *status = m.status;
            return 0;
        }
        /* timeout_ms < 0: no limit; 0: what has already arrived, no wait */
        struct timespec t1;
        clock_gettime(CLOCK_MONOTONIC, &t1);
        long left = timeout_ms - ((t1.tv_sec - t0.tv_sec) * 1000 + (t1.tv_nsec - t0.tv_nsec) / 1000000);
        if (timeout_ms >= 0 && left <= 0 && polled)
            return nc_error(-ETIMEDOUT, "no frame answer within %d ms", timeout_ms);
        struct pollfd pf = {c->fd, POLLIN, 0};
        if (poll(&pf, 1, timeout_ms < 0 ? -1 : left > 0 ? (int)left : 0) <= 0)
            continue;
        ssize_t n = read(c->fd, c->buf + c->have, sizeof c->buf - c->have);
        if (n <= 0)
            return nc_error(n == 0 ? -ECONNRESET : -errno, "connection closed while waiting for a frame answer");
        c->have += (size_t)n;
    }
}

/* Held answer i out, removed. */
static void take_held(struct nc_client *c, size_t i, uint32_t *sequence, uint64_t *frame, uint32_t *status)
{
    *sequence = c->held[i].sequence, *frame = c->held[i].frame, *status = c->held[i].status;
    memmove(c->held + i, c->held + i + 1, (c->nheld - i - 1) * sizeof *c->held);
    c->nheld--;
}

int nc_client_next_frame(struct nc_client *c, int timeout_ms, uint32_t *sequence, uint64_t *frame, uint32_t *status)
{
    if (c->nheld) {
        take_held(c, 0, sequence, frame, status);
        return 0;
    }
    return read_answer(c, timeout_ms, sequence, frame, status);
}

int nc_client_wait_frame(struct nc_client *c, uint32_t sequence, int timeout_ms, uint64_t *frame, uint32_t *status)
{
    uint32_t seq;
    for (size_t i = 0; i < c->nheld; i++)
        if (c->held[i].sequence == sequence) {
            take_held(c, i, &seq, frame, status);
            return 0;
        }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        clock_gettime(CLOCK_MONOTONIC, &t1);
        long left = timeout_ms - ((t1.tv_sec - t0.tv_sec) * 1000 + (t1.tv_nsec - t0.tv_nsec) / 1000000);
        int rc = read_answer(c, timeout_ms < 0 ? -1 : left > 0 ? (int)left : 0, &seq, frame, status);
        if (rc == -ETIMEDOUT)
            return nc_error(rc, "no frame for request %u within %d ms", sequence, timeout_ms);
        if (rc < 0 || seq == sequence)
            return rc;
        if (c->nheld == c->held_cap) { /* another request's answer: kept for the calls after this one */
            size_t cap = c->held_cap ? 2 * c->held_cap : 16;
            struct answer *h = realloc(c->held, cap * sizeof *h);
            if (!h)
                return nc_error(-ENOMEM, "out of memory for the answers to other requests");
            c->held = h, c->held_cap = cap;
        }
        c->held[c->nheld++] = (struct answer){seq, *status, *frame};
    }
}

void nc_client_close(struct nc_client *c)
{
    if (!c)
        return;
    close(c->fd);
    free(c->held);
    free(c);
}

const char *nc_client_errmsg(void) { return nc_errmsg(); }
