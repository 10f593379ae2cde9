/* bench_accuracy.c - the scenes and methods of `navcam bench accuracy`, and
 * the error of each method's frame against a converged reference. */
#include "app/bench_accuracy.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "camera/load.h"
#include "camera/quality.h"
#include "core/error.h"
#include "render/image_io.h"
#include "render/render.h"

/* "@/" in a set stands for the shapes directory, "@crater" for the crater's
 * height image (written by the bench into its work directory). */
const struct nc_bench_scene nc_bench_scenes[] = {
    {"sphere", "a Hapke sphere of 250 m (comet_67p parameters) at 40 deg phase",
     {"bodies.0.shape={type: sphere, radius_m: 250}", NULL}, NULL, 0, 0},
    {"bennu", "the Bennu shape model (12 288 facets, flat) at 40 deg phase from 2.5 km",
     {"bodies.0.shape={type: mesh, file: @/bennu_g_12570mm_v014.obj, unit: km}", "camera.position_m=[0, -2500, 0]",
      NULL},
     "bennu_g_12570mm_v014.obj", 0, 0},
    {"rubble", "the default asteroid with Bennu's boulder population, from 1.5 km",
     {"bodies.0.boulders={preset: bennu}", "camera.position_m=[0, -1500, 0]", NULL}, NULL, 1, 1},
    {"crater", "a 120 m bowl crater (Moon parameters) with the Sun 15 deg above the horizon",
     {"bodies.0.shape={type: dem, file: @crater, pixel_m: 1}", "bodies.0.material={preset: moon}",
      "sun.direction=[0.966, 0, 0.259]", "camera.position_m=[0, 0, 650]", "camera.look_at_m=[0, 0, 0]",
      "camera.up=[0, 1, 0]", NULL},
     NULL, 0, 0},
    {"icy", "the default asteroid, icy: Hapke w = 0.97",
     {"bodies.0.material={model: hapke, w: 0.97, b: 0.3, c: 0.3, B_S0: 0.6, h_S: 0.06, theta_bar: 20}", NULL}, NULL,
     1, 0},
    {"comet", "comet 67P (62 908 facets), its neck at 70 deg phase",
     {"bodies.0.shape={type: mesh, file: @/67p_lowres_rescaled.obj, unit: km, scale: 2.71}",
      "camera.position_m=[0, 0, 30000]", "camera.look_at_m=[0, 0, 0]", "camera.up=[0, 1, 0]",
      "sun.direction=[0.94, 0, 0.342]", NULL},
     "67p_lowres_rescaled.obj", 1, 0},
};
const int nc_bench_nscenes = (int)(sizeof nc_bench_scenes / sizeof nc_bench_scenes[0]);

static void method(struct nc_bench_method *m, int spp, int bounces, int soft, double lod, double rocks)
{
    memset(m, 0, sizeof *m);
    m->spp = spp;
    m->bounces = bounces;
    m->soft = soft;
    m->lod_error_px = lod;
    m->boulder_min_px = rocks;
    int o = snprintf(m->name, sizeof m->name, "%dspp", spp);
    if (bounces)
        o += snprintf(m->name + o, sizeof m->name - (size_t)o, " b%d", bounces);
    if (soft)
        o += snprintf(m->name + o, sizeof m->name - (size_t)o, " soft");
    if (lod > 0)
        o += snprintf(m->name + o, sizeof m->name - (size_t)o, " lod%g", lod);
    if (rocks >= 0)
        snprintf(m->name + o, sizeof m->name - (size_t)o, " rocks%g", rocks);
}

int nc_bench_methods(const struct nc_bench_scene *sc, const struct nc_bench_opts *o, struct nc_bench_method *m, int max)
{
    struct nc_bench_method all[NC_BENCH_METHODS_MAX];
    int n = 0;
    static const int spps[] = {1, 4, 16, 64, 256};
    for (int k = 0; k < 5; k++) {
        if (o->quick && k > 1)
            break;
        method(&all[n++], spps[k], 0, 0, 0, -1);
        method(&all[n++], spps[k], 0, 1, 0, -1);
        method(&all[n++], spps[k], 1, 1, 0, -1);
        if (!o->quick && k >= 2)
            method(&all[n++], spps[k], 3, 1, 0, -1);
    }
    /* the squares between, hard shadows, no bounce: what auto picks from */
    static const int between[] = {9, 25, 36, 49, 81, 100, 144, 196};
    for (int k = 0; k < 8 && !o->quick; k++)
        method(&all[n++], between[k], 0, 0, 0, -1);
    if (!o->quick && sc->has_mesh_lod) {
        method(&all[n++], 16, 1, 1, 1, -1);
        method(&all[n++], 16, 1, 1, 4, -1);
    }
    if (sc->has_rocks) {
        method(&all[n++], 16, 1, 1, 0, 0);
        if (!o->quick) {
            method(&all[n++], 16, 1, 1, 0, 4);
            /* every rock, without the bounce and the penumbrae its error
             * does not need, as samples grow (the cut's bias gone) */
            method(&all[n++], 16, 0, 0, 0, 0);
            method(&all[n++], 64, 0, 0, 0, 0);
            method(&all[n++], 64, 0, 1, 0, 0);
            method(&all[n++], 256, 0, 1, 0, 0);
        }
    }
    method(&all[n], 0, 0, 0, 0, -1);
    snprintf(all[n].name, sizeof all[n].name, "auto");
    all[n++].auto_quality = 1;
    if (n > max)
        n = max;
    memcpy(m, all, (size_t)n * sizeof *m);
    return n;
}

/* ---- loading ----------------------------------------------------------- */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

struct sets {
    char text[24][512];
    const char *p[24];
    int n;
};

static void add(struct sets *s, const char *fmt, const char *a, double x)
{
    if (s->n >= 24)
        return;
    if (a)
        snprintf(s->text[s->n], sizeof s->text[0], fmt, a, x);
    else
        snprintf(s->text[s->n], sizeof s->text[0], fmt, x);
    s->p[s->n] = s->text[s->n];
    s->n++;
}

/* The scene's sets with "@/" and "@crater" replaced, then the bench's size
 * and the method's render settings (ref: the reference's). */
static int load(const struct nc_bench_scene *sc, const struct nc_bench_opts *o, const struct nc_bench_method *m,
                int ref, struct nc_scene *s, struct nc_camsys *cs)
{
    struct sets st = {.n = 0};
    for (int i = 0; sc->sets[i]; i++) {
        const char *at = strchr(sc->sets[i], '@');
        if (!at) {
            add(&st, "%s", sc->sets[i], 0);
            continue;
        }
        int is_crater = !strncmp(at, "@crater", 7);
        char buf[512];
        snprintf(buf, sizeof buf, "%.*s%s%s%s", (int)(at - sc->sets[i]), sc->sets[i],
                 is_crater ? o->work_dir : o->shapes_dir, is_crater ? "/crater_dem.fits" : "",
                 at + (is_crater ? 7 : 1));
        add(&st, "%s", buf, 0);
    }
    add(&st, "camera.width_px=%.0f", NULL, o->size_px);
    add(&st, "camera.height_px=%.0f", NULL, o->size_px);
    add(&st, "camera.pixel_pitch_m=%.17g", NULL, 5.5e-6 * 1024 / o->size_px);
    if (ref) {
        add(&st, "render.samples_per_pixel=%.0f", NULL, o->ref_spp);
        add(&st, "render.bounces=%.0f", NULL, o->ref_bounces);
        add(&st, "render.soft_shadows=true", NULL, 0);
        add(&st, "render.lod_error_px=0", NULL, 0);
        if (sc->has_rocks)
            add(&st, "render.boulder_min_px=0", NULL, 0);
    } else if (m->auto_quality) {
        add(&st, "render.quality=auto", NULL, 0);
    } else {
        add(&st, "render.samples_per_pixel=%.0f", NULL, m->spp);
        add(&st, "render.bounces=%.0f", NULL, m->bounces);
        add(&st, m->soft ? "render.soft_shadows=true" : "render.soft_shadows=false", NULL, 0);
        add(&st, "render.lod_error_px=%.17g", NULL, m->lod_error_px);
        if (m->boulder_min_px >= 0)
            add(&st, "render.boulder_min_px=%.17g", NULL, m->boulder_min_px);
    }
    return nc_setup_load(NULL, st.p, st.n, s, cs);
}

/* The crater: a paraboloid bowl of depth 0.2 D under a rim 0.04 D high,
 * with ejecta falling off as (R/r)^3 outside, 1 m pixels. */
static int write_crater(const char *dir)
{
    enum { N = 301 };
    const double D = 120, R = D / 2, depth = 0.2 * D, rim = 0.04 * D;
    float *h = malloc((size_t)N * N * sizeof *h);
    if (!h)
        return nc_error(-ENOMEM, "out of memory");
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            double r = hypot(x - (N - 1) / 2.0, y - (N - 1) / 2.0);
            h[(size_t)y * N + (size_t)x] = (float)(r < R ? rim - depth * (1 - (r / R) * (r / R)) : rim * pow(R / r, 3));
        }
    char path[4096];
    snprintf(path, sizeof path, "%s/crater_dem.fits", dir);
    int rc = nc_image_write(path, h, N, N, NULL, 0, NULL);
    free(h);
    return rc;
}

/* ---- one frame ----------------------------------------------------------- */

struct shot {
    struct nc_frame f;
    float *e; /* electrons at 1 s, sensor size */
    int sw, sh;
    double time_ms;
    char chosen[96];
    char why[512]; /* auto: nc_quality_describe of its last choice */
};

static int render(const struct nc_bench_scene *sc, const struct nc_bench_opts *o, const struct nc_bench_method *m,
                  int ref, double exposure_s, struct shot *out)
{
    struct nc_scene s;
    struct nc_camsys cs;
    memset(out, 0, sizeof *out);
    int rc = load(sc, o, m, ref, &s, &cs);
    if (rc < 0)
        return rc;
    struct nc_scene drawn = s;
    nc_camsys_render_camera(&cs, &s.camera, &drawn.camera);
    struct nc_renderer r;
    rc = nc_renderer_init(&r, &drawn, o->threads);
    if (rc >= 0)
        rc = nc_frame_alloc(&out->f, drawn.camera.width_px, drawn.camera.height_px);
    /* The reference: one timed frame. A method: one frame to warm up
     * (threads, caches), then timed ones, at least one, up to 5 or half a
     * second; the fastest (other load on a shared machine only slows a
     * frame: the least disturbed one). */
    double t[5];
    int nt = 0;
    struct nc_scene at = drawn; /* auto: the settings it picks, its pilots timed with the frame */
    struct nc_quality_choice qc;
    if (rc >= 0 && !ref && (!m->auto_quality || (rc = nc_quality_auto(&r, &at, &cs, exposure_s, &qc)) >= 0))
        rc = nc_render_frame(&r, &at, &out->f);
    for (double t0 = now_ms(), spent = 0; rc >= 0 && nt < 5 && (nt == 0 || (!ref && spent < 500));
         spent = now_ms() - t0) {
        double a = now_ms();
        at = drawn;
        if (m->auto_quality && !ref)
            rc = nc_quality_auto(&r, &at, &cs, exposure_s, &qc);
        if (rc >= 0)
            rc = nc_render_frame(&r, &at, &out->f);
        t[nt++] = now_ms() - a;
    }
    drawn.render = at.render;
    out->time_ms = nt ? t[0] : 0;
    for (int i = 1; i < nt; i++)
        out->time_ms = fmin(out->time_ms, t[i]);
    const int autod = m->auto_quality && !ref && nt;
    snprintf(out->chosen, sizeof out->chosen, "spp=%d bounces=%d soft=%d%s%s", drawn.render.samples_per_pixel,
             drawn.render.bounces, drawn.render.soft_shadows, autod && qc.all_rocks ? " rocks=all" : "",
             autod && qc.full_mesh ? " lod=off" : "");
    if (autod)
        nc_quality_describe(&qc, 1, out->why, sizeof out->why);
    out->sw = cs.width_px;
    out->sh = cs.height_px;
    if (rc >= 0 && !(out->e = malloc((size_t)cs.width_px * (size_t)cs.height_px * sizeof *out->e)))
        rc = nc_error(-ENOMEM, "out of memory");
    if (rc >= 0)
        rc = nc_camsys_electrons(&cs, out->f.radiance, 1.0, out->e);
    nc_renderer_free(&r);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
    return rc;
}

static void shot_free(struct shot *s)
{
    nc_frame_free(&s->f);
    free(s->e);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* RMS and 95th percentile of v[0..n) (sorted in place). */
static void stats(double *v, size_t n, double *rms, double *p95)
{
    double sq = 0;
    for (size_t i = 0; i < n; i++)
        sq += v[i] * v[i];
    qsort(v, n, sizeof *v, cmp_double);
    *rms = n ? sqrt(sq / (double)n) : 0;
    *p95 = n ? v[(size_t)(0.95 * (double)(n - 1))] : 0;
}

/* The camera's exposure for a scene: the reference's 99th percentile of
 * body electrons at 70 % of the full well; and its DN per electron, full
 * well and read noise. */
struct dn_model {
    double t, dn_per_e, full_well_e, read_e;
};

static void errors(const struct shot *ref, const struct shot *x, const struct dn_model *dm, struct nc_bench_result *res)
{
    size_t n = (size_t)ref->f.width_px * (size_t)ref->f.height_px, ne = (size_t)ref->sw * (size_t)ref->sh, k = 0;
    double *v = malloc((n > ne ? n : ne) * sizeof *v);
    if (!v)
        return;
    /* the body's pixels: hit, and brighter than 1e-3 of the brightest percent */
    for (size_t i = 0; i < n; i++)
        if (ref->f.coverage[i] > 0)
            v[k++] = ref->f.radiance[i];
    qsort(v, k, sizeof *v, cmp_double);
    double floor = k ? 1e-3 * v[(size_t)(0.99 * (double)(k - 1))] : 0;
    k = 0;
    for (size_t i = 0; i < n; i++)
        if (ref->f.coverage[i] > 0 && ref->f.radiance[i] > floor)
            v[k++] = fabs((double)x->f.radiance[i] - ref->f.radiance[i]) / ref->f.radiance[i];
    stats(v, k, &res->rel_rms, &res->rel_p95);
    /* DN, noise-free, clipped at the full well, where either frame has
     * light; and the same pixels' errors over their own camera noise (shot
     * at the reference's electrons, plus read) */
    double *u = malloc((ne ? ne : 1) * sizeof *u);
    if (!u) {
        free(v);
        return;
    }
    k = 0;
    for (size_t i = 0; i < ne; i++) {
        double a = fmin(ref->e[i] * dm->t, dm->full_well_e), b = fmin(x->e[i] * dm->t, dm->full_well_e);
        if (a * dm->dn_per_e >= 1 || b * dm->dn_per_e >= 1) {
            u[k] = fabs(b - a) / sqrt(fmax(a + dm->read_e * dm->read_e, 1.0)); /* 1 e: sky, no read noise */
            v[k++] = fabs(b - a) * dm->dn_per_e;
        }
    }
    stats(v, k, &res->dn_rms, &res->dn_p95);
    stats(u, k, &res->sigma_rms, &res->sigma_p95);
    free(u);
    k = 0;
    for (size_t i = 0; i < ne; i++)
        if (ref->e[i] * dm->t * dm->dn_per_e >= 1)
            v[k++] = ref->e[i] * dm->t;
    qsort(v, k, sizeof *v, cmp_double);
    double e50 = k ? v[k / 2] : 0;
    res->noise_dn = sqrt(e50 + dm->read_e * dm->read_e) * dm->dn_per_e;
    free(v);
}

int nc_bench_run_scene(const struct nc_bench_scene *sc, const struct nc_bench_opts *o,
                       const struct nc_bench_method *m, int n, struct nc_bench_result *res, FILE *log)
{
    int rc = 0;
    if (!strcmp(sc->name, "crater") && (rc = write_crater(o->work_dir)) < 0)
        return rc;
    struct shot ref;
    fprintf(log, "%s: reference (%d samples, %d bounces, soft shadows, full detail)...\n", sc->name, o->ref_spp,
            o->ref_bounces);
    fflush(log);
    if ((rc = render(sc, o, m, 1, 0, &ref)) < 0) {
        shot_free(&ref);
        return rc;
    }
    fprintf(log, "%s: reference took %.0f ms\n", sc->name, ref.time_ms);
    /* the camera model's scale for this scene */
    struct nc_scene s;
    struct nc_camsys cs;
    if ((rc = load(sc, o, m, 1, &s, &cs)) < 0) {
        shot_free(&ref);
        return rc;
    }
    size_t ne = (size_t)ref.sw * (size_t)ref.sh, k = 0;
    double *v = malloc(ne * sizeof *v), p99 = 0;
    for (size_t i = 0; v && i < ne; i++)
        if (ref.e[i] > 0)
            v[k++] = ref.e[i];
    if (v && k) {
        qsort(v, k, sizeof *v, cmp_double);
        p99 = v[(size_t)(0.99 * (double)(k - 1))];
    }
    free(v);
    struct dn_model dm = {p99 > 0 ? 0.7 * cs.sensor.full_well_e / p99 : 1.0, nc_camsys_dn_per_e(&cs),
                          cs.sensor.full_well_e, cs.sensor.read_noise_e};
    nc_camsys_free(&cs);
    nc_scene_free(&s);
    for (int i = 0; i < n && rc >= 0; i++) {
        struct shot x;
        memset(&res[i], 0, sizeof res[i]);
        if ((rc = render(sc, o, &m[i], 0, dm.t, &x)) >= 0) {
            res[i].time_ms = x.time_ms;
            errors(&ref, &x, &dm, &res[i]);
            snprintf(res[i].chosen, sizeof res[i].chosen, "%s", m[i].auto_quality ? x.chosen : "");
            fprintf(log,
                    "%s: %-22s %9.1f ms  rel RMS %.4g p95 %.4g  DN RMS %.4g p95 %.4g (noise %.3g DN)  "
                    "sigma RMS %.3g p95 %.3g\n",
                    sc->name, m[i].name, res[i].time_ms, res[i].rel_rms, res[i].rel_p95, res[i].dn_rms, res[i].dn_p95,
                    res[i].noise_dn, res[i].sigma_rms, res[i].sigma_p95);
            if (x.why[0])
                fprintf(log, "%s: auto: %s\n", sc->name, x.why);
            fflush(log);
        }
        shot_free(&x);
    }
    shot_free(&ref);
    return rc;
}
