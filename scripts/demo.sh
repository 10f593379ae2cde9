#!/usr/bin/env bash
# The main job on the built-in default scene: a short approach to a procedural
# asteroid, from 16 km to 3 km, rendered to EXR (radiance, float32) and a PNG
# preview per frame. No data download, no hardware.
# Usage: scripts/demo.sh NAVCAM_BINARY OUTDIR
set -euo pipefail
navcam=${1:?usage: demo.sh NAVCAM OUTDIR}
out=${2:?usage: demo.sh NAVCAM OUTDIR}
mkdir -p "$out"
frames=8
for i in $(seq 0 $((frames - 1))); do
  # Range shrinks geometrically; a slow lateral drift keeps the view alive.
  pos=$(awk -v i="$i" -v n="$frames" 'BEGIN {
    d = 16000 * exp(log(3000 / 16000) * i / (n - 1));
    printf "[%.3f, %.3f, %.3f]", 0.08 * d, -d, 0.03 * d }')
  f=$(printf "%s/approach_%03d" "$out" "$i")
  "$navcam" render -o "$f.exr" --set "camera.position_m=$pos" >/dev/null
  "$navcam" render -o "$f.png" --set "camera.position_m=$pos" | head -1
done
echo
echo "demo: $frames frames of the approach are in $out/:"
echo "  approach_*.exr  radiance in W m^-2 sr^-1 (float32; pose, Sun and units in the metadata)"
echo "  approach_*.png  16-bit linear previews (scale in the metadata: navcam:preview_scale)"
