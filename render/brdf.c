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
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "material.h"

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
    {"w", NAN, 0.0, 1.0, "1", "single-scattering albedo"},
};

static void ls_eval(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r)
{
    for (size_t i = 0; i < n; i++)
        r[i] = scaled(p[0], geo[i].albedo_factor, 1.0) * (0.25 * INV_PI) * geo[i].mu0 / (geo[i].mu0 + geo[i].mu);
}

const struct nc_brdf_model nc_brdf_lommel_seeliger = {
    .name = "lommel_seeliger",
    .description = "Lommel-Seeliger single scattering: r = w/(4 pi) mu0/(mu0 + mu)",
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
    for (size_t i = 0; i < n; i++) {
        double cg = geo[i].cos_g < -1 ? -1 : geo[i].cos_g > 1 ? 1 : geo[i].cos_g;
        double g = acos(cg) * (180.0 / M_PI);
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
enum { CK, CCHI, CTAN, CCOT, CCOT2, CR0, CSQRT1MW, NC_HAPKE_DERIVED };

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
    c[CCOT2] = c[CCOT] * c[CCOT];
    c[CSQRT1MW] = sqrt(1.0 - p[HW]);
    c[CR0] = (1.0 - c[CSQRT1MW]) / (1.0 + c[CSQRT1MW]); /* eq. 17 */
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
 * 8.56; seed eq. 16). H(0) = 1 is the limit of x ln((1+x)/x) -> 0. */
static inline double hapke_H(double x, double w, double r0)
{
    if (!(x > 0))
        return 1.0;
    return 1.0 / (1.0 - w * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * log((1.0 + x) / x)));
}

/* Double Henyey-Greenstein, seed eq. 12: (1+c)/2 backward lobe peaks at g = 0.
 * At b = 1 a lobe is a delta at g = 0 or 180 deg; its value off the peak is 0
 * and at the peak (0/0 here) is taken as 0 too: a set of measure zero. */
static inline double hapke_p(double b, double c, double cos_g)
{
    if (b == 0)
        return 1.0;
    double k = 1.0 - b * b, back = 1.0 - 2.0 * b * cos_g + b * b, fwd = 1.0 + 2.0 * b * cos_g + b * b;
    double lb = back > 0 ? k / (back * sqrt(back)) : 0.0, lf = fwd > 0 ? k / (fwd * sqrt(fwd)) : 0.0;
    return 0.5 * (1.0 + c) * lb + 0.5 * (1.0 - c) * lf;
}

/* Coherent backscatter, seed eq. 18, with x = tan(g/2)/h_C: B_C(0) = 1 is the
 * limit of (1 - e^-x)/x -> 1; at g = 180 deg x is huge and B_C -> 0. */
static inline double hapke_BC(double x)
{
    double q = x > 1e-8 ? -expm1(-x) / x : 1.0 - 0.5 * x;
    return (1.0 + q) / (2.0 * (1.0 + x) * (1.0 + x));
}

static void hapke_eval(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r)
{
    const double K = c[CK], chi = c[CCHI], tanb = c[CTAN], cotb = c[CCOT], cotb2 = c[CCOT2];
    const int rough = p[HTHETA] > 0;
    for (size_t k = 0; k < n; k++) {
        const double mu0 = geo[k].mu0, mu = geo[k].mu;
        const double cg = geo[k].cos_g < -1 ? -1 : geo[k].cos_g > 1 ? 1 : geo[k].cos_g;
        double w = p[HW], r0 = c[CR0];
        if (geo[k].albedo_factor != 1.0) {
            w = scaled(w, geo[k].albedo_factor, 1.0);
            double s = sqrt(1.0 - w);
            r0 = (1.0 - s) / (1.0 + s);
        }
        /* tan(g/2) from cos g; infinite at g = 180 deg, where B_S, B_C -> 0. */
        const double tg2 = sqrt((1.0 - cg) / (1.0 + cg));

        double mu0e = mu0, mue = mu, S = 1.0;
        if (rough) {
            /* Hapke 1984 / 2012 shadowing, seed eqs. 19-29. */
            const double si = sqrt(fmax(0.0, 1.0 - mu0 * mu0)), se = sqrt(fmax(0.0, 1.0 - mu * mu));
            /* psi from the law of cosines (eq. 30), psi = 0 on the backscatter
             * side; undefined at i = 0 or e = 0, where every psi gives the
             * same S, so take psi = 0 there instead of dividing by zero. */
            double cpsi = 1.0;
            if (si * se > 1e-300)
                cpsi = (cg - mu0 * mu) / (si * se);
            cpsi = cpsi < -1 ? -1 : cpsi > 1 ? 1 : cpsi;
            const double psi = acos(cpsi);
            const double s2 = 0.5 * (1.0 - cpsi);                  /* sin^2(psi/2) */
            const double f = exp(-2.0 * sqrt((1.0 - cpsi) / (1.0 + cpsi))); /* eq. 29; 0 at psi = 180 deg */
            /* cot of i and e; infinite at normal incidence/emission, where
             * E1 = E2 = 0 (eqs. 27-28). */
            const double coti = si > 0 ? mu0 / si : INFINITY, cote = se > 0 ? mu / se : INFINITY;
            const double E1i = exp(-2.0 * INV_PI * cotb * coti), E1e = exp(-2.0 * INV_PI * cotb * cote);
            const double E2i = exp(-INV_PI * cotb2 * coti * coti), E2e = exp(-INV_PI * cotb2 * cote * cote);
            const double etai = chi * (mu0 + si * tanb * E2i / (2.0 - E1i)); /* eq. 26 */
            const double etae = chi * (mu + se * tanb * E2e / (2.0 - E1e));
            const double q = psi * INV_PI;
            if (mu0 >= mu) { /* i <= e: eqs. 19-21 */
                double den = 2.0 - E1e - q * E1i;
                /* den -> 0 only as i, e -> 90 deg with psi -> 180 deg, where the
                 * roughness terms vanish with mu0 and mu. */
                double a = den > 1e-12 ? 1.0 / den : 0.0;
                mu0e = chi * (mu0 + si * tanb * (cpsi * E2e + s2 * E2i) * a);
                mue = chi * (mu + se * tanb * (E2e - s2 * E2i) * a);
                S = (mue / etae) * (mu0 / etai) * chi / (1.0 - f + f * chi * (mu0 / etai));
            } else { /* e <= i: eqs. 22-24 */
                double den = 2.0 - E1i - q * E1e;
                double a = den > 1e-12 ? 1.0 / den : 0.0;
                mu0e = chi * (mu0 + si * tanb * (E2i - s2 * E2e) * a);
                mue = chi * (mu + se * tanb * (cpsi * E2i + s2 * E2e) * a);
                S = (mue / etae) * (mu0 / etai) * chi / (1.0 - f + f * chi * (mu / etae));
            }
            /* The effective cosines can dip below 0 at grazing geometries. */
            mu0e = mu0e > 0 ? mu0e : 0.0;
            mue = mue > 0 ? mue : 0.0;
            S = S > 0 ? S : 0.0;
        }
        const double sum = mu0e + mue;
        if (!(sum > 0)) {
            r[k] = 0.0;
            continue;
        }
        const double Bs = p[HBS0] > 0 ? p[HBS0] / (1.0 + tg2 / p[HHS]) : 0.0;  /* eq. 13 */
        const double Bc = p[HBC0] > 0 ? p[HBC0] * hapke_BC(tg2 / p[HHC]) : 0.0; /* eq. 18 */
        const double M = hapke_H(mu0e / K, w, r0) * hapke_H(mue / K, w, r0) - 1.0; /* eq. 14 */
        /* Hapke 2012 eq. 12.55 (IMSA): K both multiplies and divides the H arguments. */
        r[k] = K * w * (0.25 * INV_PI) * (mu0e / sum) * (hapke_p(p[HB], p[HC], cg) * (1.0 + Bs) + M) * (1.0 + Bc) * S;
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
