/* navcam/client.h - the simulator side of the NavCam pose protocol
 * (docs/protocol.md): connect, send poses and triggers, wait for frames.
 * A small C library with no dependency beyond libc and zlib: against an
 * installed NavCam, `pkg-config --cflags --libs navcam-client`. Hosts are
 * numeric IPv4 addresses (no name lookup). Functions return 0 (or a
 * sequence) on success and a negative error code on failure; the message
 * of the last failure on this thread is nc_client_errmsg(). */
#ifndef NAVCAM_CLIENT_H
#define NAVCAM_CLIENT_H

#include <stdint.h>

#include "navcam/protocol.h"

#ifdef __cplusplus
extern "C" { /* C linkage, for simulators written in C++ */
#endif

struct nc_client;

/* TCP (lock-step: frames are answered) or UDP (fire and forget: a send
 * never fails for want of a listener). Errors are negative errno values:
 * -EINVAL for a host that is not a numeric IPv4 address or a port outside
 * 1..65535, -ECONNREFUSED when nothing listens on a TCP port, ... */
int nc_client_connect(const char *host, int port, int tcp, struct nc_client **out);
/* Send a POSE or TRIGGER message (its sequence is set by the client: one
 * more than the last message sent). Returns the sequence used, or a
 * negative errno: -EINVAL for another type or flags its type does not take
 * (no sequence used), -EPIPE, ... */
long nc_client_send(struct nc_client *c, struct nc_pose_msg *m);
/* The next FRAME answer (TCP), in the order NavCam sent them: the request's
 * sequence, the frame number (UINT64_MAX when dropped) and the status
 * (NC_FRAME_DELIVERED or NC_FRAME_DROPPED) out. For simulators that send
 * several captures before reading: every capture is answered exactly once,
 * in lock-step in request order. timeout_ms: how long to wait, 0 for what
 * has already arrived (no wait), negative for no limit. Returns 0,
 * -ETIMEDOUT, -ECONNREFUSED (NavCam had no client slot for this connection:
 * serve.max_clients), -EOPNOTSUPP on a UDP client, or another negative
 * errno (-ECONNRESET: NavCam closed the connection). */
int nc_client_next_frame(struct nc_client *c, int timeout_ms, uint32_t *sequence, uint64_t *frame, uint32_t *status);
/* Wait (TCP) for the FRAME answer to `sequence`; frame and status out.
 * Answers to other requests that come first are kept, in order, for the
 * calls after it (nc_client_next_frame returns them first; a later
 * nc_client_wait_frame finds its own among them). Returns 0, or -ETIMEDOUT
 * / a negative error as nc_client_next_frame. */
int nc_client_wait_frame(struct nc_client *c, uint32_t sequence, int timeout_ms, uint64_t *frame, uint32_t *status);
void nc_client_close(struct nc_client *c);
/* What the last failing call on this thread said, e.g. "TCP 127.0.0.1:5751:
 * connect: Connection refused". */
const char *nc_client_errmsg(void);

#ifdef __cplusplus
}
#endif

#endif
