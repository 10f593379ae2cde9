/* gige_image.h - a frame as the gige output streams it: the metadata row's
 * block (layout in docs/gige.md) and the image cropped to the region of
 * interest in the pixel format. Internal to the gige driver. */
#ifndef NC_GIGE_IMAGE_H
#define NC_GIGE_IMAGE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "emulator/output.h"

#define PF_MONO8 0x01080001u
#define PF_MONO12 0x01100005u
#define PF_MONO16 0x01100007u
/* Rows of dn (W x H DN of adc_bits) into out (w x h pixels of format pf,
 * 1 or 2 bytes little-endian), from column ox and row oy (ox <= W, oy <= H;
 * what lies outside the sensor is 0); with meta, row 0 is its metadata
 * block and the image starts on row 1. With done, the bytes of out finished
 * so far are stored there (release order) every few rows, for a sender that
 * streams the first rows while the last are packed. */
void nc__gige_image(const uint16_t *dn, int W, int H, int adc_bits, const struct nc_frame_record *meta, uint32_t pf,
                    uint32_t w, uint32_t h, int ox, int oy, uint8_t *out, atomic_size_t *done);

#endif
