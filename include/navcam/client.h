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

struct nc_client;

/* TCP (lock-step: frames are answered) or UDP (fire and forget). */
int nc_client_connect(const char *host, int port, int tcp, struct nc_client **out);
/* Send a POSE or TRIGGER message (its sequence is set by the client). Returns
 * the sequence used, or a negative error. */
long nc_client_send(struct nc_client *c, struct nc_pose_msg *m);
/* The next FRAME answer (TCP), in the order NavCam sent them: the request's
 * sequence, the frame number and the status (NC_FRAME_DELIVERED or
 * NC_FRAME_DROPPED) out. For simulators that send several captures before
 * reading: in lock-step every capture is answered exactly once, in request
 * order. Returns 0, -ETIMEDOUT, -ECONNREFUSED (NavCam had no client slot
 * for this connection: serve.max_clients), or another negative error. */
int nc_client_next_frame(struct nc_client *c, int timeout_ms, uint32_t *sequence, uint64_t *frame, uint32_t *status);
/* Wait (TCP) for the FRAME answer to `sequence`, passing over answers to
 * other requests; frame and status out. Returns 0, or -ETIMEDOUT / a
 * negative error as nc_client_next_frame. */
int nc_client_wait_frame(struct nc_client *c, uint32_t sequence, int timeout_ms, uint64_t *frame, uint32_t *status);
void nc_client_close(struct nc_client *c);
/* What the last failing call on this thread said, e.g. "connect 127.0.0.1:5751:
 * Connection refused". */
const char *nc_client_errmsg(void);

#endif
