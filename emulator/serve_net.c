/* serve_net.c - network input (serve_internal.h): one thread polls the UDP
 * socket, the TCP listener and the TCP clients; it decodes messages, counts
 * and logs rejections, feeds the pose timeline and hands capture requests
 * on. It never waits for the render or the outputs. */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "core/clock.h"
#include "core/error.h"
#include "core/log.h"
#include "emulator/serve_internal.h"

static void log_reject(struct nc__emu *e, enum nc_reject r, const char *from)
{
    atomic_fetch_add(&e->rejected[r], 1);
    int64_t now = nc_mono_ns();
    if (now - e->last_reject_log_ns > 1000000000) { /* at most one line a second */
        e->last_reject_log_ns = now;
        nc_log_warn("emulator/net", "rejected a message from %s: %s (counting; further rejections this second not logged)",
                    from, nc_reject_name(r));
    }
}

/* A TCP message whose length prefix no message has, counted and logged. */
static void bad_length(struct nc__emu *e, uint32_t len)
{
    atomic_fetch_add(&e->received, 1);
    log_reject(e, len > NC_PROTO_MAX_BYTES ? NC_REJECT_OVERSIZED : NC_REJECT_TRUNCATED, "a TCP client");
}

/* A message counted and decoded, a rejection counted and logged: its
 * reason, or NC_REJECT_NONE. *answer is set when it carries a CAPTURE that
 * must be answered: accepted, or refused for a value (its header and CRC
 * sound), so that no client waits for it. */
static enum nc_reject take_message(struct nc__emu *e, const uint8_t *buf, size_t len, const char *from,
                                   struct nc_pose_msg *m, int *answer)
{
    atomic_fetch_add(&e->received, 1);
    enum nc_reject r = nc_msg_decode(buf, len, m);
    if (r == NC_REJECT_NONE && m->type == NC_MSG_FRAME)
        r = NC_REJECT_BAD_TYPE; /* FRAME goes the other way */
    if (r != NC_REJECT_NONE)
        log_reject(e, r, from);
    *answer = (r == NC_REJECT_NONE || r == NC_REJECT_NOT_FINITE || r == NC_REJECT_BAD_QUATERNION ||
               r == NC_REJECT_BAD_VALUE) && (m->flags & NC_MSG_CAPTURE);
    return r;
}

static void handle_message(struct nc__emu *e, const uint8_t *buf, size_t len, int client, unsigned gen,
                           const char *from)
{
    struct nc_pose_msg m;
    const int64_t now = nc_mono_ns();
    int answer;
    enum nc_reject r = take_message(e, buf, len, from, &m, &answer);
    if (r != NC_REJECT_NONE) {
        if (answer)
            nc__serve_refused_capture(e, &m, client, gen);
        return;
    }
    if (m.type == NC_MSG_POSE) {
        struct nc_pose p;
        nc_pose_from_msg(&m, &p);
        nc_scene_pose_body(&e->scene, &p);
        pthread_mutex_lock(&e->tl_lock);
        r = nc_timeline_push(&e->tl, &p);
        if (r == NC_REJECT_NONE) {
            e->sim_anchor_ns = m.sim_time_ns;
            e->mono_anchor_ns = now;
            e->have_anchor = 1;
            pthread_cond_broadcast(&e->tl_cond);
        }
        pthread_mutex_unlock(&e->tl_lock);
        /* A lock-step capture is rendered with the pose it carries, so its
         * time need not follow other clients' poses (several simulators may
         * share one camera); only the timeline does not take it. */
        int lockstep_capture = e->mode == NC__MODE_LOCKSTEP && (m.flags & NC_MSG_CAPTURE);
        if (r != NC_REJECT_NONE && !(lockstep_capture && r == NC_REJECT_TIME_BACKWARDS)) {
            log_reject(e, r, from);
            if (m.flags & NC_MSG_CAPTURE) /* still answered, exactly once */
                nc__serve_refused_capture(e, &m, client, gen);
            return;
        }
    }
    if (!(m.flags & NC_MSG_CAPTURE))
        return; /* a pose alone, or a TRIGGER that asks for nothing */
    if (m.type == NC_MSG_POSE && e->mode == NC__MODE_LOCKSTEP)
        nc__serve_lockstep(e, &m, client, gen, now);
    else
        nc__serve_software(e, &m, client, gen, now);
}

int nc__serve_open_sockets(struct nc__emu *e)
{
    e->udp_fd = e->tcp_fd = -1;
    struct sockaddr_in a = {.sin_family = AF_INET};
    if (inet_pton(AF_INET, e->bind, &a.sin_addr) != 1)
        return nc_error(NC_ECONFIG, "serve.bind: '%s' is not an IPv4 address", e->bind);
    int one = 1;
    if (e->udp_port) {
        e->udp_fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        a.sin_port = htons((uint16_t)e->udp_port);
        if (e->udp_fd < 0 || bind(e->udp_fd, (struct sockaddr *)&a, sizeof a) < 0)
            return nc_error(-errno, "serve: UDP %s:%d: bind: %s", e->bind, e->udp_port, strerror(errno));
    }
    if (e->tcp_port) {
        e->tcp_fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        a.sin_port = htons((uint16_t)e->tcp_port);
        if (e->tcp_fd < 0 || setsockopt(e->tcp_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) < 0 ||
            bind(e->tcp_fd, (struct sockaddr *)&a, sizeof a) < 0 || listen(e->tcp_fd, 64) < 0)
            return nc_error(-errno, "serve: TCP %s:%d: %s", e->bind, e->tcp_port, strerror(errno));
    }
    return 0;
}

void nc__serve_close_sockets(struct nc__emu *e)
{
    for (int i = 0; e->clients && i < e->max_clients; i++)
        if (e->clients[i].fd >= 0) {
            close(e->clients[i].fd);
            e->clients[i].fd = -1;
        }
    if (e->udp_fd >= 0)
        close(e->udp_fd);
    if (e->tcp_fd >= 0)
        close(e->tcp_fd);
    e->udp_fd = e->tcp_fd = -1;
}

static void close_client(struct nc__emu *e, int i)
{
    pthread_mutex_lock(&e->client_lock);
    close(e->clients[i].fd);
    e->clients[i].fd = -1;
    e->clients[i].gen++;
    e->clients[i].have = 0;
    e->clients[i].skip = 0;
    e->clients[i].out_len = 0;
    e->clients[i].gone = 0;
    pthread_mutex_unlock(&e->client_lock);
}

/* Pass over what is left of a refused message in a client's buffer: 0
 * when it is all gone. */
static uint32_t skip_refused(struct nc__client *c)
{
    const size_t k = c->skip < c->have ? c->skip : c->have;
    memmove(c->buf, c->buf + k, c->have - k);
    c->have -= k;
    c->skip -= (uint32_t)k;
    return c->skip;
}

/* A length prefix beyond this cannot have framed a NavCam message: the
 * stream is not NavCam's, or lost its place. */
#define SKIP_MAX_BYTES 65536u

/* Take one whole length-prefixed message from a client's buffer: 1 when one
 * was taken (or a refused one begun to be passed over), 0 when none is
 * complete or lock-step has no room for it (the request waits in the
 * buffer: back-pressure), -1 when the client was disconnected. */
static int client_take(struct nc__emu *e, int i)
{
    struct nc__client *c = &e->clients[i];
    if (c->skip && skip_refused(c))
        return 0;
    if (c->have < 4)
        return 0;
    uint32_t len = (uint32_t)c->buf[0] | (uint32_t)c->buf[1] << 8 | (uint32_t)c->buf[2] << 16 | (uint32_t)c->buf[3] << 24;
    if (len > NC_PROTO_MAX_BYTES || len < NC_PROTO_HEADER_BYTES + 4) {
        /* Too long or too short to be a message, but the prefix still says
         * where the next one starts: counted, and its bytes passed over. */
        bad_length(e, len);
        if (len > SKIP_MAX_BYTES) {
            nc_log_warn("emulator", "a TCP client's length prefix says %u bytes (at most %d): not a NavCam stream; "
                        "disconnected", len, NC_PROTO_MAX_BYTES);
            close_client(e, i);
            return -1;
        }
        c->skip = 4 + len;
        skip_refused(c);
        return 1;
    }
    if (c->have < 4 + len || (e->mode == NC__MODE_LOCKSTEP && nc__serve_queue_full(e)))
        return 0;
    handle_message(e, c->buf + 4, len, i, c->gen, "a TCP client");
    memmove(c->buf, c->buf + 4 + len, c->have - 4 - len);
    c->have -= 4 + len;
    return 1;
}

/* Read until the socket is empty or the buffer full (a whole request waits
 * there for room in the job queue); an end of stream or a broken
 * connection marks the client gone. */
static void client_read(struct nc__emu *e, int i)
{
    struct nc__client *c = &e->clients[i];
    while (c->have < sizeof c->buf) {
        ssize_t n = read(c->fd, c->buf + c->have, sizeof c->buf - c->have);
        if (n > 0) {
            c->have += (size_t)n;
            continue;
        }
        if (n < 0 && errno == EINTR)
            continue;
        if (n == 0 || errno != EAGAIN)
            c->gone = 1;
        return;
    }
}

/* Requests waiting in the clients' buffers, one per client in turn, so that
 * no client's backlog goes before another's: the turn goes on from the
 * client after the one whose request was taken last, also across calls (a
 * lock-step queue that frees one place at a time goes to each in turn).
 * A client being served reads its socket at its next turn (the poll found
 * the others' news), a hung-up one from its first: it takes its turns from
 * what its socket still holds, as the others do, and is closed once a turn
 * of it moves nothing (docs/emulator.md: what the job queue has no room
 * for then is discarded unread), before the round's new connections are
 * taken, so that a client that closes and connects again at once finds its
 * slot free. At most 256 turns a client a call: a client that sends
 * without end does not keep the thread from the rest; returns 1 when turns
 * were left (the next round then does not wait in poll, and a new
 * connection waits while a hung-up client still holds a slot). */
static int take_requests(struct nc__emu *e)
{
    for (int i = 0; i < e->max_clients; i++)
        e->clients[i].moved = e->clients[i].gone;
    int any = 1;
    for (int pass = 0; any && pass < 256; pass++) {
        any = 0;
        for (int k = 0, first = e->next_client; k < e->max_clients; k++) {
            const int i = (first + k) % e->max_clients;
            struct nc__client *c = &e->clients[i];
            if (c->fd < 0)
                continue;
            const size_t had = c->have;
            const uint32_t skip = c->skip;
            if (c->moved && c->have < sizeof c->buf)
                client_read(e, i);
            const int taken = client_take(e, i);
            if (taken > 0)
                e->next_client = (i + 1) % e->max_clients;
            c->moved = taken > 0 || (c->fd >= 0 && (c->have != had || c->skip != skip));
            any |= c->moved;
        }
    }
    for (int i = 0; i < e->max_clients; i++)
        if (e->clients[i].fd >= 0 && e->clients[i].gone && !e->clients[i].moved)
            close_client(e, i);
    return any;
}

static void read_datagrams(struct nc__emu *e)
{
    uint8_t dgram[NC_PROTO_MAX_BYTES + 64];
    for (;;) { /* drain every datagram; MSG_TRUNC reports a datagram's real size */
        ssize_t got = recv(e->udp_fd, dgram, sizeof dgram, MSG_TRUNC);
        if (got < 0)
            break;
        if ((size_t)got > sizeof dgram) {
            atomic_fetch_add(&e->received, 1);
            log_reject(e, NC_REJECT_OVERSIZED, "UDP");
            continue;
        }
        handle_message(e, dgram, (size_t)got, -1, 0, "UDP");
    }
}

/* A connection beyond serve.max_clients is told why (a FRAME with status
 * REFUSED, its frame field the limit) and closed. */
static void refuse(struct nc__emu *e, int fd)
{
    struct nc_pose_msg m = {.type = NC_MSG_FRAME, .frame = (uint64_t)e->max_clients, .status = NC_FRAME_REFUSED};
    uint8_t buf[4 + NC_PROTO_MAX_BYTES];
    size_t n = nc__serve_encode_tcp(&m, buf);
    (void)!send(fd, buf, 4 + n, MSG_NOSIGNAL | MSG_DONTWAIT);
    close(fd);
    pthread_mutex_lock(&e->client_lock);
    unsigned long refused = ++e->refused_clients;
    pthread_mutex_unlock(&e->client_lock);
    int64_t now = nc_mono_ns();
    if (now - e->last_refuse_log_ns > 1000000000) { /* at most one line a second */
        e->last_refuse_log_ns = now;
        nc_log_warn("emulator/net", "refused a TCP client: all %d client slots are in use (serve.max_clients); "
                    "%lu refused so far", e->max_clients, refused);
    }
}

static void accept_client(struct nc__emu *e, int more)
{
    int slot = -1, gone = 0;
    for (int i = 0; i < e->max_clients; i++) {
        if (e->clients[i].fd < 0 && slot < 0)
            slot = i;
        gone |= e->clients[i].fd >= 0 && e->clients[i].gone;
    }
    if (slot < 0 && gone && more)
        return; /* a hung-up client's last turns free its slot in a round or two: the connection waits */
    int fd = accept4(e->tcp_fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0)
        return;
    if (slot < 0) {
        refuse(e, fd);
        return;
    }
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one); /* answers go out as they are made */
    pthread_mutex_lock(&e->client_lock);
    e->clients[slot].fd = fd;
    e->clients[slot].have = 0;
    e->clients[slot].skip = 0;
    e->clients[slot].out_len = 0;
    e->clients[slot].gone = 0;
    pthread_mutex_unlock(&e->client_lock);
}

void *nc__serve_net_thread(void *arg)
{
    struct nc__emu *e = arg;
    struct pollfd *pf = malloc((size_t)(2 + e->max_clients) * sizeof *pf);
    int *map = malloc((size_t)(2 + e->max_clients) * sizeof *map);
    if (!pf || !map) {
        nc_log_error("emulator/net", "out of memory");
        free(pf);
        free(map);
        atomic_store(&e->failed, -ENOMEM);
        atomic_store(&e->stop, 1);
        return NULL;
    }
    int more = 0; /* turns were left in the last round (take_requests) */
    while (atomic_load(&e->stop) == 0) {
        /* Lock-step with a full job queue: requests wait in the clients'
         * buffers, and when those are full in the sockets (the simulator's
         * sends block), until the render takes a job; every client's next
         * request is read meanwhile, so that each is there for its turn. */
        int held = e->mode == NC__MODE_LOCKSTEP && nc__serve_queue_full(e);
        int n = 0;
        if (e->udp_fd >= 0)
            pf[n] = (struct pollfd){e->udp_fd, POLLIN, 0}, map[n++] = -1;
        if (e->tcp_fd >= 0)
            pf[n] = (struct pollfd){e->tcp_fd, POLLIN, 0}, map[n++] = -2;
        pthread_mutex_lock(&e->client_lock);
        for (int i = 0; i < e->max_clients; i++) {
            /* a client with a full buffer is polled for its hang-up alone (POLLRDHUP: the peer closed, with
             * data unread or not), which closes it this round */
            const struct nc__client *c = &e->clients[i];
            const short ev = (short)((c->have < sizeof c->buf ? POLLIN : 0) | POLLRDHUP | (c->out_len ? POLLOUT : 0));
            if (c->fd >= 0)
                pf[n] = (struct pollfd){c->fd, ev, 0}, map[n++] = i;
        }
        pthread_mutex_unlock(&e->client_lock);
        int incoming = 0;
        if (poll(pf, (nfds_t)n, more ? 0 : held ? 2 : 50) > 0) {
            for (int k = 0; k < n; k++) {
                if (!pf[k].revents)
                    continue;
                if (map[k] == -1) {
                    read_datagrams(e);
                } else if (map[k] == -2) {
                    incoming = 1;
                } else {
                    if (pf[k].revents & POLLOUT) {
                        pthread_mutex_lock(&e->client_lock);
                        nc__serve_flush_client(e, &e->clients[map[k]]);
                        pthread_mutex_unlock(&e->client_lock);
                    }
                    if (pf[k].revents & POLLIN)
                        client_read(e, map[k]);
                    if (pf[k].revents & (POLLRDHUP | POLLHUP | POLLERR))
                        e->clients[map[k]].gone = 1;
                }
            }
        }
        more = take_requests(e);
        /* New connections after the round's hang-ups are closed: a client
         * that closes and at once connects again finds its old slot free
         * (it was refused with max_clients taken). */
        if (incoming)
            accept_client(e, more);
    }
    free(pf);
    free(map);
    return NULL;
}

void nc__serve_answer_unread(struct nc__emu *e)
{
    for (int i = 0; i < e->max_clients; i++) {
        struct nc__client *c = &e->clients[i];
        while (c->fd >= 0) {
            while (!(c->skip && skip_refused(c)) && c->have >= 4) {
                uint32_t len = (uint32_t)c->buf[0] | (uint32_t)c->buf[1] << 8 | (uint32_t)c->buf[2] << 16 |
                               (uint32_t)c->buf[3] << 24;
                if ((len > NC_PROTO_MAX_BYTES || len < NC_PROTO_HEADER_BYTES + 4) && len <= SKIP_MAX_BYTES) {
                    bad_length(e, len); /* refused, passed over (client_take) */
                    c->skip = 4 + len;
                    continue;
                }
                if (len > NC_PROTO_MAX_BYTES || c->have < 4 + len)
                    break;
                /* counted as handle_message counts it; a capture is answered in its turn: dropped at
                 * shutdown, or refused for its value (the render, which would answer that in
                 * lock-step, has stopped) */
                struct nc_pose_msg m;
                int answer;
                const enum nc_reject r = take_message(e, c->buf + 4, len, "a TCP client", &m, &answer);
                if (answer) {
                    struct nc__job j = {.trigger_sim_ns = m.sim_time_ns, .sequence = m.sequence, .client = i,
                                        .client_gen = c->gen};
                    nc__serve_drop(e, &j, r != NC_REJECT_NONE ? NC__DROP_REJECTED : NC__DROP_SHUTDOWN);
                }
                memmove(c->buf, c->buf + 4 + len, c->have - 4 - len);
                c->have -= 4 + len;
            }
            if (c->have == sizeof c->buf)
                break; /* an oversized request: nothing more to make of this stream */
            ssize_t n = read(c->fd, c->buf + c->have, sizeof c->buf - c->have);
            if (n <= 0)
                break; /* EAGAIN: all that was sent is answered */
            c->have += (size_t)n;
        }
    }
}
