/* vmath_sleef.c - vmath.h with SLEEF's 4-wide AVX2 double functions (u10:
 * max error 1 ulp), chosen once at run time when the CPU has AVX2 and FMA;
 * otherwise the C library. Only the code between the target pragmas is
 * compiled for AVX2 and FMA (sleef.h declares its AVX2 functions only
 * there); the check and the libm loops run on any x86-64. */
#include <math.h>
#include <stddef.h>

#include "render/vmath.h"

#pragma GCC push_options
#pragma GCC target("avx2,fma")
#include <immintrin.h>
#include <sleef.h>

/* Full groups of lanes through SLEEF; the tail through a padded group, so a
 * value's result never depends on its position in the array. T is the
 * element type, LANES the vector width, LD/ST its load and store. */
#define NC_VMATH_AVX2(name, T, LANES, LD, ST, sleef_fn, pad)                                                  \
    static void name##_avx2(T *x, size_t n)                                                                    \
    {                                                                                                          \
        size_t i = 0;                                                                                          \
        for (; i + LANES <= n; i += LANES)                                                                     \
            ST(x + i, sleef_fn(LD(x + i)));                                                                    \
        if (i < n) {                                                                                           \
            T t[LANES];                                                                                        \
            for (size_t k = 0; k < LANES; k++)                                                                 \
                t[k] = i + k < n ? x[i + k] : (pad);                                                           \
            ST(t, sleef_fn(LD(t)));                                                                            \
            for (size_t k = 0; i + k < n; k++)                                                                 \
                x[i + k] = t[k];                                                                               \
        }                                                                                                      \
    }
NC_VMATH_AVX2(nc_vexp, double, 4, _mm256_loadu_pd, _mm256_storeu_pd, Sleef_expd4_u10avx2, 0.0)
NC_VMATH_AVX2(nc_vlog, double, 4, _mm256_loadu_pd, _mm256_storeu_pd, Sleef_logd4_u10avx2, 1.0)
NC_VMATH_AVX2(nc_vacos, double, 4, _mm256_loadu_pd, _mm256_storeu_pd, Sleef_acosd4_u10avx2, 0.0)
NC_VMATH_AVX2(nc_vlogf, float, 8, _mm256_loadu_ps, _mm256_storeu_ps, Sleef_logf8_u35avx2, 1.0f)
NC_VMATH_AVX2(nc_vexpf, float, 8, _mm256_loadu_ps, _mm256_storeu_ps, Sleef_expf8_u10avx2, 0.0f)

static void sincospi_avx2(const double *x, double *s, double *c, size_t n)
{
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        Sleef___m256d_2 r = Sleef_sincospid4_u05avx2(_mm256_loadu_pd(x + i));
        _mm256_storeu_pd(s + i, r.x);
        _mm256_storeu_pd(c + i, r.y);
    }
    if (i < n) {
        double t[4] = {0, 0, 0, 0}, ts[4], tc[4];
        for (size_t k = 0; i + k < n; k++)
            t[k] = x[i + k];
        Sleef___m256d_2 r = Sleef_sincospid4_u05avx2(_mm256_loadu_pd(t));
        _mm256_storeu_pd(ts, r.x);
        _mm256_storeu_pd(tc, r.y);
        for (size_t k = 0; i + k < n; k++) {
            s[i + k] = ts[k];
            c[i + k] = tc[k];
        }
    }
}

static void sincospif_avx2(const float *x, float *s, float *c, size_t n)
{
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        Sleef___m256_2 r = Sleef_sincospif8_u35avx2(_mm256_loadu_ps(x + i));
        _mm256_storeu_ps(s + i, r.x);
        _mm256_storeu_ps(c + i, r.y);
    }
    if (i < n) {
        float t[8] = {0}, ts[8], tc[8];
        for (size_t k = 0; i + k < n; k++)
            t[k] = x[i + k];
        Sleef___m256_2 r = Sleef_sincospif8_u35avx2(_mm256_loadu_ps(t));
        _mm256_storeu_ps(ts, r.x);
        _mm256_storeu_ps(tc, r.y);
        for (size_t k = 0; i + k < n; k++) {
            s[i + k] = ts[k];
            c[i + k] = tc[k];
        }
    }
}
#pragma GCC pop_options

static int use_avx2 = -1;

static int avx2(void)
{
    if (use_avx2 < 0) {
        __builtin_cpu_init();
        use_avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    }
    return use_avx2;
}

#define NC_VMATH_DEFINE(name, T, libm_fn)                                                                     \
    void name(T *x, size_t n)                                                                                  \
    {                                                                                                          \
        if (avx2()) {                                                                                          \
            name##_avx2(x, n);                                                                                 \
            return;                                                                                            \
        }                                                                                                      \
        for (size_t i = 0; i < n; i++)                                                                         \
            x[i] = libm_fn(x[i]);                                                                              \
    }
NC_VMATH_DEFINE(nc_vexp, double, exp)
NC_VMATH_DEFINE(nc_vlog, double, log)
NC_VMATH_DEFINE(nc_vacos, double, acos)
NC_VMATH_DEFINE(nc_vlogf, float, logf)
NC_VMATH_DEFINE(nc_vexpf, float, expf)

void nc_vsincospi(const double *x, double *s, double *c, size_t n)
{
    if (avx2()) {
        sincospi_avx2(x, s, c, n);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        s[i] = sin(M_PI * x[i]);
        c[i] = cos(M_PI * x[i]);
    }
}

void nc_vsincospif(const float *x, float *s, float *c, size_t n)
{
    if (avx2()) {
        sincospif_avx2(x, s, c, n);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        s[i] = sinf((float)M_PI * x[i]);
        c[i] = cosf((float)M_PI * x[i]);
    }
}

const char *nc_vmath_impl(void) { return avx2() ? "SLEEF AVX2 (u10)" : "libm"; }
