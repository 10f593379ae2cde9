#!/usr/bin/env bash
# freerun.sh - `navcam serve` in free-run on the default scene (null output)
# at the rates the real-time targets name, as a lab runs it:
#   1. 1024x1024 at 10 Hz (the default camera);
#   2. 512x512 at 30 Hz, the same view at half the resolution (11 um pixels:
#      the same field of view, the body about 212 px across);
#   3. 512x512 at 30 Hz, a crop of the default camera (5.5 um pixels: the
#      body still about 425 px across, as many body pixels as at 1024x1024);
#   4. case 1 with a rolling shutter (20 us a row: the frame rendered in
#      bands, each row at its own time; docs/camera.md);
#   5. case 1 with the camera turning at 0.1 rad/s (the motion smear's
#      time samples in the 2 ms exposure: 2 in docs/camera.md's run).
# One line per case from the emulator's own statistics (fps delivered,
# drops by reason, latency from exposure end to the outputs, render plus
# camera model time), then the last line:
#   fps_1024_10hz= fps_512_30hz= fps_512crop_30hz= latency_p99_ms_1024= latency_p99_ms_512=
#   fps_1024_rolling= fps_1024_turning=
# The pose listeners take NAVCAM_BENCH_PORT and the next port (default
# 6850), not serve's defaults, so that a running emulator does not stop it.
# Usage: bench/freerun.sh BUILD_DIR [SECONDS]
set -euo pipefail
navcam=$1/navcam
secs=${2:-10}
port=${NAVCAM_BENCH_PORT:-6850}
run() { # label size rate pitch [--set KEY=VALUE ...]
  local json label=$1 size=$2 rate=$3 pitch=$4
  shift 4
  json=$("$navcam" serve --set serve.mode=freerun --set serve.frame_rate_hz="$rate" \
    --set camera.width_px="$size" --set camera.height_px="$size" --set camera.pixel_pitch_m="$pitch" \
    --set serve.udp_port="$port" --set serve.tcp_port=$((port + 1)) "$@" \
    --set 'outputs=[{driver: null}]' --set serve.stats_interval_s=0 -t "$secs" 2>/dev/null | tail -1)
  python3 - "$label" "$json" <<'EOF'
import json, sys
d = json.loads(sys.argv[2])
drops = {k: v for k, v in d["dropped"].items() if v and k != "shutdown"}
print(f"{sys.argv[1]}: {d['fps']:.2f} fps delivered (resulting rate {d['resulting_frame_rate_hz']:.2f} Hz), "
      f"drops {sum(drops.values())} {drops or ''}, latency p50 {d['latency_p50_ms']:.1f} ms p99 "
      f"{d['latency_p99_ms']:.1f} ms, render+camera p50 {d['render_camera_p50_ms']:.1f} ms p99 "
      f"{d['render_camera_p99_ms']:.1f} ms", file=sys.stderr)
print(f"{d['fps']:.2f} {d['latency_p99_ms']:.1f}")
EOF
}
read -r f1 l1 <<<"$(run "1024x1024 at 10 Hz" 1024 10 5.5e-6)"
read -r f2 l2 <<<"$(run "512x512 at 30 Hz, same view (11 um pixels)" 512 30 1.1e-5)"
read -r f3 _ <<<"$(run "512x512 at 30 Hz, crop (5.5 um pixels)" 512 30 5.5e-6)"
read -r f4 _ <<<"$(run "1024x1024 at 10 Hz, rolling shutter (20 us a row)" 1024 10 5.5e-6 \
  --set sensor.shutter=rolling --set sensor.line_time_s=2e-5)"
read -r f5 _ <<<"$(run "1024x1024 at 10 Hz, turning at 0.1 rad/s" 1024 10 5.5e-6 \
  --set 'camera.angular_velocity_rad_s=[0, 0.1, 0]')"
echo "fps_1024_10hz=$f1 fps_512_30hz=$f2 fps_512crop_30hz=$f3 latency_p99_ms_1024=$l1 latency_p99_ms_512=$l2" \
  "fps_1024_rolling=$f4 fps_1024_turning=$f5"
