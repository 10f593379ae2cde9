/* noise.c - gradient noise (noise.h). */
#include "core/noise.h"

#include <math.h>

#include "core/rng.h"

static double corner(uint64_t seed, int64_t x, int64_t y, int64_t z, double fx, double fy, double fz)
{
    static const signed char g[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                         {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
    uint64_t h = nc_rng_seed(seed ^ (uint64_t)x * 0x9e3779b97f4a7c15ull, (uint64_t)y, (uint64_t)z);
    const signed char *q = g[h % 12];
    return q[0] * fx + q[1] * fy + q[2] * fz;
}

static double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

double nc_noise3(uint64_t seed, double x, double y, double z)
{
    double fx = floor(x), fy = floor(y), fz = floor(z);
    int64_t X = (int64_t)fx, Y = (int64_t)fy, Z = (int64_t)fz;
    x -= fx, y -= fy, z -= fz;
    double u = fade(x), v = fade(y), w = fade(z), c[2][2][2];
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++)
                c[i][j][k] = corner(seed, X + i, Y + j, Z + k, x - i, y - j, z - k);
    double a[2][2];
    for (int j = 0; j < 2; j++)
        for (int k = 0; k < 2; k++)
            a[j][k] = c[0][j][k] + u * (c[1][j][k] - c[0][j][k]);
    double b0 = a[0][0] + v * (a[1][0] - a[0][0]), b1 = a[0][1] + v * (a[1][1] - a[0][1]);
    return b0 + w * (b1 - b0);
}
