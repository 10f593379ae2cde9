/* vmath_libm.c - vmath.h with the C library: the portable fallback. */
#include <math.h>

#include "render/vmath.h"

int nc__vmath_no_avx512; /* nothing to keep out here */

void nc_vexp(double *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        x[i] = exp(x[i]);
}

void nc_vlog(double *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        x[i] = log(x[i]);
}

void nc_vacos(double *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        x[i] = acos(x[i]);
}

void nc_vsincospi(const double *x, double *s, double *c, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        s[i] = sin(M_PI * x[i]);
        c[i] = cos(M_PI * x[i]);
    }
}

void nc_vlogf(float *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        x[i] = logf(x[i]);
}

void nc_vexpf(float *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        x[i] = expf(x[i]);
}

void nc_vsincospif(const float *x, float *s, float *c, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        s[i] = sinf((float)M_PI * x[i]);
        c[i] = cosf((float)M_PI * x[i]);
    }
}

const char *nc_vmath_impl(void) { return "libm"; }
