/* vmath_sleef.c - vmath.h with SLEEF's 4-wide AVX2 double functions (u10:
 * max error 1 ulp), chosen once at run time when the CPU has AVX2 and FMA,
 * and their 8-wide AVX-512 twins for exp, log and acos where it has
 * AVX-512 (the same results bit for bit: SLEEF computes every lane alike,
 * and test_vmath compares them); otherwise the C library. Only the
 * functions marked AVX2 or AVX512 are compiled for those extensions; the
 * check and the libm loops run on any x86-64. */
#include <math.h>
#include <stddef.h>

#include "render/vmath.h"

/* The intrinsics first, each with its own target; sleef.h declares each
 * extension's functions only where the compiler may use it: all of them
 * here. Each function below states its own target. */
#include <immintrin.h>
#pragma GCC push_options
#pragma GCC target("avx512f,avx2,fma")
#include <sleef.h>
#pragma GCC pop_options

#define AVX2 __attribute__((target("avx2,fma")))
#define AVX512 __attribute__((target("avx512f,avx2,fma")))

/* Full groups of lanes through SLEEF; the tail through a padded group, so a
 * value's result never depends on its position in the array. T is the
 * element type, LANES the vector width, LD/ST its load and store. */
#define NC_VMATH_BATCH(attr, name, T, LANES, LD, ST, sleef_fn, pad)                                         \
    attr static void name(T *x, size_t n)                                                                      \
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
NC_VMATH_BATCH(AVX2, nc_vexp_avx2, double, 4, _mm256_loadu_pd, _mm256_storeu_pd, Sleef_expd4_u10avx2, 0.0)
NC_VMATH_BATCH(AVX2, nc_vlog_avx2, double, 4, _mm256_loadu_pd, _mm256_storeu_pd, Sleef_logd4_u10avx2, 1.0)
NC_VMATH_BATCH(AVX2, nc_vacos_avx2, double, 4, _mm256_loadu_pd, _mm256_storeu_pd, Sleef_acosd4_u10avx2, 0.0)
NC_VMATH_BATCH(AVX2, nc_vlogf_avx2, float, 8, _mm256_loadu_ps, _mm256_storeu_ps, Sleef_logf8_u35avx2, 1.0f)
NC_VMATH_BATCH(AVX2, nc_vexpf_avx2, float, 8, _mm256_loadu_ps, _mm256_storeu_ps, Sleef_expf8_u10avx2, 0.0f)

AVX2 static void sincospi_avx2(const double *x, double *s, double *c, size_t n)
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

AVX2 static void sincospif_avx2(const float *x, float *s, float *c, size_t n)
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

NC_VMATH_BATCH(AVX512, nc_vexp_avx512, double, 8, _mm512_loadu_pd, _mm512_storeu_pd, Sleef_expd8_u10avx512f, 0.0)
NC_VMATH_BATCH(AVX512, nc_vlog_avx512, double, 8, _mm512_loadu_pd, _mm512_storeu_pd, Sleef_logd8_u10avx512f, 1.0)
NC_VMATH_BATCH(AVX512, nc_vacos_avx512, double, 8, _mm512_loadu_pd, _mm512_storeu_pd, Sleef_acosd8_u10avx512f, 0.0)

static int use_avx2 = -1, use_avx512 = -1;

static int avx2(void)
{
    if (use_avx2 < 0) {
        __builtin_cpu_init();
        use_avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
        use_avx512 = use_avx2 && __builtin_cpu_supports("avx512f");
    }
    return use_avx2;
}

/* wide: the function's AVX-512 twin, or NULL */
#define NC_VMATH_DEFINE(name, T, libm_fn, wide)                                                               \
    void name(T *x, size_t n)                                                                                  \
    {                                                                                                          \
        void (*const z)(T *, size_t) = wide;                                                                   \
        if (avx2() && z && use_avx512 && !nc__vmath_no_avx512) {                                               \
            z(x, n);                                                                                           \
            return;                                                                                            \
        }                                                                                                      \
        if (avx2()) {                                                                                          \
            name##_avx2(x, n);                                                                                 \
            return;                                                                                            \
        }                                                                                                      \
        for (size_t i = 0; i < n; i++)                                                                         \
            x[i] = libm_fn(x[i]);                                                                              \
    }
int nc__vmath_no_avx512;
NC_VMATH_DEFINE(nc_vexp, double, exp, nc_vexp_avx512)
NC_VMATH_DEFINE(nc_vlog, double, log, nc_vlog_avx512)
NC_VMATH_DEFINE(nc_vacos, double, acos, nc_vacos_avx512)
NC_VMATH_DEFINE(nc_vlogf, float, logf, NULL)
NC_VMATH_DEFINE(nc_vexpf, float, expf, NULL)

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

const char *nc_vmath_impl(void)
{
    return !avx2() ? "libm" : use_avx512 && !nc__vmath_no_avx512 ? "SLEEF AVX-512 and AVX2 (u10)" : "SLEEF AVX2 (u10)";
}
