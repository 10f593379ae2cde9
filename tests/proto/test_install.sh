#!/usr/bin/env bash
# test_install.sh - NavCam installed into a fresh prefix, used as a lab would:
# a simulator written against the public header only builds with
# `pkg-config --cflags --libs navcam-client`, and talks to the installed
# `navcam serve` (lock-step, loopback): its capture is answered by a FRAME.
# Usage: test_install.sh BUILD_DIR TMP_DIR NAVCAM(unused: the installed one is run)
set -euo pipefail
build=$1 tmp=$2
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*"; }
rm -rf "$tmp"
mkdir -p "$tmp"
prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" >"$tmp/install.log"
pc=$(find "$prefix" -name navcam-client.pc | head -1)
[ -n "$pc" ] && ok || { bad "no navcam-client.pc installed"; echo "$pass passed, $fail failed"; exit 1; }
export PKG_CONFIG_PATH=$(dirname "$pc")
[ -x "$prefix/bin/navcam" ] && [ -x "$prefix/libexec/navcam/navcam-serve" ] && ok || bad "programs not installed"
# The public headers pull in nothing internal.
for h in "$prefix"/include/navcam/*.h; do
  grep -h '#include "' "$h" | grep -vq 'navcam/' && bad "$h includes an internal header" || ok
done

cat >"$tmp/sim.c" <<'SIM'
/* A simulator: one lock-step capture, its answer printed. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <navcam/client.h>
int main(int argc, char **argv)
{
    struct nc_client *c = NULL;
    int port = atoi(argv[1]);
    for (int i = 0; i < 200 && nc_client_connect("127.0.0.1", port, 1, &c) < 0; i++) {
        struct timespec ts = {0, 50000000};
        nanosleep(&ts, NULL);
    }
    if (!c) {
        fprintf(stderr, "sim: %s\n", nc_client_errmsg());
        return 1;
    }
    struct nc_pose_msg m = {.type = NC_MSG_POSE, .flags = NC_MSG_CAPTURE, .sim_time_ns = 1000000000,
                            .cam_position_m = {0, -6000, 0}, .cam_attitude_q = {0.70710678, -0.70710678, 0, 0},
                            .sun = {1, 0, 0}};
    long seq = nc_client_send(c, &m);
    uint64_t frame = 0;
    uint32_t status = 9;
    if (seq < 0 || nc_client_wait_frame(c, (uint32_t)seq, 60000, &frame, &status) < 0) {
        fprintf(stderr, "sim: %s\n", nc_client_errmsg());
        return 1;
    }
    printf("frame %llu status %u\n", (unsigned long long)frame, status);
    nc_client_close(c);
    return status == NC_FRAME_DELIVERED ? 0 : 1;
}
SIM
# A sanitizer build installs an instrumented library: the simulator must be too.
san=()
grep -q '^CMAKE_BUILD_TYPE:STRING=Asan' "$build/CMakeCache.txt" && san=(-fsanitize=address,undefined)
cc -std=c11 -D_POSIX_C_SOURCE=200809L -Wall -Werror "${san[@]}" -o "$tmp/sim" "$tmp/sim.c" $(pkg-config --cflags --libs navcam-client) \
  2>"$tmp/cc.log" && ok || { bad "the simulator does not build against the installed library: $(cat "$tmp/cc.log")"; }

# Only the public functions are global in the library: a simulator with
# functions of NavCam's internal names (nc_error, nc_errmsg) still links, and
# in C++ too (the headers declare C linkage).
lib=$(pkg-config --variable=libdir navcam-client)/libnavcam-client.a
[ "$(nm -g --defined-only "$lib" | awk 'NF == 3 {print $3}' | sort | tr '\n' ' ')" = \
  "nc_client_close nc_client_connect nc_client_errmsg nc_client_next_frame nc_client_send nc_client_wait_frame nc_msg_decode nc_msg_encode nc_msg_size nc_reject_key nc_reject_name " ] \
  && ok || bad "the library exports more than its API: $(nm -g --defined-only "$lib" | awk 'NF == 3 {print $3}' | tr '\n' ' ')"
cat >"$tmp/clash.c" <<'SIM'
#include <navcam/client.h>
int nc_error(int code, const char *fmt) { return code + (fmt != 0); }
const char *nc_errmsg(void) { return "mine"; }
int main(void) { struct nc_client *c = 0; return nc_client_connect("x", 1, 1, &c) == -22 && nc_error(1, 0) == 1 ? 0 : 1; }
SIM
cc -std=c11 -Wall -Werror "${san[@]}" -o "$tmp/clash" "$tmp/clash.c" $(pkg-config --cflags --libs navcam-client) \
  2>"$tmp/clash.log" && "$tmp/clash" && ok || bad "a simulator with its own nc_error: $(cat "$tmp/clash.log")"
cp "$tmp/clash.c" "$tmp/clash.cc"
c++ -Wall -Werror "${san[@]}" -o "$tmp/clashpp" "$tmp/clash.cc" $(pkg-config --cflags --libs navcam-client) \
  2>"$tmp/clashpp.log" && "$tmp/clashpp" && ok || bad "the client library from C++: $(cat "$tmp/clashpp.log")"

port=$((20000 + RANDOM % 20000))
"$prefix/bin/navcam" serve --set serve.mode=lockstep --set serve.tcp_port=$port --set serve.udp_port=0 \
  --set 'outputs=[{driver: null}]' --set camera.width_px=64 --set camera.height_px=48 -n 1 -t 60 \
  >"$tmp/serve.out" 2>"$tmp/serve.log" &
serve=$!
if [ -x "$tmp/sim" ]; then
  timeout 60 "$tmp/sim" $port >"$tmp/sim.out" 2>&1 && grep -q "frame 0 status 0" "$tmp/sim.out" && ok ||
    bad "simulator against the installed navcam serve: $(cat "$tmp/sim.out")"
else
  kill $serve 2>/dev/null || true
fi
wait $serve && ok || bad "installed navcam serve: $(tail -3 "$tmp/serve.log")"
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
