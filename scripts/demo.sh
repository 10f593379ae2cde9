#!/usr/bin/env bash
# The main job on the built-in default scene: `navcam serve` in lock-step,
# fed by `navcam replay` with the built-in approach trajectory (16 km to 3 km,
# 8 poses); frames (12-bit DN in 16-bit PNG) and their JSON-lines metadata
# land under OUTDIR, then the emulator prints its statistics and stops.
# No data download, no hardware.
# Usage: scripts/demo.sh NAVCAM_BINARY OUTDIR
set -euo pipefail
navcam=$(readlink -f "${1:?usage: demo.sh NAVCAM OUTDIR}")
out=${2:?usage: demo.sh NAVCAM OUTDIR}
mkdir -p "$out"
udp=${NAVCAM_DEMO_UDP:-5750}
tcp=${NAVCAM_DEMO_TCP:-5751}
"$navcam" serve --set serve.mode=lockstep --set serve.udp_port="$udp" --set serve.tcp_port="$tcp" \
  --set "outputs=[{driver: file, directory: $out}]" --max-frames 8 --stats-json "$out/stats.json" > /dev/null &
serve=$!
trap 'kill $serve 2>/dev/null || true' EXIT
# Wait for the emulator to listen (it builds the scene first), then replay.
for _ in $(seq 300); do
  (exec 3<>"/dev/tcp/127.0.0.1/$tcp") 2>/dev/null && break
  sleep 0.1
done
"$navcam" replay builtin:approach --lockstep --port "$tcp"
wait $serve
trap - EXIT
echo
echo "demo: the emulator rendered the approach in lock-step; in $out/:"
echo "  frame_*.png    digitised frames (12-bit DN, 16-bit PNG; pose, exposure and"
echo "                 camera metadata inside)"
echo "  frames.jsonl   one line per frame: trigger and exposure times, the pose used"
echo "  stats.json     the emulator's statistics"
