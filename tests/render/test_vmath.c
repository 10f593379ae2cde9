/* test_vmath.c - the batched elementary functions agree with the C library
 * to within 2 ulp over the ranges the models use, give the limits the models
 * rely on (exp(-inf) = 0, log(inf) = inf, acos(+-1)), a value's result
 * does not depend on its position in the batch (full groups vs padded tail),
 * and the AVX-512 functions give the AVX2 ones' results bit for bit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"
#include "render/vmath.h"

static double ulps(double a, double b)
{
    if (a == b)
        return 0;
    return fabs(a - b) / (nextafter(fabs(b), INFINITY) - fabs(b));
}

/* Function f (0 exp, 1 log, 2 acos) over x[0 .. n), in place. */
static void batch(int f, double *x, size_t n)
{
    if (f == 0)
        nc_vexp(x, n);
    else if (f == 1)
        nc_vlog(x, n);
    else
        nc_vacos(x, n);
}

int main(void)
{
    enum { N = 4099 }; /* not a multiple of 4: exercises the padded tail */
    static double x[N], y[N];
    double worst[3] = {0, 0, 0};
    for (int f = 0; f < 3; f++) {
        for (int i = 0; i < N; i++) {
            double u = (i + 0.5) / N;
            x[i] = f == 0 ? -745 + 745 * u : f == 1 ? exp(-30 + 60 * u) : -1 + 2 * u;
            y[i] = x[i];
        }
        batch(f, y, N);
        for (int i = 0; i < N; i++) {
            double want = f == 0 ? exp(x[i]) : f == 1 ? log(x[i]) : acos(x[i]);
            worst[f] = fmax(worst[f], ulps(y[i], want));
        }
        /* The last value again, alone: same result as inside the batch. */
        double one = x[N - 1];
        batch(f, &one, 1);
        CHECK(one == y[N - 1], "function %d: a value's result depends on its batch position", f);
    }
    printf("%s: worst error vs libm: exp %.1f ulp, log %.1f ulp, acos %.1f ulp\n", nc_vmath_impl(), worst[0], worst[1],
           worst[2]);
    CHECK(worst[0] <= 2 && worst[1] <= 2 && worst[2] <= 2, "more than 2 ulp from libm");
    double sp[4] = {-INFINITY, 0.0, -0.0, -1e-300};
    nc_vexp(sp, 4);
    CHECK(sp[0] == 0 && sp[1] == 1 && sp[2] == 1 && sp[3] == 1, "exp special values");
    double sl[3] = {INFINITY, 1.0, 1e308};
    nc_vlog(sl, 3);
    CHECK(sl[0] == INFINITY && sl[1] == 0 && fabs(sl[2] - log(1e308)) < 1e-12, "log special values");
    double sa[3] = {1.0, -1.0, 0.0};
    nc_vacos(sa, 3);
    CHECK(sa[0] == 0 && fabs(sa[1] - M_PI) < 1e-15 && fabs(sa[2] - M_PI / 2) < 1e-15, "acos special values");
    /* AVX-512 against AVX2 (where both run): random arguments over the
     * ranges the models use, the special values and a padded tail. */
    enum { M = (1 << 20) + 5 };
    double *in = malloc(M * sizeof *in), *wide = malloc(M * sizeof *wide), *narrow = malloc(M * sizeof *narrow);
    uint64_t h = 0x9e3779b97f4a7c15ull;
    long differ[3] = {0, 0, 0};
    for (int f = 0; f < 3; f++) {
        for (int i = 0; i < M; i++) {
            h ^= h << 13, h ^= h >> 7, h ^= h << 17;
            const double u = (double)(h >> 11) * 0x1p-53;
            in[i] = f == 0 ? -750 * u * u * u : f == 1 ? exp(-40 + 80 * u) : -1 + 2 * u;
        }
        in[0] = f == 0 ? -INFINITY : f == 1 ? INFINITY : 1.0, in[1] = f == 0 ? 0.0 : f == 1 ? 1.0 : -1.0;
        for (int pass = 0; pass < 2; pass++) {
            double *out = pass ? narrow : wide;
            memcpy(out, in, M * sizeof *out);
            nc__vmath_no_avx512 = pass;
            batch(f, out, M);
        }
        nc__vmath_no_avx512 = 0;
        for (int i = 0; i < M; i++)
            differ[f] += memcmp(&wide[i], &narrow[i], sizeof *wide) != 0;
    }
    printf("%s against the AVX2 functions alone, %d arguments each: exp %ld, log %ld, acos %ld differ\n",
           nc_vmath_impl(), M, differ[0], differ[1], differ[2]);
    CHECK(differ[0] == 0 && differ[1] == 0 && differ[2] == 0, "the AVX-512 and AVX2 functions differ");
    free(in);
    free(wide);
    free(narrow);
    return nc_test_end();
}
