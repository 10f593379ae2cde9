/* cmd_pose.c - `navcam pose send`: one POSE or TRIGGER message to `navcam
 * serve`. Links the client library only. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "app/cli.h"
#include "core/error.h"
#include "core/vec.h"
#include "navcam/client.h"

static const char pose_help[] =
    "Usage: navcam pose send --position X,Y,Z [--attitude W,X,Y,Z] [--sun X,Y,Z] [options]\n"
    "\n"
    "Send one POSE (or, with --trigger, one software TRIGGER) to `navcam serve`.\n"
    "  -P, --position X,Y,Z   camera position, m, scene frame, within 1e15 m of the origin\n"
    "  -A, --attitude W,X,Y,Z camera -> scene quaternion, of unit length within 1e-6 (default 1,0,0,0)\n"
    "  -S, --sun X,Y,Z        Sun direction, body frame, not zero (default 1,0,0)\n"
    "  -t, --time S           simulation time, s, -4.6e9 to 4.6e9 (default 0)\n"
    "  -c, --capture          ask for a frame (lock-step or trigger mode)\n"
    "      --trigger          send a TRIGGER instead of a POSE\n"
    "  -e, --exposure S       exposure for the requested frame, s, 0 to 3600\n"
    "  -g, --gain DB          analog gain for the requested frame, dB, -60 to 60\n"
    "      --tcp              over TCP, waiting for the FRAME answer when capturing\n"
    "  -H, --host ADDR        numeric IPv4 address (default 127.0.0.1)\n"
    "  -p, --port N           1 to 65535 (default 5750 for UDP, 5751 for TCP)\n"
    "  -h, --help             this help\n"
    "Values the protocol refuses (docs/protocol.md) are refused here, naming the option.\n"
    "Exit status: 0 sent (and, with --tcp --capture, the frame delivered), 1 not\n"
    "sent or no answer, 2 a bad option, 3 the frame dropped (the answer's status).\n";

/* n numbers X,Y,...; -1 when s is not that, with *why "not finite" for a
 * NaN or infinity among them. */
static int parse_vec(const char *s, double *v, int n, const char **why)
{
    const char *end = s;
    for (int i = 0; i < n; i++) {
        if (nc_cli_decimal(s, &end, &v[i]) < 0) {
            const char *t = s + strspn(s, " \t+-");
            if (!strncasecmp(t, "inf", 3) || !strncasecmp(t, "nan", 3))
                *why = "not finite";
            return -1;
        }
        if (i + 1 < n && *end != ',') /* components separated by commas */
            return -1;
        s = end + (*end == ',');
    }
    return *end ? -1 : 0;
}

int main(int argc, char **argv)
{
    nc_cli_init("pose send");
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
    argv[1] = "navcam pose send"; /* getopt's messages begin with it */
    const char *why = NULL; /* what is wrong with the option's value */
    while ((c = nc_cli_getopt(argc - 1, argv + 1, "P:A:S:t:ce:g:H:p:h", opts)) != -1) {
        switch (c) {
        case 'P':
            have_pos = parse_vec(optarg, pos, 3, &why) == 0;
            if (!have_pos || (why = "farther than 1e15 m from the origin",
                              !(nc_v3_norm(nc_v3(pos[0], pos[1], pos[2])) <= NC_PROTO_POSITION_MAX_M)))
                goto bad;
            break;
        case 'A':
            if (parse_vec(optarg, att, 4, &why) < 0)
                goto bad;
            why = "not a unit quaternion within 1e-6";
            if (fabs(sqrt(att[0] * att[0] + att[1] * att[1] + att[2] * att[2] + att[3] * att[3]) - 1) >
                NC_PROTO_QUAT_TOL)
                goto bad;
            break;
        case 'S':
            if (parse_vec(optarg, sun, 3, &why) < 0 || (why = "a zero vector", !(sun[0] || sun[1] || sun[2])))
                goto bad;
            break;
        case 't':
            if (parse_vec(optarg, &t, 1, &why) < 0 ||
                (why = "beyond +-4.6e9 s", !(fabs(t) <= NC_PROTO_TIME_MAX_NS * 1e-9)))
                goto bad;
            break;
        case 'c': m.flags |= NC_MSG_CAPTURE; break;
        case 'R': m.type = NC_MSG_TRIGGER; m.flags |= NC_MSG_CAPTURE; break;
        case 'e':
            if (parse_vec(optarg, &v, 1, &why) < 0 ||
                (why = "not within 0 to 3600 s", !(v >= 0 && v <= NC_PROTO_EXPOSURE_MAX_S)))
                goto bad;
            m.exposure_s = v, m.flags |= NC_MSG_EXPOSURE;
            break;
        case 'g':
            if (parse_vec(optarg, &v, 1, &why) < 0 ||
                (why = "not within -60 to 60 dB", !(v >= -NC_PROTO_GAIN_MAX_DB && v <= NC_PROTO_GAIN_MAX_DB)))
                goto bad;
            m.gain_db = v, m.flags |= NC_MSG_GAIN;
            break;
        case 'C': tcp = 1; break;
        case 'H':
            if (nc_cli_host(host = optarg) < 0) {
                fputs("Try 'navcam pose send --help'.\n", stderr);
                return 2;
            }
            break;
        case 'p':
            if (parse_vec(optarg, &v, 1, &why) < 0 ||
                (why = "not a port, 1 to 65535", !(v >= 1 && v <= 65535 && v == floor(v))))
                goto bad;
            port = (int)v;
            break;
        case 'h': fputs(pose_help, stdout); return 0;
        default: fputs("Try 'navcam pose send --help'.\n", stderr); return 2;
        }
        why = NULL;
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
        if (!rc && status == NC_FRAME_DELIVERED)
            printf("frame %llu delivered\n", (unsigned long long)frame);
        else if (!rc) { /* the reason is in the server's statistics */
            printf("dropped (status %u)\n", status);
            nc_client_close(cl);
            return 3;
        }
    }
    if (rc)
        fprintf(stderr, "navcam pose send: %s\n", nc_errmsg());
    nc_client_close(cl);
    return rc;
bad:
    for (int i = 0; opts[i].name; i++)
        if (opts[i].val == c)
            fprintf(stderr, "navcam pose send: --%s %s: %s\n", opts[i].name, optarg,
                    why ? why : c == 'A' ? "expected 4 numbers W,X,Y,Z" : strchr("PS", c) ? "expected 3 numbers X,Y,Z"
                                                                                      : "expected a number");
    return 2;
}
