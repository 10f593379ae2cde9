/* testutil.c - see testutil.h. */
#include "testutil.h"

#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"

int nc_test_failed, nc_test_passed;

const char *nc_test_tmp(void)
{
    static char dir[1024];
    if (!dir[0]) {
        const char *e = getenv("NC_TEST_TMP");
        snprintf(dir, sizeof dir, "%s", e ? e : "/tmp/navcam_test");
        char cmd[1100];
        snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
        if (system(cmd) != 0) {
            fprintf(stderr, "cannot create %s\n", dir);
            exit(2);
        }
    }
    return dir;
}

const char *nc_test_path(const char *name)
{
    static char buf[8][1200];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", nc_test_tmp(), name);
    return buf[k];
}

void nc_test_write(const char *path, const char *text)
{
    nc_test_write_bytes(path, text, strlen(text));
}

void nc_test_write_bytes(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, len, f) != len || fclose(f) != 0) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(2);
    }
}

char *nc_test_read(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long n = f && fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (n >= 0 && fseek(f, 0, SEEK_SET) == 0 && (buf = malloc((size_t)n + 1)) &&
        fread(buf, 1, (size_t)n, f) == (size_t)n) {
        buf[n] = 0;
        *len = (size_t)n;
    } else {
        free(buf);
        buf = NULL;
    }
    if (f)
        fclose(f);
    return buf;
}

int nc_test_scene_rc(const char *yaml, const char *const *sets, int nsets, struct nc_scene *s)
{
    struct nc_cfg cfg;
    nc_cfg_init(&cfg);
    int rc = nc_cfg_load_string(&cfg, yaml, "test.yaml");
    for (int i = 0; rc >= 0 && i < nsets; i++)
        rc = nc_cfg_set(&cfg, sets[i]);
    if (rc >= 0 && (rc = nc_scene_read(&cfg, s)) >= 0) {
        /* Render tests ignore the camera model of scenes that have one. */
        static const char *const camera_model[] = {"optics", "sensor", "exposure"};
        for (int i = 0; i < 3; i++) {
            struct nc_cfg_node *n = nc_cfg_get(cfg.root, camera_model[i]);
            if (n)
                nc_cfg_mark_used(n);
        }
        if ((rc = nc_cfg_check_unused(&cfg)) < 0)
            nc_scene_free(s);
    }
    nc_cfg_free(&cfg);
    return rc;
}

void nc_test_scene(const char *yaml, const char *const *sets, int nsets, struct nc_scene *s)
{
    if (nc_test_scene_rc(yaml, sets, nsets, s) < 0) {
        fprintf(stderr, "scene: %s\n", nc_errmsg());
        exit(2);
    }
}

void nc_test_render(const struct nc_scene *s, int threads, struct nc_frame *f)
{
    struct nc_renderer r;
    if (nc_renderer_init(&r, s, threads) < 0 || nc_frame_alloc(f, s->camera.width_px, s->camera.height_px) < 0 ||
        nc_render_frame(&r, s, f) < 0) {
        fprintf(stderr, "render: %s\n", nc_errmsg());
        exit(2);
    }
    nc_renderer_free(&r);
}

void nc_test_asteroid_mesh(int subdivisions, int craters, struct nc_mesh *m)
{
    struct nc_asteroid_params p = {.radii_m = {280, 230, 200}, .subdivisions = subdivisions, .seed = 3,
                                   .craters = craters, .lump_amplitude = 0.1};
    if (nc_mesh_asteroid(&p, m) < 0) {
        fprintf(stderr, "asteroid: %s\n", nc_errmsg());
        exit(2);
    }
}

int nc_test_contains(const char *haystack, const char *needle) { return strstr(haystack, needle) != NULL; }

int nc_test_cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

double nc_test_fit_slope(const double *d, size_t n, double lo, double hi)
{
    /* Maximum likelihood: the mean of ln(D/lo) equals its expectation
     * 1/b - L e^(-bL) / (1 - e^(-bL)), L = ln(hi/lo), which falls with b:
     * bisection. */
    double m = 0;
    for (size_t i = 0; i < n; i++)
        m += log(d[i] / lo);
    m /= (double)n;
    double L = log(hi / lo), a = 0.05, b = 10;
    for (int it = 0; it < 200; it++) {
        double s = 0.5 * (a + b), e = 1 / s - L * exp(-s * L) / (1 - exp(-s * L));
        if (e > m)
            a = s; /* too shallow */
        else
            b = s;
    }
    return 0.5 * (a + b);
}

int nc_test_end(void)
{
    printf("%d passed, %d failed\n", nc_test_passed, nc_test_failed);
    return nc_test_failed ? 1 : 0;
}

int nc_test_spawn(const char *dir, const char *const *argv)
{
    char log[4200];
    snprintf(log, sizeof log, "%s/serve.log", dir);
    mkdir(dir, 0777);
    const pid_t parent = getpid();
    pid_t pid = fork();
    if (pid == 0) {
        /* a test that crashes takes its server with it (else it would hold
         * its ports for the next test) */
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() != parent)
            _exit(127);
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644), nul = open("/dev/null", O_WRONLY);
        if (chdir(dir) < 0 || fd < 0 || nul < 0)
            _exit(127);
        dup2(fd, 2);
        dup2(nul, 1);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    return (int)pid;
}

const char nc_test_asteroid_yaml[] =
    "bodies:\n"
    "  - shape: {type: asteroid, radii_m: [280, 230, 200], subdivisions: 5, seed: 7, craters: 30}\n"
    "    material: {model: lambert, A: 0.1}\n"
    "sun: {direction: [0.643, -0.766, 0.3]}\n"
    "camera: {width_px: 256, height_px: 256, focal_length_m: 0.025, pixel_pitch_m: 2.2e-5,\n"
    "         position_m: [0, -3000, 0], look_at_m: [0, 0, 0], up: [0, 0, 1]}\n"
    "render: {samples_per_pixel: 4}\n";

double nc_test_cpu_s(int pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", pid);
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f)
        fclose(f);
    buf[n] = 0;
    const char *p = strrchr(buf, ')'); /* fields 14 and 15 after the command's name */
    unsigned long ut = 0, st = 0;
    if (!p || sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &ut, &st) != 2)
        return -1;
    return (double)(ut + st) / (double)sysconf(_SC_CLK_TCK);
}

int nc_test_mesh_hit(const struct nc_mesh *m, struct nc_vec3 o, struct nc_vec3 d, double *t, struct nc_vec3 *n,
                     double *inside)
{
    int hit = 0;
    *t = INFINITY;
    for (size_t k = 0; k < m->nt; k++) { /* Moller-Trumbore */
        const double *p0 = &m->v[3 * m->tri[3 * k]], *p1 = &m->v[3 * m->tri[3 * k + 1]],
                     *p2 = &m->v[3 * m->tri[3 * k + 2]];
        const struct nc_vec3 a = nc_v3(p0[0], p0[1], p0[2]), e1 = nc_v3_sub(nc_v3(p1[0], p1[1], p1[2]), a),
                             e2 = nc_v3_sub(nc_v3(p2[0], p2[1], p2[2]), a), pv = nc_v3_cross(d, e2);
        const double det = nc_v3_dot(e1, pv);
        if (det == 0)
            continue;
        const struct nc_vec3 tv = nc_v3_sub(o, a), qv = nc_v3_cross(tv, e1);
        const double u = nc_v3_dot(tv, pv) / det, v = nc_v3_dot(d, qv) / det, tt = nc_v3_dot(e2, qv) / det;
        if (u >= 0 && v >= 0 && u + v <= 1 && tt > 0 && tt < *t) {
            *t = tt, *inside = fmin(fmin(u, v), 1 - u - v), hit = 1;
            *n = nc_v3_unit(nc_v3_cross(e1, e2));
            if (nc_v3_dot(*n, d) > 0)
                *n = nc_v3_scale(*n, -1);
        }
    }
    return hit;
}
