#!/usr/bin/env bash
# guest_v4l2_gpio.sh - runs inside the test guest (vm.sh run): `navcam serve`
# with the V4L2 output on v4l2loopback and the GPIO trigger on gpio-sim,
# against a real V4L2 capture reader and edges driven on the sim line.
# Checks are in check.py; the benchmark line is printed at the end.
#
# Usage (in the guest): guest_v4l2_gpio.sh OUTDIR NAVCAM HELPERDIR SRCDIR [EDGES]
# (bench/bench_edge_to_frame.sh passes more edges for the latency figures)
set -euo pipefail
out=$1 navcam=$2 helpers=$3 src=$4
mods=/run/vm/root
edges=${5:-12}
cd "$out"
rm -rf a b c d e && mkdir -p a b c d e

. "$(dirname "$0")/guest_lib.sh"
trap 'echo "guest_v4l2_gpio.sh: line $LINENO: $BASH_COMMAND failed"' ERR
serve_pid= serve_dir=
cleanup() {
    [[ -n $serve_pid ]] || return 0
    kill -INT "$serve_pid" 2>/dev/null
    wait "$serve_pid" 2>/dev/null
    echo "-- navcam serve was still running; its log and summary:"
    cat "$serve_dir/serve.log" "$serve_dir/stats.json"
}
trap cleanup EXIT

# ---- drivers ---------------------------------------------------------------
step "loading v4l2loopback, gpio-sim"
modprobe -d $mods v4l2loopback devices=1 video_nr=3 card_label=NavCam exclusive_caps=1 max_buffers=2
modprobe -d $mods gpio-sim
sim_chip navcam 4
echo "gpio-sim: $chip at $sim; v4l2loopback: $(cat /sys/class/video4linux/video3/name)"

trig="{driver: gpio, chip: $chip, line: TRIG, activation: rising_edge, debounce_s: 0.002,
       strobe: {line: STROBE, active: high}}"

start_serve() { # DIR ARGS...
    local d=$1
    shift
    serve_dir=$d
    (cd "$d" && exec "$navcam" serve -j 1 "${small[@]}" "$@" >stats.json 2>serve.log) &
    serve_pid=$!
    listening "$serve_pid" "$d/serve.log" && return
    echo "navcam serve did not start"; cat "$d/serve.log"; return 1
}
stop_serve() { # DIR
    kill -INT "$serve_pid"
    wait "$serve_pid" || { echo "navcam serve exited with $?"; cat "$1/serve.log"; return 1; }
    serve_pid=
}

# ---- A: triggered frames through v4l2loopback, strobe watched ----------------
step "A: $edges edges on TRIG -> frames at the V4L2 reader and in files, strobe on STROBE"
start_serve a --set "serve.trigger=$trig" \
    --set "outputs=[{driver: file, directory: files, pattern: frame_%06llu.fits}, {driver: v4l2, card: NavCam}]"
"$helpers/v4l2_capture" /dev/video3 "$edges" a 60 2 >a/capture.log 2>&1 &
cap_pid=$!
for _ in $(seq 600); do [[ -f a/ready ]] && break; sleep 0.05; done
[[ -f a/ready ]] || { cat a/capture.log a/serve.log; exit 1; }
"$helpers/gpio_sim" watch "$sim/sim_gpio1/value" a/strobe.csv a/stop-watch &
watch_pid=$!
sleep 0.3
# Edges are driven from CPU 0 only: gpio-sim raises them through irq_work on
# the writing CPU, and handle_simple_irq drops an interrupt that arrives
# while the same one is still being handled on another CPU - which happens
# when the host stalls one TCG vCPU mid-handler (both edges of one pulse were
# lost that way once in six runs). One CPU serialises the handlers.
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" "$edges" 400 a/edges.csv
wait "$cap_pid" || { echo "capture failed"; cat a/capture.log a/serve.log; exit 1; }
sleep 0.2
touch a/stop-watch
wait "$watch_pid"
stop_serve a
cat a/capture.log

# ---- B: a trigger storm ----------------------------------------------------
step "B: a storm of 20000 edges while poses stream in"
# 400 poses at 200 Hz of simulation time, streamed in real time.
awk 'BEGIN { for (i = 0; i < 400; i++) printf "%.3f,0,-6000,0,1,0,0,0,1e11,0,0\n", i * 0.005 }' >b/traj.csv
start_serve b --set "serve.trigger=$trig" --set serve.udp_port=5760 \
    --set serve.tcp_port=5761 --set "outputs=[{driver: v4l2, card: NavCam}, {driver: null}]"
"$navcam" replay b/traj.csv --port 5760 >b/replay.log 2>&1 &
replay_pid=$!
grep VmRSS /proc/$serve_pid/status >b/rss_before
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" 20000 0 b/edges.csv
grep VmRSS /proc/$serve_pid/status >b/rss_after
wait "$replay_pid"
sleep 0.5
stop_serve b

# ---- C: a device that fails mid-run ----------------------------------------
# v4l2loopback 0.12.7 has no control device and cannot be unloaded while
# open, so the failure comes from vivid, the kernel's virtual test driver
# (an HDMI output, for progressive frames; NavCam streams to it with mmap):
# its "Disconnect" control makes the device act as unplugged (every call
# returns ENODEV, the node goes away), as a USB video bridge would.
step "C: the V4L2 device disconnects mid-run (vivid), then comes back"
modprobe -d $mods vivid n_devs=1 node_types=0x100 num_outputs=1 output_types=1
vout=
for v in /sys/class/video4linux/video*; do
    [[ $(cat "$v/name") == vivid* ]] && vout=/dev/$(basename "$v")
done
echo "vivid output: $vout"
# Meanwhile the strobe, active low this time, follows the free-run exposures
# (the gpio line is configured but not the trigger source).
"$helpers/gpio_sim" watch "$sim/sim_gpio1/value" c/strobe.csv c/stop-watch &
watch_pid=$!
start_serve c --set serve.mode=freerun --set serve.frame_rate_hz=10 --set sensor.adc_bits=12 \
    --set serve.udp_port=5770 --set serve.tcp_port=5771 \
    --set "serve.trigger={driver: gpio, chip: $chip, line: TRIG, strobe: {line: STROBE, active: low}}" \
    --set "outputs=[{driver: v4l2, device: $vout, reopen_interval_s: 0.5}, {driver: file, directory: files, pattern: frame_%06llu.fits}]"
sleep 3
v4l2-ctl -d "$vout" --set-ctrl disconnect=1 || true
sleep 2
# Unplugged and plugged back: the node reappears once the module reloads.
for _ in $(seq 50); do rmmod vivid 2>/dev/null && break; sleep 0.1; done
modprobe -d $mods vivid n_devs=1 node_types=0x100 num_outputs=1 output_types=1
sleep 3
stop_serve c
touch c/stop-watch
wait "$watch_pid"

# ---- D: another reader: v4l2-ctl, as docs/setup.md's check runs it -----------
step "D: free-run Y16 frames with a metadata row read by v4l2-ctl --stream-mmap"
start_serve d --set serve.mode=freerun --set serve.frame_rate_hz=10 --set sensor.adc_bits=12 \
    --set serve.udp_port=5780 --set serve.tcp_port=5781 \
    --set "outputs=[{driver: v4l2, card: NavCam, metadata_row: 1}, {driver: file, directory: files, pattern: frame_%06llu.fits}]"
# As A's reader does: wait until the device offers capture (exclusive_caps=1).
for _ in $(seq 100); do
    v4l2-ctl -d /dev/video3 --info 2>/dev/null | sed -n '/Device Caps/,$p' | grep -q "Video Capture" && break
    sleep 0.1
done
timeout 60 v4l2-ctl -d /dev/video3 --stream-mmap --stream-count 5 --stream-to d/frames.raw >d/ctl.log 2>&1 ||
    { echo "v4l2-ctl failed"; cat d/ctl.log; }
v4l2-ctl -d /dev/video3 --get-fmt-video >d/fmt.log 2>&1 || true
# A reader sets another frame rate for the device (v4l2loopback keeps one
# for every reader): NavCam sets its own back with its next frame.
v4l2-ctl -d /dev/video3 --set-parm=30 >d/parm_set.log 2>&1 || true
for _ in $(seq 50); do
    v4l2-ctl -d /dev/video3 --get-parm >d/parm.log 2>&1 || true
    grep -q "Frames per second: 10.000" d/parm.log && break
    sleep 0.1
done
stop_serve d

# ---- E: the GPIO chip goes away mid-run ------------------------------------------
# A chip of its own, removed while serve holds its lines (a USB GPIO expander
# unplugged): the kernel then reports the line's event file hung up on every
# poll. Serve says so once, stops polling it (it spun at 100 % CPU), and
# still stops cleanly; the strobe's failed writes are logged once.
step "E: the trigger's GPIO chip removed mid-run"
v4l2_chip=$chip
sim_chip gone 2
start_serve e --set serve.mode=freerun --set serve.frame_rate_hz=2 --set serve.udp_port=5790 --set serve.tcp_port=5791 \
    --set "serve.trigger={driver: gpio, chip: $chip, line: TRIG, strobe: {line: STROBE, active: high}}" \
    --set "outputs=[{driver: null}]"
sleep 1
echo 0 >/sys/kernel/config/gpio-sim/gone/live
sleep 0.5
t0=$(awk '{print $14 + $15}' /proc/$serve_pid/stat)
sleep 2
t1=$(awk '{print $14 + $15}' /proc/$serve_pid/stat)
echo "$((t1 - t0)) $(getconf CLK_TCK)" >e/cpu_ticks.txt
stop_serve e
chip=$v4l2_chip

step "checks"
python3 "$src/tests/vm/check.py" "$out" "$edges"
