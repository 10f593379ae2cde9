/* test_clock.c - a frame period as the fraction interfaces take
 * (nc_period_fraction, core/clock.h): whole rates keep 1000 as numerator,
 * others get as many more digits as they need, and every fraction is
 * within 5e-7 of 1 / hz over the range V4L2 outputs take. */
#include <math.h>
#include <stdio.h>

#include "core/clock.h"
#include "testutil.h"

static void expect(double hz, uint32_t num, uint32_t den)
{
    uint32_t n, d;
    nc_period_fraction(hz, &n, &d);
    CHECK(n == num && d == den, "%g Hz: %u/%u s, want %u/%u", hz, n, d, num, den);
}

int main(void)
{
    expect(10, 1000, 10000);
    expect(30, 1000, 30000);
    expect(0.001, 1000, 1);
    expect(1000, 1000, 1000000);
    expect(0.0015, 10000, 15); /* 1000/2 s, 33 % off, until session 67 */
    expect(0.3333333, 10000000, 3333333);
    expect(0.0011234567, 1000000000, 1123457);
    expect(12.5, 1000, 12500);
    double worst = 0;
    for (double hz = 1e-3; hz <= 1e3; hz *= 1.0137) {
        uint32_t n, d;
        nc_period_fraction(hz, &n, &d);
        worst = fmax(worst, fabs((double)n / d * hz - 1));
    }
    printf("periods from 1e-3 to 1e3 Hz: within %.2g of 1 / hz\n", worst);
    CHECK(worst < 5e-7, "worst %g", worst);
    return nc_test_end();
}
