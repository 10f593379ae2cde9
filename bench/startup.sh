#!/usr/bin/env bash
# startup.sh - how long `navcam` takes to start: `navcam --version` (the
# dispatcher alone), `navcam COMMAND --help` for the commands (the
# dispatcher, exec, and the command's libraries loaded), and a tiny render
# written to FITS and to PNG: the difference is what loading OpenImageIO
# (the module navcam-oiio.so, loaded only for EXR, TIFF and PNG files)
# costs. Median of N runs.
# Last line: startup_version_ms= startup_render_help_ms= startup_serve_help_ms= startup_oiio_ms=
# (target: version under 30 ms)
# Usage: bench/startup.sh BUILD_DIR [N]
set -euo pipefail
navcam=$1/navcam
n=${2:-41}
median_ms() {
  local t=()
  for _ in $(seq "$n"); do
    local s e
    s=$(date +%s%N)
    "$@" >/dev/null 2>&1
    e=$(date +%s%N)
    t+=($(( (e - s) / 1000 )))
  done
  printf '%s\n' "${t[@]}" | sort -n | sed -n "$(( (n + 1) / 2 ))p" | awk '{printf "%.2f", $1 / 1000}'
}
v=$(median_ms "$navcam" --version)
r=$(median_ms "$navcam" render --help)
b=$(median_ms "$navcam" brdf --help)
s=$(median_ms "$navcam" serve --help)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
tiny=(--set camera.width_px=16 --set camera.height_px=16 --set bodies.0.shape.subdivisions=2 -j 1)
f=$(median_ms "$navcam" render -o "$tmp/t.fits" "${tiny[@]}")
p=$(median_ms "$navcam" render -o "$tmp/t.png" "${tiny[@]}")
o=$(awk -v p="$p" -v f="$f" 'BEGIN {printf "%.2f", p - f}')
echo "start-up, median of $n runs: navcam --version $v ms; render --help $r ms; brdf --help $b ms; serve --help $s ms"
echo "a 16x16 render to FITS $f ms, to PNG $p ms: OpenImageIO's module $o ms"
echo "startup_version_ms=$v startup_render_help_ms=$r startup_serve_help_ms=$s startup_oiio_ms=$o"
