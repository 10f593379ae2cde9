/* clock_map.c - a device clock mapped onto CLOCK_MONOTONIC (clock_map.h). */
#include "core/clock_map.h"

#include <math.h>
#include <string.h>

/* The largest rate difference believed: a crystal's +-1000 ppm. */
#define MAX_DRIFT 1e-3
#define SEARCH_STEPS 80

/* The feasible set F of (offset, drift): every exchange i of the k newest
 * says lo_i <= offset + drift x_i <= hi_i, x_i its device time since ref.
 * For a drift d, the offsets allowed are [L(d), H(d)]: L is a maximum of
 * lines (convex), H a minimum (concave), so H - L is concave and F is a
 * convex polygon, searched below by golden sections. */
struct fit {
    const struct nc_clock_map *m;
    int k;
    int64_t ref, base; /* base is subtracted from offsets to keep doubles exact */
};

static const struct nc_clock_sample *nth_newest(const struct nc_clock_map *m, int i)
{
    return &m->s[(m->head - 1 - i + 2 * NC_CLOCK_MAP_SAMPLES) % NC_CLOCK_MAP_SAMPLES];
}

/* The exchange's device time (the middle of its stay on the device). */
static int64_t dev_mid(const struct nc_clock_sample *s) { return s->t2 + (s->t3 - s->t2) / 2; }

static void offsets_at(const struct fit *f, double d, double *lo, double *hi)
{
    *lo = -INFINITY, *hi = INFINITY;
    for (int i = 0; i < f->k; i++) {
        const struct nc_clock_sample *s = nth_newest(f->m, i);
        double trend = d * (double)(dev_mid(s) - f->ref);
        *lo = fmax(*lo, (double)(s->t3 - s->t4 - f->base) - trend);
        *hi = fmin(*hi, (double)(s->t2 - s->t1 - f->base) - trend);
    }
}

enum goal { WIDTH, MIN_LO, MAX_HI };
static double goal_at(const struct fit *f, enum goal g, double d)
{
    double lo, hi;
    offsets_at(f, d, &lo, &hi);
    return g == WIDTH ? hi - lo : g == MIN_LO ? -lo : hi;
}

/* The d in [a, b] maximising a concave goal. */
static double golden_max(const struct fit *f, enum goal g, double a, double b)
{
    const double r = 0.6180339887498949;
    double c = b - r * (b - a), e = a + r * (b - a), gc = goal_at(f, g, c), ge = goal_at(f, g, e);
    for (int i = 0; i < SEARCH_STEPS; i++) {
        if (gc < ge)
            a = c, c = e, gc = ge, e = a + r * (b - a), ge = goal_at(f, g, e);
        else
            b = e, e = c, ge = gc, c = b - r * (b - a), gc = goal_at(f, g, c);
    }
    return 0.5 * (a + b);
}

/* Where the concave width crosses zero between inside (>= 0) and outside. */
static double edge_of(const struct fit *f, double inside, double outside)
{
    if (goal_at(f, WIDTH, outside) >= 0)
        return outside;
    for (int i = 0; i < SEARCH_STEPS; i++) {
        double mid = 0.5 * (inside + outside);
        if (goal_at(f, WIDTH, mid) >= 0)
            inside = mid;
        else
            outside = mid;
    }
    return inside;
}

static void refit(struct nc_clock_map *m)
{
    const struct nc_clock_sample *newest = nth_newest(m, 0);
    struct fit f = {m, m->n, dev_mid(newest), newest->t3 - newest->t4};
    /* The newest exchanges that agree: an older one that does not fit the
     * linear model (a drift that changed) is left out rather than emptying F.
     * One exchange alone is always feasible. */
    double dbest = golden_max(&f, WIDTH, -MAX_DRIFT, MAX_DRIFT);
    if (goal_at(&f, WIDTH, dbest) < 0) {
        int ok = 1, bad = m->n;
        while (bad - ok > 1) {
            f.k = (ok + bad) / 2;
            double d = golden_max(&f, WIDTH, -MAX_DRIFT, MAX_DRIFT);
            if (goal_at(&f, WIDTH, d) >= 0)
                ok = f.k, dbest = d;
            else
                bad = f.k;
        }
        f.k = ok;
        if (ok == 1)
            dbest = 0;
    }
    double dlo = edge_of(&f, dbest, -MAX_DRIFT), dhi = edge_of(&f, dbest, MAX_DRIFT);
    double omin = -goal_at(&f, MIN_LO, golden_max(&f, MIN_LO, dlo, dhi));
    double omax = goal_at(&f, MAX_HI, golden_max(&f, MAX_HI, dlo, dhi));
    m->ref_dev_ns = f.ref;
    m->drift = 0.5 * (dlo + dhi);
    m->drift_half_range = 0.5 * (dhi - dlo);
    m->offset_ns = (double)f.base + 0.5 * (omin + omax);
    m->bound_ns = 0.5 * (omax - omin);
    m->used = f.k;
    m->valid = 1;
}

void nc_clock_map_reset(struct nc_clock_map *m) { memset(m, 0, sizeof *m); }

void nc_clock_map_add(struct nc_clock_map *m, int64_t t1, int64_t t2, int64_t t3, int64_t t4)
{
    if (t4 < t1 || t3 < t2 || t3 - t2 > t4 - t1) {
        m->rejected++;
        return;
    }
    m->s[m->head] = (struct nc_clock_sample){t1, t2, t3, t4};
    m->head = (m->head + 1) % NC_CLOCK_MAP_SAMPLES;
    if (m->n < NC_CLOCK_MAP_SAMPLES)
        m->n++;
    m->added++;
    refit(m);
}

int nc_clock_map_to_host(const struct nc_clock_map *m, int64_t dev_ns, int64_t *host_ns)
{
    if (!m->valid)
        return -1;
    double off = m->offset_ns + m->drift * (double)(dev_ns - m->ref_dev_ns);
    *host_ns = dev_ns - (int64_t)llround(off);
    return 0;
}

int nc_clock_map_to_device(const struct nc_clock_map *m, int64_t host_ns, int64_t *dev_ns)
{
    if (!m->valid)
        return -1;
    /* dev = host + offset + drift (dev - ref): one fixed-point step is exact
     * to drift^2 (1e-8 of the distance from ref at 100 ppm). */
    int64_t guess = host_ns + (int64_t)llround(m->offset_ns);
    double off = m->offset_ns + m->drift * (double)(guess - m->ref_dev_ns);
    *dev_ns = host_ns + (int64_t)llround(off);
    return 0;
}

double nc_clock_map_bound_ns(const struct nc_clock_map *m, int64_t dev_ns)
{
    if (!m->valid)
        return INFINITY;
    return m->bound_ns + m->drift_half_range * fabs((double)(dev_ns - m->ref_dev_ns));
}
