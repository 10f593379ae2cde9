/* test_noise.c - gradient noise (core/noise.h): zero at the lattice points,
 * mean zero and RMS NC_NOISE_RMS over uniform points, continuous, a pure
 * function of seed and point; its gradient (nc_noise3_grad) against
 * central differences, with RMS NC_NOISE_GRAD_RMS a component. */
#include <math.h>
#include <stdint.h>

#include "core/noise.h"
#include "testutil.h"

int main(void)
{
    double s = 0, s2 = 0, jump = 0, g2 = 0, gerr = 0;
    int same_value = 1;
    uint64_t x = 12345;
    const long n = 1000000;
    for (long i = 0; i < n; i++) {
        double p[3];
        for (int k = 0; k < 3; k++) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            p[k] = (double)(x >> 11) * 0x1.0p-53 * 1000 - 500;
        }
        double v = nc_noise3(7, p[0], p[1], p[2]);
        s += v, s2 += v * v;
        /* continuity: a step of 1e-6 periods moves it by at most ~1e-5 */
        jump = fmax(jump, fabs(nc_noise3(7, p[0] + 1e-6, p[1], p[2]) - v));
        double g[3];
        same_value &= nc_noise3_grad(7, p[0], p[1], p[2], g) == v;
        g2 += g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (i % 16 == 0) /* central differences, step 1e-5 periods: error ~1e-9 */
            for (int k = 0; k < 3; k++) {
                double a[3] = {p[0], p[1], p[2]}, b[3] = {p[0], p[1], p[2]};
                a[k] += 1e-5, b[k] -= 1e-5;
                double d = (nc_noise3(7, a[0], a[1], a[2]) - nc_noise3(7, b[0], b[1], b[2])) / 2e-5;
                gerr = fmax(gerr, fabs(d - g[k]));
            }
    }
    double mean = s / n, rms = sqrt(s2 / n - mean * mean);
    printf("noise: mean %.5f, RMS %.4f (NC_NOISE_RMS %.2f), largest change over 1e-6 periods %.2g\n", mean, rms,
           NC_NOISE_RMS, jump);
    CHECK(fabs(mean) < 0.002, "mean %g", mean);
    CHECK(fabs(rms / NC_NOISE_RMS - 1) < 0.01, "RMS %g, stated %g", rms, NC_NOISE_RMS);
    CHECK(jump < 1e-5, "a jump of %g", jump);
    double grms = sqrt(g2 / (3.0 * n));
    printf("gradient: RMS %.4f a component (NC_NOISE_GRAD_RMS %.3f), largest difference from central differences "
           "%.2g; the same value bits %d\n", grms, NC_NOISE_GRAD_RMS, gerr, same_value);
    CHECK(same_value, "nc_noise3_grad's value differs from nc_noise3's");
    CHECK(gerr < 1e-6, "the gradient is off central differences by %g", gerr);
    CHECK(fabs(grms / NC_NOISE_GRAD_RMS - 1) < 0.01, "gradient RMS %g, stated %g", grms, NC_NOISE_GRAD_RMS);
    int zero = 1, same = 1, differ = 0;
    for (int i = -3; i <= 3; i++) {
        zero &= nc_noise3(3, i, 2 * i, -i) == 0;
        same &= nc_noise3(3, i + 0.3, 0.7, i * 0.1) == nc_noise3(3, i + 0.3, 0.7, i * 0.1);
        differ += nc_noise3(3, i + 0.3, 0.7, i * 0.1) != nc_noise3(4, i + 0.3, 0.7, i * 0.1);
    }
    CHECK(zero && same && differ >= 5, "lattice zeros %d, repeatable %d, seeds differ at %d of 7 points", zero, same,
          differ);
    return nc_test_end();
}
