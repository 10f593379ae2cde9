#!/usr/bin/env bash
# test_v4l2_setup.sh - the v4l2 output's set-up on a device whose
# VIDIOC_REQBUFS succeeds with no buffers (v4l2_shim.so makes /dev/null such
# a device): `navcam serve` must stop with exit 1 and say so, not report a
# stale errno or run on with the device closed.
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
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
