#!/usr/bin/env bash
# bench_edge_to_frame.sh BUILD_DIR [EDGES] - trigger edge to frame available
# at a V4L2 reader, inside the qemu guest of tests/vm, through a GPIO line
# (gpio-sim edge -> navcam serve -> v4l2loopback -> mmap capture reader) and
# through USB (gpio-sim edge -> the reference USB trigger adapter, a
# FunctionFS gadget -> dummy_hcd -> navcam serve's usb driver -> ...), 64x48
# frames with 50 ms exposures, one edge every 400 ms. The guest is emulated
# (TCG): the figures show where the time goes, they are not what real
# hardware gives.
# Needs `scripts/install-deps.sh --test` (qemu, kernel headers, v4l2loopback-dkms).
# Last lines: edge_to_frame_p50_ms=... p99_ms=... (GPIO), then
# edge_to_frame_usb_p50_ms=... p99_ms=... (USB)
set -euo pipefail
build=$(cd "${1:?usage: bench_edge_to_frame.sh BUILD_DIR [EDGES]}" && pwd)
edges=${2:-40}
src=$(cd "$(dirname "$0")/.." && pwd)
out=$build/bench_edge_to_frame
helpers=$build/tests
[[ -x $helpers/v4l2_capture && -x $helpers/gpio_sim ]] || { echo "build $build has no tests/v4l2_capture (needs libgpiod)" >&2; exit 1; }
"$src/tests/vm/vm.sh" run "$src/tests/vm/guest_v4l2_gpio.sh" "$out" 600 "$build/navcam" "$helpers" "$src" "$edges"
[[ -x $build/navcam-usb-adapter ]] || { echo "build $build has no navcam-usb-adapter (needs libusb and libgpiod)" >&2; exit 1; }
"$src/tests/vm/vm.sh" run "$src/tests/vm/guest_usb.sh" "$out-usb" 600 "$build/navcam" "$helpers" "$src" \
    "$build/navcam-usb-adapter" "$edges"
grep -a "edge to frame at the V4L2 reader" "$out/console.log" | tr -d '\r'
grep -a "edge to frame at the V4L2 reader through USB" "$out-usb/console.log" | tr -d '\r'
grep -a "^edge_to_frame_p50_ms=" "$out/console.log" | tr -d '\r'
grep -a "^edge_to_frame_usb_p50_ms=" "$out-usb/console.log" | tr -d '\r'
