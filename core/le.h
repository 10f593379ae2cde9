/* le.h - little-endian scalars in byte buffers, independent of the host's
 * byte order and of alignment: the wire protocol, the GigE metadata row and
 * the star index use them. */
#ifndef NC_LE_H
#define NC_LE_H

#include <stdint.h>
#include <string.h>

static inline void nc_le_put_u16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8); }
static inline void nc_le_put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}
static inline void nc_le_put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}
static inline uint16_t nc_le_get_u16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }
static inline uint32_t nc_le_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint64_t nc_le_get_u64(const uint8_t *p)
{
    return (uint64_t)nc_le_get_u32(p) | (uint64_t)nc_le_get_u32(p + 4) << 32;
}
static inline void nc_le_put_f32(uint8_t *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    nc_le_put_u32(p, u);
}
static inline float nc_le_get_f32(const uint8_t *p)
{
    uint32_t u = nc_le_get_u32(p);
    float v;
    memcpy(&v, &u, 4);
    return v;
}
static inline void nc_le_put_f64(uint8_t *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    nc_le_put_u64(p, u);
}
static inline double nc_le_get_f64(const uint8_t *p)
{
    uint64_t u = nc_le_get_u64(p);
    double v;
    memcpy(&v, &u, 8);
    return v;
}

#endif
