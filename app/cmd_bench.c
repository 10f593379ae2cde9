/* cmd_bench.c - `navcam bench accuracy`: error against time for the methods
 * NavCam offers, on reference scenes, as CSV and a chart (docs/accuracy.md). */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>

#include "app/bench_accuracy.h"
#include "app/cli.h"
#include "core/error.h"
#include "core/fs.h"
#include "core/log.h"

static const char bench_help[] =
    "Usage: navcam bench accuracy [-o DIR] [options]\n"
    "\n"
    "Renders each reference scene converged (the reference), then with each method\n"
    "(samples per pixel, indirect bounces, soft shadows, levels of detail, boulder\n"
    "cut, render.quality: auto), and records per method the render time per frame\n"
    "and the error against the reference: relative radiance over the body's pixels\n"
    "and DN after the scene's camera model (noise-free, exposed so that the\n"
    "reference's 99th percentile sits at 70 % of the full well), RMS and 95th\n"
    "percentile. Writes DIR/accuracy.csv, DIR/accuracy_front.csv (each scene's\n"
    "Pareto front: scene, time_ms, rel_rms), DIR/accuracy.gp and, through gnuplot,\n"
    "DIR/accuracy.png: error against time per scene with its Pareto front.\n"
    "\n"
    "Scenes: sphere (analytic Hapke sphere), bennu (a real shape model), rubble\n"
    "(procedural asteroid with boulders), crater (a bowl crater at low Sun),\n"
    "icy (a bright body), comet (67P's neck). docs/accuracy.md shows the charts.\n"
    "\n"
    "  -o, --output DIR     output directory (default: accuracy; made with its missing parents)\n"
    "      --scene NAME     only this scene; repeatable\n"
    "      --size N         frames of N x N pixels with the default camera's field\n"
    "                       (default 256)\n"
    "      --ref-spp N      the reference's samples per pixel, a square (default 1024)\n"
    "      --ref-bounces N  the reference's bounces (default 6)\n"
    "      --shapes DIR     the shape models (default ../shared/data/shapes); a scene\n"
    "                       whose model is missing is skipped with a note\n"
    "      --quick          fewer methods (what the tests run)\n"
    "  -j, --threads N      render threads, 0 to 1024 (default and 0: all cores)\n"
    "  -h, --help           this help\n"
    "\n"
    "CSV columns: scene, method, spp, bounces, soft_shadows, lod_error_px,\n"
    "boulder_min_px (-1: the scene's default), time_ms, rel_rms, rel_p95, dn_rms,\n"
    "dn_p95, noise_dn (the camera's shot and read noise at the median lit pixel),\n"
    "sigma_rms, sigma_p95 (each pixel's DN error over its own shot and read noise:\n"
    "the error render.quality: auto bounds by auto_noise_fraction), pareto (1: no\n"
    "other method is both faster and closer in rel_rms), pareto_dn (the same in\n"
    "dn_rms), pareto_sigma (in sigma_rms), chosen (what auto picked).\n";

static int parse_int(const char *opt, const char *s, int lo, int hi, int *out)
{
    long v;
    if (nc_cli_long(opt, s, lo, hi, &v) < 0)
        return -1;
    *out = (int)v;
    return 0;
}

/* The errors a front is drawn in: relative radiance RMS, DN RMS after the
 * camera model, and RMS of each pixel's error over its own camera noise
 * (what render.quality: auto bounds by k). */
enum metric { M_REL, M_DN, M_SIGMA, NMETRIC };
static const char *const metric_name[NMETRIC] = {"relative", "DN", "sigma"};
static const char *const metric_err[NMETRIC] = {"rel RMS", "DN RMS", "sigma RMS"};

static double err_of(const struct nc_bench_result *r, int metric)
{
    return metric == M_REL ? r->rel_rms : metric == M_DN ? r->dn_rms : r->sigma_rms;
}

/* Pareto flags over the scene's methods (auto excluded from the front). */
static void pareto(const struct nc_bench_method *m, const struct nc_bench_result *r, int n, int metric, int *flag)
{
    for (int i = 0; i < n; i++) {
        flag[i] = !m[i].auto_quality;
        for (int k = 0; k < n && flag[i]; k++)
            if (k != i && !m[k].auto_quality && r[k].time_ms <= r[i].time_ms &&
                err_of(&r[k], metric) <= err_of(&r[i], metric) &&
                (r[k].time_ms < r[i].time_ms || err_of(&r[k], metric) < err_of(&r[i], metric)))
                flag[i] = 0;
    }
}

/* The flagged methods sorted by time (errors falling); returns how many. */
static int front_of(const struct nc_bench_result *r, int n, const int *flag, int *idx)
{
    int nf = 0;
    for (int i = 0; i < n; i++)
        if (flag[i]) {
            int k = nf++;
            for (; k > 0 && r[idx[k - 1]].time_ms > r[i].time_ms; k--)
                idx[k] = idx[k - 1];
            idx[k] = i;
        }
    return nf;
}

/* auto's time over the front's at auto's error: the front interpolated in
 * log time against log error between the two methods that bracket it, or
 * its cheapest method where that is already closer; -1 where auto is closer
 * than every method of the front. */
static double auto_ratio(const struct nc_bench_method *m, const struct nc_bench_result *r, int n, const int *front,
                         int nf, int metric)
{
    int a = -1;
    for (int i = 0; i < n; i++)
        if (m[i].auto_quality)
            a = i;
    if (a < 0 || nf == 0)
        return -1;
    const double e = err_of(&r[a], metric);
    if (err_of(&r[front[0]], metric) <= e)
        return r[a].time_ms / r[front[0]].time_ms;
    for (int k = 1; k < nf; k++) {
        const struct nc_bench_result *p = &r[front[k - 1]], *q = &r[front[k]];
        if (err_of(q, metric) <= e) {
            double u = log(e / err_of(p, metric)) / log(err_of(q, metric) / err_of(p, metric));
            return r[a].time_ms / exp(log(p->time_ms) + u * log(q->time_ms / p->time_ms));
        }
    }
    return -1;
}

/* One line on auto against a front. */
static void report_auto(const char *scene, const struct nc_bench_result *a, double ratio, int metric)
{
    if (ratio > 0)
        printf("%s: auto (%s) takes %.2f x the %s front's time at its error (%s %.4g)\n", scene, a->chosen, ratio,
               metric_name[metric], metric_err[metric], err_of(a, metric));
    else
        printf("%s: auto (%s) is closer than every method of the %s front (%s %.4g)\n", scene, a->chosen,
               metric_name[metric], metric_err[metric], err_of(a, metric));
}

static void gp_scene(FILE *gp, const char *name, const char *what)
{
    fprintf(gp,
            "set title \"%s: %s\" noenhanced\n"
            "plot 'accuracy.csv' using (strcol(1) eq \"%s\" && strcol(2) ne \"auto\" ? $8 : 1/0):9 with points pt 7 ps 1 "
            "lc rgb '#3070b0' title 'methods', \\\n"
            "  'accuracy_front.csv' using (strcol(1) eq \"%s\" ? $2 : 1/0):3 with linespoints lw 2 pt 6 ps 1.5 lc rgb '#d04020' "
            "title 'Pareto front', \\\n"
            "  'accuracy.csv' using (strcol(1) eq \"%s\" && strcol(2) eq \"auto\" ? $8 : 1/0):9 with points pt 5 ps 2 "
            "lc rgb '#20a040' title 'auto', \\\n"
            "  'accuracy.csv' using (strcol(1) eq \"%s\" ? $8 : 1/0):9:2 with labels left offset 0.6,0.3 font ',7' "
            "noenhanced notitle\n",
            name, what, name, name, name, name);
}

int main(int argc, char **argv)
{
    nc_cli_init("bench");
    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"scene", required_argument, NULL, 'S'},
        {"size", required_argument, NULL, 'z'},   {"ref-spp", required_argument, NULL, 'r'},
        {"ref-bounces", required_argument, NULL, 'b'}, {"shapes", required_argument, NULL, 'd'},
        {"quick", no_argument, NULL, 'Q'},        {"threads", required_argument, NULL, 'j'},
        {"help", no_argument, NULL, 'h'},         {NULL, 0, NULL, 0},
    };
    struct nc_bench_opts o = {.size_px = 256, .ref_spp = 1024, .ref_bounces = 6, .shapes_dir = "../shared/data/shapes"};
    const char *dir = "accuracy", *only[16];
    int nonly = 0, c;
    if (argc < 2 || strcmp(argv[1], "accuracy")) {
        if (argc >= 2 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help"))) {
            fputs(bench_help, stdout);
            return 0;
        }
        fprintf(stderr, "navcam bench: expected a benchmark name: accuracy\nTry 'navcam bench --help'.\n");
        return 2;
    }
    optind = 2;
    while ((c = nc_cli_getopt(argc, argv, "o:j:h", opts)) != -1) {
        int bad = 0;
        switch (c) {
        case 'o': dir = optarg; break;
        case 'S':
            if (nonly < 16)
                only[nonly++] = optarg;
            break;
        case 'z': bad = parse_int("size", optarg, 16, 4096, &o.size_px); break;
        case 'r':
            bad = parse_int("ref-spp", optarg, 1, 1024, &o.ref_spp); /* render.samples_per_pixel's range */
            if (!bad && (int)lround(sqrt(o.ref_spp)) * (int)lround(sqrt(o.ref_spp)) != o.ref_spp) {
                fprintf(stderr, "navcam bench: --ref-spp expects a square number of samples (1, 4, 9, ... 1024), "
                                "got '%s'\n", optarg);
                bad = 1;
            }
            break;
        case 'b': bad = parse_int("ref-bounces", optarg, 0, 64, &o.ref_bounces); break;
        case 'd': o.shapes_dir = optarg; break;
        case 'Q': o.quick = 1; break;
        case 'j': bad = nc_cli_threads(optarg, &o.threads) < 0; break;
        case 'h': fputs(bench_help, stdout); return 0;
        default: fputs("Try 'navcam bench --help'.\n", stderr); return 2;
        }
        if (bad)
            return 2;
    }
    if (optind < argc) {
        fprintf(stderr, "navcam bench: unexpected argument '%s'\n", argv[optind]);
        return 2;
    }
    for (int i = 0; i < nonly; i++) {
        int known = 0;
        for (int k = 0; k < nc_bench_nscenes; k++)
            known |= !strcmp(only[i], nc_bench_scenes[k].name);
        if (!known) {
            fprintf(stderr, "navcam bench: unknown scene '%s' (sphere, bennu, rubble, crater, icy, comet)\n", only[i]);
            return 2;
        }
    }
    if (nc_mkdirs(dir) < 0)
        return nc_cli_fail();
    o.work_dir = dir;
    nc_log_set_level(NC_LOG_WARN); /* not the scene's notes at every load */
    /* Written under temporary names and renamed once every scene is measured: a run that measures nothing or
     * fails leaves an earlier run's results as they were. */
    static const char *const made[] = {"accuracy.csv", "accuracy_front.csv", "accuracy.gp"};
    char path[4096], tmp[3][4200];
    FILE *out[3];
    for (int i = 0; i < 3; i++) {
        snprintf(tmp[i], sizeof tmp[i], "%s/.%s.tmp", dir, made[i]);
        out[i] = fopen(tmp[i], "w");
    }
    FILE *csv = out[0], *front = out[1], *gp = out[2];
    if (!csv || !front || !gp) {
        fprintf(stderr, "navcam bench: cannot write into %s: %s\n", dir, strerror(errno));
        for (int i = 0; i < 3; i++)
            if (out[i])
                fclose(out[i]), unlink(tmp[i]);
        return 1;
    }
    fprintf(csv, "scene,method,spp,bounces,soft_shadows,lod_error_px,boulder_min_px,time_ms,rel_rms,rel_p95,dn_rms,"
                 "dn_p95,noise_dn,sigma_rms,sigma_p95,pareto,pareto_dn,pareto_sigma,chosen\n");
    fprintf(front, "scene,time_ms,rel_rms\n");
    fprintf(gp, "# gnuplot script written by navcam bench accuracy\nset datafile separator ','\n"
                "set terminal pngcairo size 1500,1000 font ',9'\nset output 'accuracy.png'\n"
                "set multiplot layout 2,3 title 'NavCam: error against render time per frame (%dx%d; reference %d "
                "samples, %d bounces, soft shadows, full detail)'\n"
                "set logscale xy\nset xlabel 'render time per frame, ms'\nset ylabel 'relative radiance error, RMS'\n"
                "set key bottom left font ',8'\nset grid\n",
            o.size_px, o.size_px, o.ref_spp, o.ref_bounces);
    int rc = 0, nplots = 0;
    for (int si = 0; si < nc_bench_nscenes && rc >= 0; si++) {
        const struct nc_bench_scene *sc = &nc_bench_scenes[si];
        int wanted = nonly == 0;
        for (int i = 0; i < nonly; i++)
            wanted |= !strcmp(only[i], sc->name);
        if (!wanted)
            continue;
        if (sc->shape_file) {
            snprintf(path, sizeof path, "%s/%s", o.shapes_dir, sc->shape_file);
            struct stat stt;
            if (stat(path, &stt) < 0) {
                printf("%s: skipped: %s: %s (--shapes DIR)\n", sc->name, path, strerror(errno));
                continue;
            }
        }
        struct nc_bench_method m[NC_BENCH_METHODS_MAX];
        struct nc_bench_result res[NC_BENCH_METHODS_MAX];
        int n = nc_bench_methods(sc, &o, m, NC_BENCH_METHODS_MAX);
        if ((rc = nc_bench_run_scene(sc, &o, m, n, res, stdout)) < 0)
            break;
        int flag[NMETRIC][NC_BENCH_METHODS_MAX], idx[NMETRIC][NC_BENCH_METHODS_MAX], nf[NMETRIC];
        for (int q = 0; q < NMETRIC; q++) {
            pareto(m, res, n, q, flag[q]);
            nf[q] = front_of(res, n, flag[q], idx[q]);
        }
        for (int i = 0; i < n; i++) {
            res[i].pareto = flag[M_REL][i];
            fprintf(csv, "%s,%s,%d,%d,%d,%g,%g,%.4f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%d,%s\n", sc->name,
                    m[i].name, m[i].spp, m[i].bounces, m[i].soft, m[i].lod_error_px, m[i].boulder_min_px,
                    res[i].time_ms, res[i].rel_rms, res[i].rel_p95, res[i].dn_rms, res[i].dn_p95, res[i].noise_dn,
                    res[i].sigma_rms, res[i].sigma_p95, flag[M_REL][i], flag[M_DN][i], flag[M_SIGMA][i],
                    res[i].chosen);
        }
        for (int k = 0; k < nf[M_REL]; k++)
            fprintf(front, "%s,%.4f,%.6g\n", sc->name, res[idx[M_REL][k]].time_ms, res[idx[M_REL][k]].rel_rms);
        for (int q = 0; q < NMETRIC; q++)
            report_auto(sc->name, &res[n - 1], auto_ratio(m, res, n, idx[q], nf[q], q), q);
        gp_scene(gp, sc->name, sc->what);
        nplots++;
    }
    fprintf(gp, "unset multiplot\n");
    int written = 1;
    for (int i = 0; i < 3; i++)
        written &= !ferror(out[i]) & (fclose(out[i]) == 0);
    if (rc < 0 || !nplots || !written) { /* nothing half-made left behind, nothing earlier lost */
        for (int i = 0; i < 3; i++)
            unlink(tmp[i]);
        if (rc < 0)
            return nc_cli_fail();
        fprintf(stderr, "navcam bench: %s\n",
                !written ? "cannot write the results (a full disk?)"
                         : "every scene asked for was skipped: nothing measured, no chart");
        return 1;
    }
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, made[i]);
        if (rename(tmp[i], path) < 0) {
            fprintf(stderr, "navcam bench: %s: %s\n", path, strerror(errno));
            return 1;
        }
    }
    snprintf(path, sizeof path, "%s/accuracy.png", dir);
    unlink(path); /* an earlier run's chart does not stand beside these results */
    if (nc_cli_gnuplot(dir, "accuracy.gp") != 0)
        printf("no chart: gnuplot failed or is missing (Debian: gnuplot-nox); %s/accuracy.gp draws it\n", dir);
    else
        printf("wrote %s/accuracy.csv, %s/accuracy.png\n", dir, dir);
    return 0;
}
