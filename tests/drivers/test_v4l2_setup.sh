#!/usr/bin/env bash
# test_v4l2_setup.sh - the v4l2 output's set-up on a device whose
# VIDIOC_REQBUFS succeeds with no buffers (v4l2_shim.so makes /dev/null such
# a device): `navcam serve` must stop with exit 1 and say so, not report a
# stale errno or run on with the device closed. Then, with the shim's
# NAVCAM_SHIM_UNPLUG, a device that is unplugged for 2.5 s: the failure and
# the failed reopenings say why, the reopening counts that outage's frames;
# and with reopen_limit the output says once that it gave up; the frame
# interval asked for, and a format held at another width.
# Usage: test_v4l2_setup.sh NAVCAM SHIM
set -u
navcam=$1 shim=$2
pass=0 fail=0
# The shim is not instrumented; a sanitizer build must let it load first.
export ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0
out=$(LD_PRELOAD=$shim timeout 60 "$navcam" serve --set camera.width_px=64 --set camera.height_px=48 \
  --set serve.udp_port=0 --set serve.tcp_port=0 --max-seconds 5 \
  --set "outputs=[{driver: v4l2, device: /dev/null, io: mmap}]" 2>&1)
rc=$?
if [ $rc -eq 1 ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL: exit $rc, want 1: $out"; fi
case "$out" in
  *"/dev/null (card 'No Buffers'): VIDIOC_REQBUFS granted no buffers"*) pass=$((pass + 1)) ;;
  *) fail=$((fail + 1)); echo "FAIL: the message does not say the device granted no buffers: $out" ;;
esac
expect() { # what, text, pattern
  case "$2" in
    *$3*) pass=$((pass + 1)) ;;
    *) fail=$((fail + 1)); echo "FAIL: $1: no '$3' in: $2" ;;
  esac
}
unplugged() { # extra output keys
  NAVCAM_SHIM_UNPLUG=1 LD_PRELOAD=$shim timeout 60 "$navcam" serve --set camera.width_px=64 \
    --set camera.height_px=48 --set serve.udp_port=0 --set serve.tcp_port=0 --max-seconds 5 \
    --set serve.mode=freerun --set serve.frame_rate_hz=10 \
    --set "outputs=[{driver: v4l2, device: /dev/null, reopen_interval_s: 0.05$1}]" 2>&1
}
out=$(unplugged "")
expect unplug "$out" "/dev/null (card 'Unplugged') failed: write: No such device; closed, looking for it again every 0.05 s"
expect "failed reopening" "$out" "reopening failed (attempt *): v4l2 output: /dev/null: No such file or directory"
# the outage's frames only (2.5 s at 10 Hz), not the EAGAIN frame before
# it; every frame while the device is away tries to reopen it (0.05 s), so
# the error the log shows a second after the first is a failed reopening
n=$(printf '%s\n' "$out" | sed -n "s/.*(card 'Unplugged') reopened after \([0-9]*\) lost frames.*/\1/p")
if [ -n "$n" ] && [ "$n" -ge 18 ] && [ "$n" -le 30 ]; then pass=$((pass + 1)); else
  fail=$((fail + 1)); echo "FAIL: reopened after '$n' lost frames, want the outage's 25 to 30: $out"; fi
# the frame interval asked for, to 5e-7 of the rate (1000/2 s for 0.0015 Hz until session 67)
expect interval "$(unplugged ", frame_rate_hz: 0.0015")" "frame interval 10000/15 s (0.0015 Hz)"
# a format held at another width: the message names both causes (only max_width until session 67)
expect "held width" "$(NAVCAM_SHIM_WIDTH=32 unplugged "")" "the driver set 32x48, the camera has 64x48 (v4l2loopback: \
max_width or max_height, or a reader still streaming, or keep_format=1, holds the last producer's format)"
out=$(unplugged ", reopen_limit: 2")
expect "reopen_limit" "$out" "2 attempts to reopen it failed (reopen_limit): given up, its frames are lost from now on"
expect "reopen_limit" "$out" "not looked for any more (reopen_limit)"
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
