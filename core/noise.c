/* noise.c - gradient noise (noise.h). */
#include "core/noise.h"

#include <math.h>

#include "core/rng.h"

/* The hashed gradient of lattice point (x, y, z). */
static const signed char *gradient(uint64_t seed, int64_t x, int64_t y, int64_t z)
{
    static const signed char g[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                         {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
    return g[nc_rng_seed(seed ^ (uint64_t)x * 0x9e3779b97f4a7c15ull, (uint64_t)y, (uint64_t)z) % 12];
}

static double corner(uint64_t seed, int64_t x, int64_t y, int64_t z, double fx, double fy, double fz)
{
    const signed char *q = gradient(seed, x, y, z);
    return q[0] * fx + q[1] * fy + q[2] * fz;
}

static double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
static double fade_d(double t) { return 30 * t * t * (t - 1) * (t - 1); }

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

double nc_noise3_grad(uint64_t seed, double x, double y, double z, double g[3])
{
    const double fl[3] = {floor(x), floor(y), floor(z)};
    const int64_t L[3] = {(int64_t)fl[0], (int64_t)fl[1], (int64_t)fl[2]};
    const double f[3] = {x - fl[0], y - fl[1], z - fl[2]};
    /* s: the fade along each axis, ds its derivative, w[a][i] the weight
     * of corner side i along axis a */
    double s[3], ds[3], w[3][2], c[2][2][2];
    for (int a = 0; a < 3; a++)
        s[a] = fade(f[a]), ds[a] = fade_d(f[a]), w[a][0] = 1 - s[a], w[a][1] = s[a];
    g[0] = g[1] = g[2] = 0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++) {
                const signed char *q = gradient(seed, L[0] + i, L[1] + j, L[2] + k);
                c[i][j][k] = q[0] * (f[0] - i) + q[1] * (f[1] - j) + q[2] * (f[2] - k);
                const double W = w[0][i] * w[1][j] * w[2][k];
                g[0] += W * q[0], g[1] += W * q[1], g[2] += W * q[2];
            }
    /* the fades' share: each axis's difference across the cell, weighted
     * along the other two */
    for (int j = 0; j < 2; j++)
        for (int k = 0; k < 2; k++) {
            g[0] += ds[0] * w[1][j] * w[2][k] * (c[1][j][k] - c[0][j][k]);
            g[1] += ds[1] * w[0][j] * w[2][k] * (c[j][1][k] - c[j][0][k]);
            g[2] += ds[2] * w[0][j] * w[1][k] * (c[j][k][1] - c[j][k][0]);
        }
    /* the value, in nc_noise3's order of operations (the same bits) */
    double a[2][2];
    for (int j = 0; j < 2; j++)
        for (int k = 0; k < 2; k++)
            a[j][k] = c[0][j][k] + s[0] * (c[1][j][k] - c[0][j][k]);
    double b0 = a[0][0] + s[1] * (a[1][0] - a[0][0]), b1 = a[0][1] + s[1] * (a[1][1] - a[0][1]);
    return b0 + s[2] * (b1 - b0);
}
