/* bench_accuracy.h - `navcam bench accuracy`: reference scenes, the methods
 * swept over them, and the error of each against a converged reference
 * (docs/accuracy.md). */
#ifndef NC_APP_BENCH_ACCURACY_H
#define NC_APP_BENCH_ACCURACY_H

#include <stdio.h>

/* A reference scene: the built-in default scene with these overrides. */
struct nc_bench_scene {
    const char *name, *what;
    const char *sets[12];
    const char *shape_file; /* a file of the shapes directory it needs, or NULL */
    int has_mesh_lod, has_rocks;
};

/* One method: render settings laid over the scene. */
struct nc_bench_method {
    char name[48];
    int spp, bounces, soft, auto_quality;
    double lod_error_px, boulder_min_px; /* < 0: the scene's default */
};

struct nc_bench_result {
    double time_ms;               /* render, median of the timed runs */
    double rel_rms, rel_p95;      /* |L - Lref| / Lref over the body's pixels */
    double dn_rms, dn_p95;        /* |DN - DNref| after the camera model, noise-free */
    double noise_dn;              /* the camera's own noise (shot + read) at the median body pixel, DN */
    double sigma_rms, sigma_p95;  /* |e - eref| / sqrt(eref + read^2): each pixel's error over its own
                                     camera noise (what render.quality: auto bounds by k) */
    int pareto;                   /* no other method of the scene is both faster and closer (rel_rms) */
    char chosen[96];              /* auto: the settings it picked */
};

struct nc_bench_opts {
    int size_px;       /* frames of size_px x size_px, the default camera's field kept */
    int ref_spp;       /* the reference's samples per pixel (a square) */
    int ref_bounces;
    int quick;         /* fewer methods (tests) */
    const char *shapes_dir;
    const char *work_dir; /* files the scenes need (the crater's DEM) */
    int threads;
};

extern const struct nc_bench_scene nc_bench_scenes[];
extern const int nc_bench_nscenes;

#define NC_BENCH_METHODS_MAX 48 /* methods a scene can have (nc_bench_methods) */

/* The methods swept on scene sc; returns how many (at most max). */
int nc_bench_methods(const struct nc_bench_scene *sc, const struct nc_bench_opts *o, struct nc_bench_method *m, int max);
/* Render the reference and every method of scene sc, filling res[0..n).
 * Progress lines go to log. Returns < 0 on error (nc_errmsg). */
int nc_bench_run_scene(const struct nc_bench_scene *sc, const struct nc_bench_opts *o,
                       const struct nc_bench_method *m, int n, struct nc_bench_result *res, FILE *log);

#endif
