/* vmath.h - elementary functions over arrays, in place, for the batched
 * reflectance models: the hot path of a Hapke render is its exp, log and
 * acos calls. Implemented with SLEEF's AVX2 functions (1-ulp accuracy) where
 * the CPU has AVX2 and FMA (exp, log and acos with their AVX-512 twins,
 * the same bits, where it has AVX-512), else with libm; CMake picks the file
 * (vmath_sleef.c on x86-64 with SLEEF, vmath_libm.c elsewhere). On one
 * machine the choice never changes, so results are reproducible. */
#ifndef NC_VMATH_H
#define NC_VMATH_H

#include <stddef.h>

void nc_vexp(double *x, size_t n);
void nc_vlog(double *x, size_t n);
void nc_vacos(double *x, size_t n);
/* s[i] = sin(pi x[i]), c[i] = cos(pi x[i]). */
void nc_vsincospi(const double *x, double *s, double *c, size_t n);
/* Single precision, for noise generation (SLEEF: 3.5 ulp log and sincospi,
 * 1 ulp exp; 8 lanes). */
void nc_vlogf(float *x, size_t n);
void nc_vexpf(float *x, size_t n);
void nc_vsincospif(const float *x, float *s, float *c, size_t n);
/* Nonzero: the AVX-512 functions stay out where the CPU has them (the
 * AVX2 ones run), for tests that compare the two. */
extern int nc__vmath_no_avx512;
/* Which implementation runs here, for logs and benchmarks. */
const char *nc_vmath_impl(void);

#endif
