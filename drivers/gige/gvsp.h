/* gvsp.h - the GigE Vision stream protocol (GVSP) sender of the gige output:
 * one image block (leader, payload packets, trailer) sent the moment a
 * frame is ready, from NavCam's own UDP socket on the device's address.
 * Aravis's embedded device (which answers the control protocol) sends
 * frames only when it polls its trigger latch; this sender does not poll.
 * Internal to the gige driver.
 *
 * Packet layout (GigE Vision 1.x, standard IDs, big-endian): an 8-byte
 * header (status 0, block id, packet format 1 leader / 2 trailer / 3
 * payload, 24-bit packet id); the image leader adds payload type 0x0001,
 * a 64-bit timestamp, pixel format, width, height, offsets and paddings;
 * payload packets carry packet_size - 36 bytes each (IP 20 + UDP 8 + GVSP
 * 8 bytes of overhead), the last one the rest; the trailer carries the
 * payload type and the height. */
#ifndef NC_GVSP_H
#define NC_GVSP_H

#include <netinet/in.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

struct nc__gvsp {
    int fd;
    uint16_t block_id; /* of the last block sent; 0 is never used (set to 0 to count from 1 again) */
    uint8_t *packets;  /* room for one batch of packets */
    size_t packets_size;
};

struct nc__gvsp_image {
    uint32_t pixel_format, width, height, offset_x, offset_y;
    uint64_t timestamp_ns;
    const uint8_t *data;
    size_t size; /* width x height x bytes per pixel */
    /* NULL, or the bytes of data written so far: packets are sent as the
     * bytes they carry are ready. */
    const atomic_size_t *ready;
};

/* A UDP socket bound to addr (the device's IPv4 address), any port. */
int nc__gvsp_open(struct nc__gvsp *s, const char *addr);
/* One image block to dest in packets of packet_size bytes (IP and UDP
 * headers included, as GevSCPSPacketSize counts them); the first block of
 * a stream channel (first != 0) has its payload NC_GVSP_FIRST_PAUSE_NS
 * after its leader, the time Aravis takes to size its socket buffer when a
 * leader comes (docs/gige.md, "Packet size and socket buffers"). Returns
 * 0, or a negative errno when the socket refused a packet (the block is
 * then incomplete at the client). */
int nc__gvsp_send(struct nc__gvsp *s, const struct sockaddr_in *dest, uint32_t packet_size,
                  const struct nc__gvsp_image *im, int first);
#define NC_GVSP_FIRST_PAUSE_NS 5000000L
void nc__gvsp_close(struct nc__gvsp *s);

#endif
