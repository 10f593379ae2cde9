/* serve_cmd.c - the `navcam serve`, `navcam replay` and `navcam pose send`
 * commands: argument parsing, and the trajectory reader of replay. The
 * emulator itself is emulator/serve.c; the protocol side is client/. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "error.h"
#include "navcam/client.h"
#include "output.h"
#include "serve.h"
#include "trigger.h"
#include "vec.h"

int cmd_serve(int argc, char **argv);
int cmd_replay(int argc, char **argv);
int cmd_pose(int argc, char **argv);

static const char serve_help[] =
    "Usage: navcam serve [SCENE.yaml] [--set KEY=VALUE]... [options]\n"
    "\n"
    "Run the camera emulator: poses in over UDP/TCP (docs/protocol.md), frames out to\n"
    "the outputs of the scene's `outputs:` list (file, null). Modes (serve.mode):\n"
    "  lockstep  every POSE with CAPTURE gets exactly one frame, in order, answered\n"
    "            with a FRAME message on TCP: reproducible closed loops\n"
    "  freerun   frames at serve.frame_rate_hz on the emulator's clock\n"
    "  trigger   a frame per accepted edge of serve.trigger (default: software\n"
    "            triggers, TRIGGER or POSE with CAPTURE); e.g.\n"
    "            --set 'serve.trigger={driver: timer, rate_hz: 20, activation:\n"
    "            falling_edge, delay_s: 0.01, debounce_s: 0.001}'\n"
    "Listeners bind serve.bind (127.0.0.1) on serve.udp_port (5750) and\n"
    "serve.tcp_port (5751). SIGINT/SIGTERM: finish the frame in flight, flush the\n"
    "outputs, print statistics (a JSON summary on stdout), exit 0.\n"
    "\n"
    "  -s, --set KEY=VALUE     override a configuration key (repeatable)\n"
    "  -n, --max-frames N      stop after N frames were delivered or dropped\n"
    "  -t, --max-seconds S     stop after S seconds\n"
    "      --stats-json FILE   also write the summary to FILE\n"
    "  -j, --threads N         render threads\n"
    "  -h, --help              this help\n"
    "\n"
    "Example (lock-step, the built-in default scene, frames under out/):\n"
    "  navcam serve --set serve.mode=lockstep &\n"
    "  navcam replay builtin:approach --lockstep\n";

/* The help text, then the drivers this build has (from the registries). */
static void serve_usage(void)
{
    fputs(serve_help, stdout);
    puts("\nOutput drivers (outputs: [{driver: NAME, ...}]):");
    for (int i = 0; nc_output_drivers[i]; i++)
        printf("  %-9s %s\n", nc_output_drivers[i]->name, nc_output_drivers[i]->description);
    puts("Trigger drivers (serve.trigger: {driver: NAME, ...}; docs/emulator.md):");
    for (int i = 0; nc_trigger_drivers[i]; i++)
        printf("  %-9s %s\n", nc_trigger_drivers[i]->name, nc_trigger_drivers[i]->description);
}

int cmd_serve(int argc, char **argv)
{
    static const struct option opts[] = {
        {"set", required_argument, NULL, 's'},        {"max-frames", required_argument, NULL, 'n'},
        {"max-seconds", required_argument, NULL, 't'}, {"stats-json", required_argument, NULL, 'J'},
        {"threads", required_argument, NULL, 'j'},    {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    struct nc_serve_options o = {0};
    int c;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = getopt_long(argc, argv, "s:n:t:j:h", opts, NULL)) != -1) {
        switch (c) {
        case 's': sets[o.nsets++] = optarg; break;
        case 'n': o.max_frames = atol(optarg); break;
        case 't': o.max_seconds = atof(optarg); break;
        case 'J': o.stats_json_path = optarg; break;
        case 'j': o.threads = atoi(optarg); break;
        case 'h': serve_usage(); free(sets); return 0;
        default: fputs("Try 'navcam serve --help'.\n", stderr); free(sets); return 2;
        }
    }
    if (optind < argc)
        o.scene_path = argv[optind++];
    if (optind < argc) {
        fprintf(stderr, "navcam serve: more than one scene file given\n");
        free(sets);
        return 2;
    }
    o.sets = sets;
    int rc = nc_serve(&o);
    free(sets);
    if (rc < 0) {
        fprintf(stderr, "navcam serve: %s\n", nc_errmsg());
        return 1;
    }
    return 0;
}

/* ---- trajectories --------------------------------------------------------- */

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

int cmd_replay(int argc, char **argv)
{
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

static const char pose_help[] =
    "Usage: navcam pose send --position X,Y,Z --attitude W,X,Y,Z --sun X,Y,Z [options]\n"
    "\n"
    "Send one POSE (or, with --trigger, one software TRIGGER) to `navcam serve`.\n"
    "  -P, --position X,Y,Z   camera position, m, scene frame\n"
    "  -A, --attitude W,X,Y,Z camera -> scene quaternion (default 1,0,0,0)\n"
    "  -S, --sun X,Y,Z        Sun direction, body frame (default 1,0,0)\n"
    "  -t, --time S           simulation time, s (default 0)\n"
    "  -c, --capture          ask for a frame (lock-step or trigger mode)\n"
    "      --trigger          send a TRIGGER instead of a POSE\n"
    "  -e, --exposure S       exposure for the requested frame, s\n"
    "  -g, --gain DB          analog gain for the requested frame, dB\n"
    "      --tcp              over TCP, waiting for the FRAME answer when capturing\n"
    "  -H, --host ADDR        default 127.0.0.1;  -p, --port N  default 5750 (UDP) / 5751 (TCP)\n";

static int parse_vec(const char *s, double *v, int n)
{
    char *end;
    for (int i = 0; i < n; i++) {
        v[i] = strtod(s, &end);
        if (end == s || !isfinite(v[i]))
            return -1;
        s = end + (*end == ',');
    }
    return *end ? -1 : 0;
}

int cmd_pose(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "send") != 0) {
        fputs(argc > 1 && !strcmp(argv[1], "--help") ? pose_help : "Usage: navcam pose send ... (navcam pose send --help)\n",
              argc > 1 && !strcmp(argv[1], "--help") ? stdout : stderr);
        return argc > 1 && !strcmp(argv[1], "--help") ? 0 : 2;
    }
    static const struct option opts[] = {
        {"position", required_argument, NULL, 'P'}, {"attitude", required_argument, NULL, 'A'},
        {"sun", required_argument, NULL, 'S'},      {"time", required_argument, NULL, 't'},
        {"capture", no_argument, NULL, 'c'},        {"trigger", no_argument, NULL, 'R'},
        {"exposure", required_argument, NULL, 'e'}, {"gain", required_argument, NULL, 'g'},
        {"tcp", no_argument, NULL, 'C'},            {"host", required_argument, NULL, 'H'},
        {"port", required_argument, NULL, 'p'},     {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    double pos[3] = {0, 0, 0}, att[4] = {1, 0, 0, 0}, sun[3] = {1, 0, 0}, t = 0, v;
    struct nc_pose_msg m = {.type = NC_MSG_POSE};
    int tcp = 0, port = 0, c, have_pos = 0;
    const char *host = "127.0.0.1";
    optind = 1;
    while ((c = getopt_long(argc - 1, argv + 1, "P:A:S:t:ce:g:H:p:h", opts, NULL)) != -1) {
        switch (c) {
        case 'P': have_pos = parse_vec(optarg, pos, 3) == 0; if (!have_pos) goto bad; break;
        case 'A': if (parse_vec(optarg, att, 4) < 0) goto bad; break;
        case 'S': if (parse_vec(optarg, sun, 3) < 0) goto bad; break;
        case 't': if (parse_vec(optarg, &t, 1) < 0) goto bad; break;
        case 'c': m.flags |= NC_MSG_CAPTURE; break;
        case 'R': m.type = NC_MSG_TRIGGER; m.flags |= NC_MSG_CAPTURE; break;
        case 'e': if (parse_vec(optarg, &v, 1) < 0) goto bad; m.exposure_s = v; m.flags |= NC_MSG_EXPOSURE; break;
        case 'g': if (parse_vec(optarg, &v, 1) < 0) goto bad; m.gain_db = v; m.flags |= NC_MSG_GAIN; break;
        case 'C': tcp = 1; break;
        case 'H': host = optarg; break;
        case 'p': port = atoi(optarg); break;
        case 'h': fputs(pose_help, stdout); return 0;
        default: fputs("Try 'navcam pose send --help'.\n", stderr); return 2;
        }
    }
    if (m.type == NC_MSG_POSE && !have_pos) {
        fprintf(stderr, "navcam pose send: --position X,Y,Z is required\n");
        return 2;
    }
    m.sim_time_ns = (int64_t)llround(t * 1e9);
    m.cam_position_m = nc_v3(pos[0], pos[1], pos[2]);
    m.cam_attitude_q = (struct nc_quat){att[0], att[1], att[2], att[3]};
    m.sun = nc_v3(sun[0], sun[1], sun[2]);
    struct nc_client *cl;
    if (nc_client_connect(host, port ? port : tcp ? 5751 : 5750, tcp, &cl) < 0) {
        fprintf(stderr, "navcam pose send: %s\n", nc_errmsg());
        return 1;
    }
    long seq = nc_client_send(cl, &m);
    int rc = seq < 0;
    if (!rc && tcp && (m.flags & NC_MSG_CAPTURE)) {
        uint64_t frame;
        uint32_t status;
        rc = nc_client_wait_frame(cl, (uint32_t)seq, 60000, &frame, &status) < 0;
        if (!rc)
            printf("frame %llu %s\n", (unsigned long long)frame, status == NC_FRAME_DELIVERED ? "delivered" : "dropped");
    }
    if (rc)
        fprintf(stderr, "navcam pose send: %s\n", nc_errmsg());
    nc_client_close(cl);
    return rc;
bad:
    fprintf(stderr, "navcam pose send: bad value '%s' for --%s\n", optarg, opts[0].name);
    return 2;
}
