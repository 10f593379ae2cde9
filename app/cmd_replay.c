/* cmd_replay.c - `navcam replay`: stream a trajectory (CSV, or the built-in
 * approach) to `navcam serve`. A simulator of the simplest kind: it links the
 * client library only. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/cli.h"
#include "core/error.h"
#include "core/vec.h"
#include "navcam/client.h"

struct traj_row {
    double t_s;
    struct nc_vec3 p, sun;
    struct nc_quat q;
    int capture;
};

/* The built-in approach to the default scene's asteroid (as `make demo`):
 * 8 poses, 16 km to 3 km, one per second, looking at the body. */
static int builtin_approach(struct traj_row **out)
{
    const int n = 8;
    struct traj_row *r = calloc(n, sizeof *r);
    if (!r)
        return -ENOMEM;
    for (int i = 0; i < n; i++) {
        double d = 16000 * exp(log(3000.0 / 16000) * i / (n - 1));
        r[i].t_s = i;
        r[i].p = nc_v3(0.08 * d, -d, 0.03 * d);
        nc_quat_look_at(r[i].p, nc_v3(0, 0, 0), nc_v3(0, 0, 1), &r[i].q);
        r[i].sun = nc_v3(0.643, -0.766, 0);
        r[i].capture = 1;
    }
    *out = r;
    return n;
}

/* CSV: t_s, cam_x_m, cam_y_m, cam_z_m, q_w, q_x, q_y, q_z, sun_x, sun_y, sun_z[, capture]. */
static int read_traj(const char *path, struct traj_row **out)
{
    if (!strcmp(path, "builtin:approach"))
        return builtin_approach(out);
    FILE *f = fopen(path, "r");
    if (!f)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    struct traj_row *rows = NULL;
    size_t n = 0, cap = 0, lineno = 0;
    char line[1024];
    int rc = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        if (line[strspn(line, " \t\r\n")] == '\0' || line[0] == '#')
            continue;
        double v[12];
        int k = 0;
        char *s = line, *end;
        for (; k < 12; k++) {
            v[k] = strtod(s, &end);
            if (end == s)
                break;
            s = end + strspn(end, " \t");
            if (*s == ',')
                s++;
        }
        if (k < 11 || (k == 11 && *s && *s != '\n' && *s != '\r')) {
            if (lineno == 1 && n == 0)
                continue; /* a header */
            rc = nc_error(NC_EUSAGE, "%s:%zu: expected t_s,cam_x_m,cam_y_m,cam_z_m,q_w,q_x,q_y,q_z,sun_x,sun_y,sun_z[,capture]",
                          path, lineno);
            break;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            struct traj_row *r2 = realloc(rows, cap * sizeof *rows);
            if (!r2) {
                rc = -ENOMEM;
                break;
            }
            rows = r2;
        }
        rows[n++] = (struct traj_row){v[0], nc_v3(v[1], v[2], v[3]), nc_v3(v[8], v[9], v[10]), {v[4], v[5], v[6], v[7]},
                                      k == 12 ? v[11] != 0 : 1};
    }
    fclose(f);
    if (rc < 0) {
        free(rows);
        return rc;
    }
    *out = rows;
    return (int)n;
}

static const char replay_help[] =
    "Usage: navcam replay TRAJ.csv|builtin:approach [--lockstep] [--speed X] [options]\n"
    "\n"
    "Stream a trajectory to `navcam serve`. TRAJ.csv rows (an optional header first):\n"
    "  t_s, cam_x_m, cam_y_m, cam_z_m, q_w, q_x, q_y, q_z, sun_x, sun_y, sun_z[, capture]\n"
    "times in seconds of simulation time, the camera pose in the scene frame\n"
    "(quaternion camera -> scene), the Sun direction in the body frame; capture 1\n"
    "(the default) asks for a frame. builtin:approach is the default scene's approach.\n"
    "\n"
    "  -l, --lockstep        TCP; send each pose and wait for its frame before the next\n"
    "  -x, --speed X         pace rows at X times real time (default 1; 0 = as fast as\n"
    "                        possible); ignored with --lockstep\n"
    "  -H, --host ADDR       numeric IPv4 address (default 127.0.0.1)\n"
    "  -p, --port N          default 5751 (TCP, lock-step) or 5750 (UDP)\n"
    "  -T, --timeout-ms N    lock-step wait per frame (default 60000)\n"
    "  -h, --help            this help\n";

int main(int argc, char **argv)
{
    nc_cli_init("replay");
    static const struct option opts[] = {
        {"lockstep", no_argument, NULL, 'l'},        {"speed", required_argument, NULL, 'x'},
        {"host", required_argument, NULL, 'H'},      {"port", required_argument, NULL, 'p'},
        {"timeout-ms", required_argument, NULL, 'T'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    int lockstep = 0, port = 0, timeout_ms = 60000, c;
    double speed = 1;
    const char *host = "127.0.0.1";
    optind = 1;
    while ((c = getopt_long(argc, argv, "lx:H:p:T:h", opts, NULL)) != -1) {
        switch (c) {
        case 'l': lockstep = 1; break;
        case 'x': speed = atof(optarg); break;
        case 'H': host = optarg; break;
        case 'p': port = atoi(optarg); break;
        case 'T': timeout_ms = atoi(optarg); break;
        case 'h': fputs(replay_help, stdout); return 0;
        default: fputs("Try 'navcam replay --help'.\n", stderr); return 2;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "navcam replay: give one trajectory (a CSV file or builtin:approach)\n");
        return 2;
    }
    struct traj_row *rows = NULL;
    int n = read_traj(argv[optind], &rows);
    if (n < 0) {
        fprintf(stderr, "navcam replay: %s\n", nc_errmsg());
        return 1;
    }
    struct nc_client *cl;
    if (nc_client_connect(host, port ? port : lockstep ? 5751 : 5750, lockstep, &cl) < 0) {
        fprintf(stderr, "navcam replay: %s\n", nc_errmsg());
        free(rows);
        return 1;
    }
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int rc = 0, delivered = 0, dropped = 0;
    for (int i = 0; i < n && rc == 0; i++) {
        struct nc_pose_msg m = {.type = NC_MSG_POSE, .flags = rows[i].capture ? NC_MSG_CAPTURE : 0,
                                .sim_time_ns = (int64_t)llround(rows[i].t_s * 1e9), .cam_position_m = rows[i].p,
                                .cam_attitude_q = rows[i].q, .sun = rows[i].sun};
        if (!lockstep && speed > 0) { /* pace by simulation time */
            double due = (rows[i].t_s - rows[0].t_s) / speed;
            struct timespec now;
            clock_gettime(CLOCK_MONOTONIC, &now);
            double el = (now.tv_sec - t0.tv_sec) + (now.tv_nsec - t0.tv_nsec) * 1e-9;
            if (due > el) {
                struct timespec w = {(time_t)(due - el), (long)((due - el - (time_t)(due - el)) * 1e9)};
                nanosleep(&w, NULL);
            }
        }
        long seq = nc_client_send(cl, &m);
        if (seq < 0) {
            rc = 1;
            break;
        }
        if (lockstep && rows[i].capture) {
            uint64_t frame;
            uint32_t status;
            if (nc_client_wait_frame(cl, (uint32_t)seq, timeout_ms, &frame, &status) < 0) {
                rc = 1;
                break;
            }
            if (status == NC_FRAME_DELIVERED) {
                delivered++;
                printf("pose %d (t = %.3f s): frame %llu\n", i, rows[i].t_s, (unsigned long long)frame);
            } else {
                dropped++;
                printf("pose %d (t = %.3f s): dropped\n", i, rows[i].t_s);
            }
        }
    }
    if (rc)
        fprintf(stderr, "navcam replay: %s\n", nc_errmsg());
    else
        printf("replayed %d poses%s", n, lockstep ? "" : "\n");
    if (!rc && lockstep)
        printf(": %d frames delivered, %d dropped\n", delivered, dropped);
    nc_client_close(cl);
    free(rows);
    return rc;
}
