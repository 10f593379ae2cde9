#!/usr/bin/env bash
# freerun.sh - `navcam serve` in free-run on the default scene (null output)
# at the rates the real-time targets name, as a lab runs it:
#   1. 1024x1024 at 10 Hz (the default camera);
#   2. 512x512 at 30 Hz, the same view at half the resolution (11 um pixels:
#      the same field of view, the body about 212 px across);
#   3. 512x512 at 30 Hz, a crop of the default camera (5.5 um pixels: the
#      body still about 425 px across, as many body pixels as at 1024x1024).
# One line per case from the emulator's own statistics (fps delivered,
# drops by reason, latency from exposure end to the outputs, render plus
# camera model time), then the last line:
#   fps_1024_10hz= fps_512_30hz= fps_512crop_30hz= latency_p99_ms_1024= latency_p99_ms_512=
# Usage: bench/freerun.sh BUILD_DIR [SECONDS]
set -euo pipefail
navcam=$1/navcam
secs=${2:-10}
run() { # label size rate pitch
  local json
  json=$("$navcam" serve --set serve.mode=freerun --set serve.frame_rate_hz="$3" \
    --set camera.width_px="$2" --set camera.height_px="$2" --set camera.pixel_pitch_m="$4" \
    --set 'outputs=[{driver: null}]' --set serve.stats_interval_s=0 -t "$secs" 2>/dev/null | tail -1)
  python3 - "$1" "$json" <<'EOF'
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
echo "fps_1024_10hz=$f1 fps_512_30hz=$f2 fps_512crop_30hz=$f3 latency_p99_ms_1024=$l1 latency_p99_ms_512=$l2"
