/* testutil.h - minimal test helpers: non-fatal checks with messages, a
 * per-test temporary directory, and scene construction from YAML text. */
#ifndef NC_TESTUTIL_H
#define NC_TESTUTIL_H

#include <stdio.h>
#include <stdint.h>

#include "render/render.h"
#include "render/scene.h"

extern int nc_test_failed, nc_test_passed;

#define CHECK(cond, ...)                                                                                   \
    do {                                                                                                   \
        if (cond) {                                                                                        \
            nc_test_passed++;                                                                              \
        } else {                                                                                           \
            nc_test_failed++;                                                                              \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);                      \
            fprintf(stderr, __VA_ARGS__);                                                                  \
            fputc('\n', stderr);                                                                           \
        }                                                                                                  \
    } while (0)

/* A small cratered asteroid (Lambert, subdivisions 5: 20 480 triangles)
 * seen whole from 3 km by a 256x256 camera at about 40 deg phase: the
 * surface-detail tests' scene. */
extern const char nc_test_asteroid_yaml[];

/* Temporary directory of this test (created), and a path inside it. */
const char *nc_test_tmp(void);
const char *nc_test_path(const char *name);
void nc_test_write(const char *path, const char *text);
/* len bytes (NUL bytes too) to path */
void nc_test_write_bytes(const char *path, const void *data, size_t len);
/* The bytes of a file (NUL-terminated, malloc'd; its length in *len), or
 * NULL if it cannot be read. */
char *nc_test_read(const char *path, size_t *len);
/* CPU seconds process pid has used so far (user and system, /proc); -1 if unknown. */
double nc_test_cpu_s(int pid);
/* Scene from YAML text plus overrides; aborts the test on error. */
void nc_test_scene(const char *yaml, const char *const *sets, int nsets, struct nc_scene *s);
/* Load YAML text + sets; returns the error code and leaves nc_errmsg(). */
int nc_test_scene_rc(const char *yaml, const char *const *sets, int nsets, struct nc_scene *s);
/* Render the scene with the given thread count into a newly allocated frame. */
void nc_test_render(const struct nc_scene *s, int threads, struct nc_frame *f);
/* The lumpy test asteroid's mesh (radii 280, 230, 200 m, seed 3) at this
 * many subdivisions and craters; a failure ends the test. */
void nc_test_asteroid_mesh(int subdivisions, int craters, struct nc_mesh *m);
/* The nearest of mesh m's facets (body frame = scene frame) the ray o + t d
 * meets, in double by brute force: 1 with its t, its facet's unit normal n
 * turned to face the ray, and how far the hit is inside the facet (the
 * least barycentric coordinate), else 0. */
int nc_test_mesh_hit(const struct nc_mesh *m, struct nc_vec3 o, struct nc_vec3 d, double *t, struct nc_vec3 *n,
                     double *inside);
int nc_test_contains(const char *haystack, const char *needle);
/* qsort's comparison of uint64_t values, ascending. */
int nc_test_cmp_u64(const void *a, const void *b);
/* The slope b of a cumulative power law N(>D) ~ D^-b truncated to [lo, hi],
 * fitted by maximum likelihood to n diameters. */
double nc_test_fit_slope(const double *d, size_t n, double lo, double hi);
/* Start argv[0] (NULL-terminated argv) in directory dir (made if missing),
 * stderr to dir/serve.log, stdout to /dev/null; returns the child's pid. */
int nc_test_spawn(const char *dir, const char *const *argv);
/* Print "N passed, M failed" and return the exit status. */
int nc_test_end(void);

#endif
