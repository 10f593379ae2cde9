/* brdf.c - the reflectance models: Lambert, Lommel-Seeliger, Hapke 2012
 * (IMSA) and McEwen's lunar-Lambert, each one constant struct for the
 * registry in material.c.
 *
 * Conventions are those of shared/notes/reflectance.md (seed paper appendix
 * A): every model returns the bidirectional reflectance r (1/sr), radiance =
 * r J. Models must stay finite at every geometry the caller can pass
 * (0 < mu0 <= 1, 0 < mu <= 1, -1 <= cos g <= 1): each singular point of the
 * formulas is handled where it arises, with the limit value, and documented in
 * docs/reflectance.md. This file must not know about rays or images.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/material.h"
#include "render/vmath.h"

#define INV_PI (1.0 / M_PI)

/* The albedo parameter scaled by the local albedo-map factor, kept in range. */
static inline double scaled(double value, double factor, double max)
{
    double v = value * factor;
    return v < max ? v : max;
}

/* ---- Lambert: r = A mu0 / pi ------------------------------------------- */

static const struct nc_brdf_param lambert_params[] = {
    {"A", NAN, 0.0, 1.0, "1", "Lambert albedo (bihemispherical reflectance)"},
};

static void lambert_eval(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r)
{
    for (size_t i = 0; i < n; i++)
        r[i] = scaled(p[0], geo[i].albedo_factor, 1.0) * INV_PI * geo[i].mu0;
}

const struct nc_brdf_model nc_brdf_lambert = {
    .name = "lambert",
    .description = "Lambertian surface: r = A mu0 / pi",
    .params = lambert_params,
    .nparams = 1,
    .albedo_param = 0,
    .eval = lambert_eval,
};

/* ---- Lommel-Seeliger: r = w/(4 pi) mu0/(mu0 + mu) ------------------------ */

static const struct nc_brdf_param ls_params[] = {
    {"w", NAN, 0.0, 1.0, "1", "the law's albedo factor (a sphere's geometric albedo is w/8; not a single-scattering albedo)"},
};

static void ls_eval(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r)
{
    for (size_t i = 0; i < n; i++)
        r[i] = scaled(p[0], geo[i].albedo_factor, 1.0) * (0.25 * INV_PI) * geo[i].mu0 / (geo[i].mu0 + geo[i].mu);
}

const struct nc_brdf_model nc_brdf_lommel_seeliger = {
    .name = "lommel_seeliger",
    .description = "Lommel-Seeliger: r = w/(4 pi) mu0/(mu0 + mu)",
    .params = ls_params,
    .nparams = 1,
    .albedo_param = 0,
    .eval = ls_eval,
};

/* ---- McEwen lunar-Lambert ---------------------------------------------------
 * I/F = pi r = A [2 L(g) mu0/(mu0 + mu) + (1 - L(g)) mu0], with the limb-
 * darkening weight L(g) = 1 + L1 g + L2 g^2 + L3 g^3 (g in degrees), clamped to
 * [0, 1]. Defaults: McEwen (1996, LPSC XXVII, "A precise lunar photometric
 * function"). A is the normal albedo (I/F at i = e = g = 0); A <= 0.25 keeps
 * the directional-hemispherical albedo <= 1 at every incidence. */
static const struct nc_brdf_param mcewen_params[] = {
    {"A", NAN, 0.0, 0.25, "1", "normal albedo: I/F at i = e = g = 0"},
    {"L1", -0.019, -1.0, 1.0, "1/deg", "linear coefficient of L(g)"},
    {"L2", 2.42e-4, -1.0, 1.0, "1/deg^2", "quadratic coefficient of L(g)"},
    {"L3", -1.46e-6, -1.0, 1.0, "1/deg^3", "cubic coefficient of L(g)"},
};

static void mcewen_eval(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r)
{
    double gv[16];
    for (size_t base = 0; base < n; base += 16) {
        size_t m = n - base < 16 ? n - base : 16;
        for (size_t i = 0; i < m; i++)
            gv[i] = geo[base + i].cos_g < -1 ? -1 : geo[base + i].cos_g > 1 ? 1 : geo[base + i].cos_g;
        nc_vacos(gv, m);
        for (size_t i = 0; i < m; i++)
            r[base + i] = gv[i];
    }
    for (size_t i = 0; i < n; i++) {
        double g = r[i] * (180.0 / M_PI);
        double L = 1.0 + g * (p[1] + g * (p[2] + g * p[3]));
        L = L < 0 ? 0 : L > 1 ? 1 : L;
        double mu0 = geo[i].mu0, mu = geo[i].mu;
        r[i] = scaled(p[0], geo[i].albedo_factor, 0.25) * INV_PI * (2.0 * L * mu0 / (mu0 + mu) + (1.0 - L) * mu0);
    }
}

const struct nc_brdf_model nc_brdf_mcewen = {
    .name = "mcewen",
    .description = "McEwen lunar-Lambert: I/F = A [2 L(g) mu0/(mu0+mu) + (1 - L(g)) mu0]",
    .params = mcewen_params,
    .nparams = 4,
    .albedo_param = 0,
    .eval = mcewen_eval,
};

/* ---- Hapke 2012 with IMSA ---------------------------------------------------- */

enum { HW, HB, HC, HBS0, HHS, HBC0, HHC, HTHETA, HPHI };

static const struct nc_brdf_param hapke_params[] = {
    {"w", NAN, 0.0, 1.0, "1", "single-scattering albedo"},
    {"b", 0.0, 0.0, 1.0, "1", "asymmetry of each Henyey-Greenstein lobe"},
    {"c", 1.0, -1.0, 1.0, "1", "weight of the backward lobe: (1+c)/2 backward, (1-c)/2 forward"},
    {"B_S0", 0.0, 0.0, 10.0, "1", "shadow-hiding opposition amplitude"},
    {"h_S", 0.05, 0.0, 2.0, "1", "shadow-hiding opposition width (> 0 where B_S0 > 0)"},
    {"B_C0", 0.0, 0.0, 10.0, "1", "coherent-backscatter opposition amplitude"},
    {"h_C", 0.05, 0.0, 2.0, "1", "coherent-backscatter opposition width (> 0 where B_C0 > 0)"},
    {"theta_bar", 0.0, 0.0, 60.0, "deg", "mean slope angle of macroscopic roughness"},
    {"phi", 0.0, 0.0, 0.752, "1", "filling factor (1 - porosity)"},
};

/* Derived constants, computed once per parameter set. */
enum { CK, CCHI, CTAN, CCOT, CR0, NC_HAPKE_DERIVED };

static void hapke_prepare(const double *p, double *c)
{
    double phi = p[HPHI];
    if (phi > 0) {
        /* Hapke 2012 eq. 7.45b; K = 1 in the limit phi -> 0. */
        double x = 1.209 * pow(phi, 2.0 / 3.0);
        c[CK] = -log1p(-x) / x;
    } else {
        c[CK] = 1.0;
    }
    double tb = p[HTHETA] * (M_PI / 180.0);
    c[CTAN] = tan(tb);
    c[CCHI] = 1.0 / sqrt(1.0 + M_PI * c[CTAN] * c[CTAN]); /* eq. 25 */
    c[CCOT] = tb > 0 ? 1.0 / c[CTAN] : INFINITY;
    double s = sqrt(1.0 - p[HW]);
    c[CR0] = (1.0 - s) / (1.0 + s); /* eq. 17 */
}

static int hapke_check(const double *p, char *why, size_t len)
{
    if (p[HBS0] > 0 && !(p[HHS] > 0)) {
        snprintf(why, len, "h_S must be > 0 when B_S0 > 0 (got h_S = %g)", p[HHS]);
        return -1;
    }
    if (p[HBC0] > 0 && !(p[HHC] > 0)) {
        snprintf(why, len, "h_C must be > 0 when B_C0 > 0 (got h_C = %g)", p[HHC]);
        return -1;
    }
    return 0;
}

/* Hapke 2002 approximation of Chandrasekhar's H function (= Hapke 2012 eq.
 * 8.56; seed eq. 16), given L = ln((1 + x)/x). H(0) = 1 is the limit of
 * x ln((1+x)/x) -> 0. */
static inline double hapke_H(double x, double w, double r0, double L)
{
    return x > 0 ? 1.0 / (1.0 - w * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * L)) : 1.0;
}

/* Double Henyey-Greenstein, seed eq. 12: (1+c)/2 backward lobe peaks at g = 0.
 * At b = 1 a lobe is a delta at g = 0 or 180 deg; its value off the peak is 0
 * and at the peak (0/0 here) is taken as 0 too: a set of measure zero. */
static inline double hapke_p(double b, double c, double cos_g)
{
    double k = 1.0 - b * b, back = 1.0 - 2.0 * b * cos_g + b * b, fwd = 1.0 + 2.0 * b * cos_g + b * b;
    double lb = back > 0 ? k / (back * sqrt(back)) : 0.0, lf = fwd > 0 ? k / (fwd * sqrt(fwd)) : 0.0;
    return b == 0 ? 1.0 : 0.5 * (1.0 + c) * lb + 0.5 * (1.0 - c) * lf;
}

/* Coherent backscatter, seed eq. 18, with x = tan(g/2)/h_C: B_C(0) = 1 is the
 * limit of (1 - e^-x)/x -> 1; at g = 180 deg x is huge and B_C -> 0. */
static inline double hapke_BC(double x)
{
    double q = x > 1e-8 ? -expm1(-x) / x : 1.0 - 0.5 * x;
    return (1.0 + q) / (2.0 * (1.0 + x) * (1.0 + x));
}

/* Hapke 2012 with IMSA (seed eqs. 7, 11-29; notes/reflectance.md):
 *   r = K w/(4 pi) mu0e/(mu0e + mue) [p(g)(1 + B_S0 B_S) + H(mu0e/K) H(mue/K) - 1]
 *       [1 + B_C0 B_C] S(i, e, psi)
 * The two branches of the shadowing function (i <= e, eqs. 19-21, and e <= i,
 * eqs. 22-24) are the same formulas with the roles of the two directions
 * exchanged. Writing A for the direction nearer the normal (mu_A = max(mu0,
 * mu)) and B for the other, both reduce to
 *   r = K w/(4 pi) mu0 mu_Ae mu_Be chi [...] (1 + B_C0 B_C)
 *       / ((mu_Ae + mu_Be) eta_B (eta_A (1 - f) + f chi mu_A)),
 * one expression without a branch whose BRDF r/mu0 is symmetric in (mu0, mu)
 * by construction: reciprocity holds exactly. (The mu0 of eq. 19, or the mu
 * of eq. 22, is mu_A; the remaining mu0 is r's own.)
 * The work is staged over up to HCHUNK geometries so that the acos, exp and
 * log calls run as vector batches (vmath.h). */
#define HCHUNK 16

/* (1 - cos psi) sA sB = sA sB + muA muB - cos g and (1 + cos psi) sA sB =
 * sA sB - muA muB + cos g, with sY = sqrt(1 - muY^2), in double-double
 * arithmetic: near psi = 0 or 180 deg (and most at grazing angles, where the
 * sines are near 1) the terms cancel to nearly nothing, and the shadowing
 * function's f, sin^2(psi/2) and psi itself go as the square root of what
 * is left, so its absolute error has to be far below a double's rounding
 * (test_stability: 1.2e-6 relative at i = e = 89 deg, psi = 0, in plain
 * double; 3e-11 with this). */
static inline void two_sum(double a, double b, double *s, double *e)
{
    *s = a + b;
    double bb = *s - a;
    *e = (a - (*s - bb)) + (b - bb);
}

static inline void dd_sine(double mu, double *hi, double *lo) /* sqrt(1 - mu^2) */
{
    double p = mu * mu, pe = fma(mu, mu, -p), x, xe;
    two_sum(1.0, -p, &x, &xe);
    xe -= pe;
    double s = sqrt(x);
    *hi = s;
    *lo = s > 0 ? (fma(-s, s, x) + xe) / (2.0 * s) : 0.0;
}

static void one_pm_cos_psi(double muA, double muB, double cg, double *minus, double *plus)
{
    double ah, al, bh, bl;
    dd_sine(muA, &ah, &al);
    dd_sine(muB, &bh, &bl);
    double ph = ah * bh, pl = fma(ah, bh, -ph) + ah * bl + al * bh;
    double mh = muA * muB, ml = fma(muA, muB, -mh);
    double t, te, u, ue;
    two_sum(ph, mh, &t, &te);
    two_sum(t, -cg, &u, &ue);
    *minus = u + (ue + te + pl + ml);
    two_sum(ph, -mh, &t, &te);
    two_sum(t, cg, &u, &ue);
    *plus = u + (ue + te + pl - ml);
}

/* f(x) for the first n entries of each of the rows of x (rows of HCHUNK):
 * one call when the rows are full. */
static void rows(void (*f)(double *, size_t), double *x, int nrows, size_t n)
{
    if (n == HCHUNK) {
        f(x, (size_t)nrows * HCHUNK);
        return;
    }
    for (int i = 0; i < nrows; i++)
        f(x + (size_t)i * HCHUNK, n);
}

/* Each stage's loop is branch-free over the lanes (the rare cases, psi near
 * 0 or 180 deg, are redone after it), so that the compiler vectorises it;
 * nothing is contracted (the AVX2 clone has no FMA, and this file is built
 * without contraction for the AVX-512 one), so every lane's result is the
 * same, bit for bit, as the plain one's (and as the scalar loops' before:
 * 1.4 million evaluations over edge geometries compared). */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) static void
hapke_chunk(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r)
{
    const double K = c[CK], chi = c[CCHI], tanb = c[CTAN], cotb = c[CCOT];
    const int rough = p[HTHETA] > 0;
    double mu0[HCHUNK], mu[HCHUNK], cg[HCHUNK], fa[HCHUNK];
    double muA[HCHUNK], muB[HCHUNK], sA[HCHUNK], sB[HCHUNK], inv[HCHUNK], cpsi[HCHUNK], omcpsi[HCHUNK],
        opcpsi[HCHUNK], q[HCHUNK], aA[HCHUNK], aB[HCHUNK];
    double ex[5 * HCHUNK], lg[2 * HCHUNK], xA[HCHUNK], xB[HCHUNK], S[HCHUNK], Sden[HCHUNK], Bc[HCHUNK];
    int redo[HCHUNK];

    /* Stage 1: geometry, and the arguments of acos and exp. */
    for (size_t k = 0; k < n; k++) {
        mu0[k] = geo[k].mu0;
        mu[k] = geo[k].mu;
        cg[k] = geo[k].cos_g < -1 ? -1 : geo[k].cos_g > 1 ? 1 : geo[k].cos_g;
        fa[k] = geo[k].albedo_factor;
        muA[k] = mu0[k] > mu[k] ? mu0[k] : mu[k];
        muB[k] = mu0[k] > mu[k] ? mu[k] : mu0[k];
    }
    if (rough) {
        for (size_t k = 0; k < n; k++) {
            const double a2 = 1.0 - muA[k] * muA[k], b2 = 1.0 - muB[k] * muB[k];
            sA[k] = sqrt(a2 > 0 ? a2 : 0.0);
            sB[k] = sqrt(b2 > 0 ? b2 : 0.0);
            /* psi from the law of cosines (eq. 30), psi = 0 on the
             * backscatter side, and a = cot(theta_bar) cot(y) for y = A, B.
             * At i = 0 or e = 0 psi is undefined and every psi gives the
             * same S, so take psi = 0 there; cot(0) = infinity makes E1 =
             * E2 = 0. */
            const int both = sA[k] * sB[k] > 1e-300;
            inv[k] = 1.0 / (both ? sA[k] * sB[k] : 1.0);
            const double cp = both ? (cg[k] - muA[k] * muB[k]) * inv[k] : 1.0;
            omcpsi[k] = both ? 1.0 - cp : 0.0;
            opcpsi[k] = both ? 1.0 + cp : 2.0;
            redo[k] = both && (omcpsi[k] < 0.01 || opcpsi[k] < 0.01); /* psi within 8 deg of 0 or 180 */
            cpsi[k] = cp < -1 ? -1 : cp > 1 ? 1 : cp;
            aA[k] = both ? cotb * muA[k] * sB[k] * inv[k] : INFINITY;
            const double aB1 = cotb * muB[k] / (sB[k] > 0 ? sB[k] : 1.0);
            aB[k] = both ? cotb * muB[k] * sA[k] * inv[k] : sB[k] > 0 ? aB1 : INFINITY;
        }
        for (size_t k = 0; k < n; k++) /* cancellation: 1 -+ cos psi in double-double */
            if (redo[k]) {
                one_pm_cos_psi(muA[k], muB[k], cg[k], &omcpsi[k], &opcpsi[k]);
                omcpsi[k] *= inv[k];
                opcpsi[k] *= inv[k];
            }
        for (size_t k = 0; k < n; k++) {
            const double omc = omcpsi[k] < 0 ? 0 : omcpsi[k] > 2 ? 2 : omcpsi[k];
            const double opc = opcpsi[k] < 0 ? 0 : opcpsi[k] > 2 ? 2 : opcpsi[k];
            omcpsi[k] = omc;
            opcpsi[k] = opc;
            q[k] = cpsi[k];
            const double fr = sqrt(omc / (opc > 0 ? opc : 1.0));
            ex[k] = opc > 0 ? -2.0 * fr : -INFINITY;         /* f, eq. 29: 0 at psi = 180 deg */
            ex[HCHUNK + k] = -2.0 * INV_PI * aA[k];          /* E1, eq. 27 */
            ex[2 * HCHUNK + k] = -2.0 * INV_PI * aB[k];
            ex[3 * HCHUNK + k] = -INV_PI * aA[k] * aA[k];    /* E2, eq. 28 */
            ex[4 * HCHUNK + k] = -INV_PI * aB[k] * aB[k];
        }
        nc_vacos(q, n);
        rows(nc_vexp, ex, 5, n);
        /* Near psi = 0 or 180 deg, acos(+-(1 - x)) loses x's low digits:
         * psi from x itself there. */
        for (size_t k = 0; k < n; k++) {
            if (omcpsi[k] < 0.01)
                q[k] = 2.0 * asin(sqrt(0.5 * omcpsi[k]));
            else if (opcpsi[k] < 0.01)
                q[k] = M_PI - 2.0 * asin(sqrt(0.5 * opcpsi[k]));
        }
    }

    /* Stage 2: effective cosines, the shadowing factors, the H arguments. */
    for (size_t k = 0; k < n; k++) {
        double muAe = muA[k], muBe = muB[k];
        S[k] = Sden[k] = 1.0;
        if (rough) { /* the same for every lane: the compiler takes it out of the loop */
            const double f = ex[k], E1A = ex[HCHUNK + k], E1B = ex[2 * HCHUNK + k], E2A = ex[3 * HCHUNK + k],
                         E2B = ex[4 * HCHUNK + k];
            const double s2 = 0.5 * omcpsi[k]; /* sin^2(psi/2) */
            /* eq. 26: eta(y) = chi [cos y + sin y tan(theta_bar) E2/(2 - E1)] */
            const double gA = 2.0 - E1A, gB = 2.0 - E1B, ig = 1.0 / (gA * gB);
            const double etaA = chi * (muA[k] + sA[k] * tanb * E2A * gB * ig);
            const double etaB = chi * (muB[k] + sB[k] * tanb * E2B * gA * ig);
            /* eqs. 20-21 (or 23-24 with the roles exchanged); the divisor
             * vanishes only as both angles reach 90 deg with psi = 180 deg,
             * where the roughness terms vanish with the cosines. */
            const double dd = 2.0 - E1B - q[k] * INV_PI * E1A, id = dd > 1e-12 ? 1.0 / dd : 0.0;
            muAe = chi * (muA[k] + sA[k] * tanb * (cpsi[k] * E2B + s2 * E2A) * id);
            muBe = chi * (muB[k] + sB[k] * tanb * (E2B - s2 * E2A) * id);
            /* The effective cosines can dip below 0 at grazing geometries. */
            muAe = muAe > 0 ? muAe : 0.0;
            muBe = muBe > 0 ? muBe : 0.0;
            S[k] = muAe * muBe * chi;
            Sden[k] = etaB * (etaA * (1.0 - f) + f * chi * muA[k]);
        }
        S[k] /= muAe + muBe; /* with the mu0e/(mu0e + mue) of eq. 7 */
        xA[k] = muAe / K;
        xB[k] = muBe / K;
        lg[k] = xA[k] > 0 ? (1.0 + xA[k]) / xA[k] : 1.0;
        lg[HCHUNK + k] = xB[k] > 0 ? (1.0 + xB[k]) / xB[k] : 1.0;
    }
    rows(nc_vlog, lg, 2, n);

    /* Stage 3: H, the phase function and the opposition effects. */
    double tg2[HCHUNK];
    for (size_t k = 0; k < n; k++)
        tg2[k] = sqrt((1.0 - cg[k]) / (1.0 + cg[k])); /* tan(g/2); infinite at g = 180 deg */
    for (size_t k = 0; k < n; k++) /* eq. 18 (expm1: not vectorised) */
        Bc[k] = p[HBC0] > 0 ? p[HBC0] * hapke_BC(tg2[k] / p[HHC]) : 0.0;
    const double w0 = p[HW], r00 = c[CR0], b = p[HB], cc = p[HC], Bs0 = p[HBS0], hS = p[HHS];
    for (size_t k = 0; k < n; k++) {
        const double w = fa[k] != 1.0 ? scaled(w0, fa[k], 1.0) : w0, sq = sqrt(1.0 - w);
        const double r0 = fa[k] != 1.0 ? (1.0 - sq) / (1.0 + sq) : r00;
        const double Bs = Bs0 > 0 ? Bs0 * hS / (hS + tg2[k]) : 0.0; /* eq. 13 */
        const double M = hapke_H(xA[k], w, r0, lg[k]) * hapke_H(xB[k], w, r0, lg[HCHUNK + k]) - 1.0; /* eq. 14 */
        const double bracket = (hapke_p(b, cc, cg[k]) * (1.0 + Bs) + M) * (1.0 + Bc[k]);
        /* Hapke 2012 eq. 12.55 (IMSA): K both multiplies and divides the H arguments. */
        const double v = K * w * (0.25 * INV_PI) * mu0[k] * bracket * S[k] / Sden[k];
        r[k] = S[k] > 0 && S[k] <= DBL_MAX && Sden[k] > 0 ? v : 0.0;
    }
}

/* A chunk of m geometries that is not a whole number of 8-lane vectors
 * runs padded to one (copies of its first geometry): the stages' loops then
 * have no scalar tails, which cost more than the padded lanes (13
 * geometries took 49 ns each, 16 took 35). Each lane is computed on its own,
 * so the results are the same. */
static void hapke_eval(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r)
{
    for (size_t base = 0; base < n; base += HCHUNK) {
        const size_t m = n - base < HCHUNK ? n - base : HCHUNK, mp = (m + 7) / 8 * 8;
        if (mp == m) {
            hapke_chunk(p, c, m, geo + base, r + base);
            continue;
        }
        struct nc_photometry g[HCHUNK];
        double rp[HCHUNK];
        for (size_t k = 0; k < mp; k++)
            g[k] = geo[base + (k < m ? k : 0)];
        hapke_chunk(p, c, mp, g, rp);
        memcpy(r + base, rp, m * sizeof *r);
    }
}

const struct nc_brdf_model nc_brdf_hapke = {
    .name = "hapke",
    .description = "Hapke 2012 with IMSA: w, b, c, B_S0, h_S, B_C0, h_C, theta_bar (deg), phi",
    .params = hapke_params,
    .nparams = 9,
    .albedo_param = 0,
    .ncderived = NC_HAPKE_DERIVED,
    .prepare = hapke_prepare,
    .check = hapke_check,
    .eval = hapke_eval,
};
