#!/usr/bin/env bash
# guest_usb.sh - runs inside the test guest (vm.sh run): NavCam's `usb`
# trigger driver against the reference adapter (adapters/usb-trigger), both
# in this guest: the adapter is a FunctionFS gadget on dummy_hcd reading a
# gpio-sim line, NavCam reaches it through libusb on the host side of the
# same virtual bus, as it would through a cable. udevd runs (libusb's
# hot-plug events come from it) with NavCam's udev rule, and `navcam serve`
# runs as an unprivileged user in group plugdev.
# Checks are in check_usb.py; the benchmark line is printed at the end.
#
# Usage (in the guest): guest_usb.sh OUTDIR NAVCAM HELPERDIR SRCDIR ADAPTER [EDGES]
set -euo pipefail
out=$1 navcam=$2 helpers=$3 src=$4 adapter=$5
edges=${6:-12}
mods=/run/vm/root
cd "$out"
rm -rf a b c d e && mkdir -p a b c d e

. "$(dirname "$0")/guest_lib.sh"
trap 'echo "guest_usb.sh: line $LINENO: $BASH_COMMAND failed"' ERR
serve_pid= serve_dir= adapter_pid=
cleanup() {
    if [[ -n $serve_pid ]]; then
        kill -INT "$serve_pid" 2>/dev/null
        wait "$serve_pid" 2>/dev/null
        echo "-- navcam serve was still running; its log and summary:"
        cat "$serve_dir/serve.log" "$serve_dir/stats.json"
    fi
    [[ -z $adapter_pid ]] || { kill -INT "$adapter_pid" 2>/dev/null; wait "$adapter_pid" 2>/dev/null; cat "$out/adapter.log"; }
}
trap cleanup EXIT

# ---- drivers, udev, the adapter ---------------------------------------------
step "starting udevd; loading gpio-sim, v4l2loopback, dummy_hcd, libcomposite, usb_f_fs"
# NavCam's rule, where udevd reads rules at run time (the root is read-only).
# udevd first, so that it gives every device node its group.
mkdir -p /run/udev/rules.d
cp "$src/udev/70-navcam-usb-trigger.rules" "$src/udev/99-navcam.rules" /run/udev/rules.d/
/lib/systemd/systemd-udevd --daemon
modprobe -d $mods gpio-sim
modprobe -d $mods v4l2loopback devices=1 video_nr=3 card_label=NavCam exclusive_caps=1 max_buffers=2
modprobe -d $mods dummy_hcd
modprobe -d $mods libcomposite
modprobe -d $mods usb_f_fs
sim_chip adapter 2
udc=$(ls /sys/class/udc)
echo "gpio-sim: $chip; UDC: $udc"

step "the reference adapter: gadget, FunctionFS, navcam-usb-adapter on $chip TRIG/STROBE"
ffs=/run/navcam-usb-adapter
"$src/adapters/usb-trigger/navcam-usb-gadget.sh" setup --ffs $ffs --serial NC-TEST-1
gadget=/sys/kernel/config/usb_gadget/navcam
# Its clock 1000.5 s ahead of the guest's and 150 ppm fast: NavCam must map
# it, as it would a board's own clock.
"$adapter" --ffs $ffs --gadget $gadget --udc "$udc" --chip "$chip" --input TRIG --strobe STROBE \
    --clock-offset-s 1000.5 --clock-drift-ppm 150 2>adapter.log &
adapter_pid=$!
dev=
for _ in $(seq 200); do
    for d in /sys/bus/usb/devices/*; do
        [[ -f $d/idVendor && $(cat "$d/idVendor") == 1209 ]] && dev=$d
    done
    [[ -n $dev ]] && break
    sleep 0.05
done
[[ -n $dev ]] || { echo "the adapter did not enumerate"; cat adapter.log; exit 1; }
node=/dev/bus/usb/$(printf %03d "$(cat "$dev/busnum")")/$(printf %03d "$(cat "$dev/devnum")")
# (udevadm settle declines to run in a chroot: wait for the rule's effect)
for _ in $(seq 100); do [[ $(stat -c %G "$node" 2>/dev/null) == plugdev ]] && break; sleep 0.05; done
for _ in $(seq 100); do [[ $(stat -c %G /dev/video3 2>/dev/null) == video ]] && break; sleep 0.05; done
echo "adapter enumerated: $dev ($(cat "$dev/product"), serial $(cat "$dev/serial")), node $node: $(stat -c '%G %a' "$node")"
stat -c '%G %a' "$node" >udev_node.txt
# 99-navcam.rules: the loopback device's stable name and group
echo "$(readlink /dev/navcam0) $(stat -c '%G %a' /dev/video3)" >>udev_node.txt

# A GPIO line named without its chip, as a user who may open no chip (99-navcam.rules gives group gpio
# access; here nobody is not in it): libgpiod must open every chip to search them, and the error says so.
mkdir -p /run/tmp/gpio_denied && chmod 777 /run/tmp/gpio_denied
(cd /run/tmp/gpio_denied && setpriv --reuid=65534 --regid=65534 --groups=46,44 -- "$navcam" serve -j 1 "${small[@]}" \
    --set serve.mode=trigger --set "serve.trigger={driver: gpio, line: TRIG}" --set "outputs=[{driver: null}]") \
    >gpio_denied.log 2>&1 || echo "exit $?" >>gpio_denied.log

adapter_stats() { # FILE: the adapter's counters now
    local n
    n=$(grep -c 'stats {' adapter.log || true)
    kill -USR1 "$adapter_pid"
    for _ in $(seq 100); do
        [[ $(grep -c 'stats {' adapter.log || true) -gt $n ]] && break
        sleep 0.02
    done
    grep 'stats {' adapter.log | tail -1 | sed 's/.*stats //' >"$1"
}

trig="{driver: usb, id: '1209:0001', serial: NC-TEST-1, input: 0, strobe_output: 0, activation: rising_edge,
       debounce_s: 0.002}"
# navcam serve as nobody in groups plugdev and video: the udev rule is what
# lets it open the adapter. It works in /run/tmp (a tmpfs: the 9p share
# cannot give it files of its own), and its results are copied out.
start_serve() { # DIR ARGS...
    local d=$1 w=/run/tmp/$1
    shift
    serve_dir=$d
    rm -rf "$w" && mkdir -p "$w" && chmod 777 "$w"
    (cd "$w" && exec setpriv --reuid=65534 --regid=65534 --groups=46,44 -- "$navcam" serve -j 1 "${small[@]}" "$@" \
        >stats.json 2>serve.log) &
    serve_pid=$!
    listening "$serve_pid" "$w/serve.log" && return
    cp -r "$w/." "$d/"
    echo "navcam serve did not start"; cat "$d/serve.log"; return 1
}
stop_serve() { # DIR
    local rc=0
    kill -INT "$serve_pid"
    wait "$serve_pid" || rc=$?
    serve_pid=
    cp -r "/run/tmp/$1/." "$1/"
    [[ $rc == 0 ]] || { echo "navcam serve exited with $rc"; cat "$1/serve.log"; return 1; }
}
wait_log() { # DIR TEXT: until serve.log says TEXT (10 s)
    for _ in $(seq 200); do
        grep -q "$2" "/run/tmp/$1/serve.log" && return
        sleep 0.05
    done
    echo "serve.log never said '$2'"; cat "/run/tmp/$1/serve.log"; return 1
}

# ---- A: edges through USB -> frames, strobe watched ---------------------------
step "A: $edges edges on the adapter's TRIG -> frames at the V4L2 reader and in files, strobe on STROBE"
start_serve a --set "serve.trigger=$trig" \
    --set "outputs=[{driver: file, directory: files, pattern: frame_%06llu.fits}, {driver: v4l2, card: NavCam}]"
"$helpers/v4l2_capture" /dev/video3 "$edges" a 60 2 >a/capture.log 2>&1 &
cap_pid=$!
for _ in $(seq 600); do [[ -f a/ready ]] && break; sleep 0.05; done
[[ -f a/ready ]] || { cat a/capture.log; exit 1; }
"$helpers/gpio_sim" watch "$sim/sim_gpio1/value" a/strobe.csv a/stop-watch &
watch_pid=$!
sleep 1 # the clock map's first exchanges
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" "$edges" 400 a/edges.csv
wait "$cap_pid" || { echo "capture failed"; cat a/capture.log; exit 1; }
sleep 0.2
touch a/stop-watch
wait "$watch_pid"
stop_serve a
cat a/capture.log

# ---- B: a storm of 20000 pulses ----------------------------------------------
step "B: a storm of 20000 pulses through USB"
start_serve b --set "serve.trigger=$trig" --set serve.udp_port=5760 --set serve.tcp_port=5761 \
    --set "outputs=[{driver: null}]"
sleep 0.5
adapter_stats b/adapter_before.json
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" 20000 0 b/edges.csv
sleep 2 # the last messages through the bus and the queue
adapter_stats b/adapter_after.json
stop_serve b

# ---- C: unplugged mid-run, plugged again ---------------------------------------
step "C: the adapter unplugged (gadget unbound) mid-run, then plugged again"
start_serve c --set "serve.trigger=$trig" --set serve.udp_port=5770 --set serve.tcp_port=5771 \
    --set "outputs=[{driver: file, directory: files, pattern: frame_%06llu.fits}]"
sleep 1
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" 6 300 c/edges1.csv
echo "" >$gadget/UDC
wait_log c "unplugged"
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" 3 300 c/edges_unplugged.csv
echo "$udc" >$gadget/UDC
wait_log c "reopened after"
sleep 1
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" 6 300 c/edges2.csv
sleep 0.5
stop_serve c

# ---- D: a transfer error with the adapter still there ---------------------------
# A read of FunctionFS's IN endpoint file halts the endpoint: NavCam's queued
# IN transfers end with a stall, as a device's firmware fault would make them.
step "D: the adapter's IN endpoint stalled mid-run: the session ends and starts again"
start_serve d --set "serve.trigger=$trig" --set serve.udp_port=5780 --set serve.tcp_port=5781 \
    --set "outputs=[{driver: file, directory: files, pattern: frame_%06llu.fits}]"
sleep 1
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" 4 300 d/edges1.csv
sleep 0.3
dd if=$ffs/ep1 of=/dev/null bs=64 count=1 >d/halt.log 2>&1 || true
wait_log d "the session ended on a transfer error (a stall"
wait_log d "reopened after"
sleep 1
taskset -c 0 "$helpers/gpio_sim" edges "$sim/sim_gpio0/pull" 4 300 d/edges2.csv
sleep 0.5
stop_serve d

# ---- E: a full packet of requests in one transfer --------------------------------
step "E: a full OUT packet of TIME requests in one transfer (no navcam serve): every reply at once"
"$helpers/usb_burst" 0.5 >e/burst.log 2>&1 && echo 0 >e/status || echo $? >e/status
cat e/burst.log

kill -INT "$adapter_pid"
wait "$adapter_pid" || true
adapter_pid=
"$src/adapters/usb-trigger/navcam-usb-gadget.sh" teardown --ffs $ffs

step "checks"
python3 "$src/tests/vm/check_usb.py" "$out" "$edges"
