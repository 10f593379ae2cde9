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
#include "core/traj.h"
#include "core/vec.h"
#include "navcam/client.h"

static const char replay_help[] =
    "Usage: navcam replay TRAJ.csv|builtin:approach [--lockstep] [--speed X] [options]\n"
    "\n"
    "Stream a trajectory to `navcam serve`. TRAJ.csv rows (an optional header first):\n"
    "  t_s, cam_x_m, cam_y_m, cam_z_m, q_w, q_x, q_y, q_z, sun_x, sun_y, sun_z[, capture]\n"
    "times in seconds of simulation time, the camera pose in the scene frame\n"
    "(quaternion camera -> scene), the Sun direction in the body frame; capture 1\n"
    "(the default) asks for a frame. builtin:approach is the default scene's approach.\n"
    "Without --lockstep, times must not decrease from row to row. A header that names\n"
    "every column (capture optional) in another order has them taken by name, e.g.\n"
    "q_x,q_y,q_z,q_w for a scalar-last quaternion (docs/batch.md).\n"
    "Or SPC SUM-like rows, after the header t_s,scobj_x_km,...:\n"
    "  t_s, scobj_x_km, scobj_y_km, scobj_z_km, cx_x, cx_y, cx_z, cy_x, cy_y, cy_z,\n"
    "  cz_x, cz_y, cz_z, sz_x, sz_y, sz_z[, capture]\n"
    "SCOBJ (spacecraft -> body, km), camera axes and Sun in the body-fixed frame,\n"
    "the scene frame when bodies[0] sits at the origin unturned (docs/sumfiles.md).\n"
    "\n"
    "  -l, --lockstep        TCP; send each pose and wait for its frame before the next\n"
    "  -x, --speed X         pace rows at X times real time, 1e-6 to 1e6 (default 1;\n"
    "                        0 = as fast as possible); ignored with --lockstep\n"
    "  -H, --host ADDR       numeric IPv4 address (default 127.0.0.1)\n"
    "  -p, --port N          default 5751 (TCP, lock-step) or 5750 (UDP)\n"
    "  -T, --timeout-ms N    lock-step wait per frame (default 60000)\n"
    "  -w, --wait S          lock-step: while nothing listens on the port yet (a server\n"
    "                        still building its scene), try again for up to S seconds\n"
    "                        (default 30; 0: fail at once). Free-run poses go by UDP,\n"
    "                        which has no connection: those sent before the server\n"
    "                        listens are lost\n"
    "  -h, --help            this help\n";

/* A TCP connection refused (a server still starting) is tried again every
 * 0.1 s for up to wait_s seconds. */
static int connect_waiting(const char *host, int port, int tcp, double wait_s, struct nc_client **cl)
{
    struct timespec t0, now, pause = {0, 100000000};
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int said = 0;; said = 1) {
        int rc = nc_client_connect(host, port, tcp, cl);
        clock_gettime(CLOCK_MONOTONIC, &now);
        const double el = (now.tv_sec - t0.tv_sec) + (now.tv_nsec - t0.tv_nsec) * 1e-9;
        if (rc != -ECONNREFUSED || el + 0.1 > wait_s)
            return rc;
        if (!said)
            fprintf(stderr, "navcam replay: nothing listens on TCP %s:%d yet; trying for up to %g s (--wait)\n", host,
                    port, wait_s);
        nanosleep(&pause, NULL);
    }
}

int main(int argc, char **argv)
{
    nc_cli_init("replay");
    static const struct option opts[] = {
        {"lockstep", no_argument, NULL, 'l'},        {"speed", required_argument, NULL, 'x'},
        {"host", required_argument, NULL, 'H'},      {"port", required_argument, NULL, 'p'},
        {"timeout-ms", required_argument, NULL, 'T'}, {"wait", required_argument, NULL, 'w'},
        {"help", no_argument, NULL, 'h'},         {NULL, 0, NULL, 0},
    };
    int lockstep = 0, c, bad = 0;
    long port = 0, timeout_ms = 60000;
    double speed = 1, wait_s = 30;
    const char *host = "127.0.0.1";
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "lx:H:p:T:w:h", opts)) != -1 && !bad) {
        switch (c) {
        case 'l': lockstep = 1; break;
        case 'x':
            bad = nc_cli_double("speed", optarg, 0, 1e6, &speed);
            if (!bad && speed > 0 && speed < 1e-6) { /* a row's wait would overflow a time_t */
                fprintf(stderr, "navcam replay: --speed expects 0 or 1e-06..1e+06, got '%s'\n", optarg);
                bad = 1;
            }
            break;
        case 'H': bad = nc_cli_host(host = optarg); break;
        case 'p': bad = nc_cli_long("port", optarg, 1, 65535, &port); break;
        case 'T': bad = nc_cli_long("timeout-ms", optarg, 1, 86400000, &timeout_ms); break;
        case 'w': bad = nc_cli_double("wait", optarg, 0, 3600, &wait_s); break;
        case 'h': fputs(replay_help, stdout); return 0;
        default: bad = 1; break;
        }
    }
    if (bad) {
        fputs("Try 'navcam replay --help'.\n", stderr);
        return 2;
    }
    if (optind != argc - 1) {
        fprintf(stderr, "navcam replay: give one trajectory (a CSV file or builtin:approach)\n");
        return 2;
    }
    struct nc_traj_row *rows = NULL;
    int n = nc_traj_read(argv[optind], &rows);
    if (n < 0) {
        fprintf(stderr, "navcam replay: %s\n", nc_errmsg());
        return 1;
    }
    for (int i = 1; i < n && !lockstep; i++)
        if (rows[i].t_s < rows[i - 1].t_s) { /* serve would refuse it (time_backwards), and pacing could not keep it */
            fprintf(stderr, "navcam replay: %s:%d: t_s %.9g s is before the row before's %.9g s (line %d): free-run "
                            "poses go forward in simulation time (--lockstep renders each pose as it comes)\n",
                    argv[optind], rows[i].line, rows[i].t_s, rows[i - 1].t_s, rows[i - 1].line);
            free(rows);
            return 1;
        }
    struct nc_client *cl;
    if (connect_waiting(host, port ? (int)port : lockstep ? 5751 : 5750, lockstep, wait_s, &cl) < 0) {
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
