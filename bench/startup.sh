#!/usr/bin/env bash
# startup.sh - how long `navcam` takes to start: `navcam --version` (the
# dispatcher alone), and `navcam COMMAND --help` for the commands (the
# dispatcher, exec, and the command's libraries loaded). Median of N runs.
# Last line: startup_version_ms= startup_render_help_ms= startup_serve_help_ms= (target: version under 30 ms)
# Usage: bench/startup.sh BUILD_DIR [N]
set -euo pipefail
navcam=$1/navcam
n=${2:-41}
median_ms() {
  local t=()
  for _ in $(seq "$n"); do
    local s e
    s=$(date +%s%N)
    "$@" >/dev/null
    e=$(date +%s%N)
    t+=($(( (e - s) / 1000 )))
  done
  printf '%s\n' "${t[@]}" | sort -n | sed -n "$(( (n + 1) / 2 ))p" | awk '{printf "%.2f", $1 / 1000}'
}
v=$(median_ms "$navcam" --version)
r=$(median_ms "$navcam" render --help)
b=$(median_ms "$navcam" brdf --help)
s=$(median_ms "$navcam" serve --help)
echo "start-up, median of $n runs: navcam --version $v ms; render --help $r ms; brdf --help $b ms; serve --help $s ms"
echo "startup_version_ms=$v startup_render_help_ms=$r startup_serve_help_ms=$s"
