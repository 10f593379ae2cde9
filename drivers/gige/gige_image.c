/* gige_image.c - the streamed image and its metadata row (gige_image.h). */
#include "drivers/gige/gige_image.h"

#include <string.h>

#include "core/le.h"

/* A DN as the pixel format stores it: (dn << left) >> right. */
static void shifts(uint32_t pf, int bits, int *left, int *right)
{
    int keep = pf == PF_MONO8 ? 8 : pf == PF_MONO12 ? 12 : 16;
    *left = pf == PF_MONO12 || bits >= keep ? 0 : keep - bits; /* Mono8, Mono16: most significant bits */
    *right = bits > keep ? bits - keep : 0;
}

/* One row: DNs below 2^adc_bits shifted into the pixel format, in 16-bit
 * lanes (left and right are never both set, so nothing is lost). */
__attribute__((target_clones("avx2", "default")))
static void row16(const uint16_t *restrict src, int n, int left, int right, uint8_t *restrict o)
{
    for (int x = 0; x < n; x++) {
        uint16_t v = (uint16_t)(src[x] << left);
        v = (uint16_t)(v >> right);
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
        memcpy(o + 2 * x, &v, 2); /* one vectorised store */
#else
        nc_le_put_u16(o + 2 * x, v);
#endif
    }
}

__attribute__((target_clones("avx2", "default")))
static void row8(const uint16_t *restrict src, int n, int left, int right, uint8_t *restrict o)
{
    for (int x = 0; x < n; x++) {
        uint16_t v = (uint16_t)(src[x] << left);
        o[x] = (uint8_t)(v >> right);
    }
}

void nc__gige_image(const uint16_t *dn, int W, int H, int adc_bits, const struct nc_frame_record *meta, uint32_t pf,
                    uint32_t w, uint32_t h, int ox, int oy, uint8_t *out, atomic_size_t *done)
{
    const int bpp = pf == PF_MONO8 ? 1 : 2;
    int row0 = 0, left, right;
    shifts(pf, adc_bits, &left, &right);
    if (meta) { /* the metadata row on top */
        nc_frame_metadata_row(meta, out, (size_t)w * bpp);
        row0 = 1;
    }
    for (int y = row0; y < (int)h; y++) {
        int sy = oy + y - row0;
        uint8_t *o = out + (size_t)y * w * bpp;
        if (sy >= H) {
            memset(o, 0, (size_t)w * bpp);
            continue;
        }
        const uint16_t *src = dn + (size_t)sy * W + ox;
        int n = ox + (int)w <= W ? (int)w : W - ox; /* >= 0: ox <= W */
        if (bpp == 1)
            row8(src, n, left, right, o);
        else
            row16(src, n, left, right, o);
        if (n < (int)w)
            memset(o + (size_t)n * bpp, 0, (size_t)((int)w - n) * bpp);
        if (done && y % 16 == 15)
            atomic_store_explicit(done, (size_t)(y + 1) * w * bpp, memory_order_release);
    }
    if (done) /* all, even when the metadata row is the whole image */
        atomic_store_explicit(done, (size_t)h * w * bpp, memory_order_release);
}
