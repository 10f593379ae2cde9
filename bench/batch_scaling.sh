#!/usr/bin/env bash
# Throughput of navcam batch against the number of Slurm array tasks
# (docs/batch.md): the default scene at 1024x1024 (DN frames, geometry
# planes and lists), FRAMES poses of an approach, on a single-node Slurm
# started here (scripts/slurm-local.sh). Each configuration starts from an
# empty directory; the time is from submission until squeue shows the job
# gone (polled every 0.2 s, so sbatch --wait's own polling does not count).
# Last line per configuration:
#   tasks= threads_per_task= frames= seconds= frames_per_hour=
# usage: bench/batch_scaling.sh BUILD_DIR [FRAMES]
set -euo pipefail
build=$(cd "${1:?build directory}" && pwd)
frames=${2:-24}
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d /tmp/nc_bench_batch.XXXXXX)
slurm=$(mktemp -d /tmp/nc_slurm.XXXXXX)
trap '"$src/scripts/slurm-local.sh" stop "$slurm"; rm -rf "$work"' EXIT
export SLURM_CONF
SLURM_CONF=$("$src/scripts/slurm-local.sh" start "$slurm")
python3 - "$frames" > "$work/traj.csv" <<'PY'
import math, sys
n = int(sys.argv[1])
print("t_s,cam_x_m,cam_y_m,cam_z_m,q_w,q_x,q_y,q_z,sun_x,sun_y,sun_z")
for i in range(n):
    d = 6000 - 3000 * i / max(1, n - 1)
    a = 0.05 * i
    p = (d * math.sin(a), -d * math.cos(a), 0.0)
    z = [-c / d for c in p]
    x = [z[1], -z[0], 0.0]
    y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]]
    m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
    w = math.sqrt(1 + m[0][0] + m[1][1] + m[2][2]) / 2
    q = (w, (m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w), (m[1][0] - m[0][1]) / (4 * w))
    print("%d,%.6f,%.6f,%.6f,%.12f,%.12f,%.12f,%.12f,0.643,-0.766,0" % ((i,) + p + q))
PY
ncpu=$(nproc)
run() { # tasks threads
  local tasks=$1 threads=$2 out="$work/out_$1_$2"
  mkdir -p "$work/logs"
  local t0 t1 id
  t0=$(date +%s.%N)
  id=$(NAVCAM="$build/navcam" sbatch --parsable --array=0-$((tasks - 1)) --cpus-per-task="$threads" \
        -D "$work/logs" "$src/examples/slurm/navcam_batch.sbatch" "$work/traj.csv" "$out")
  while squeue -h -j "$id" 2>/dev/null | grep -q .; do sleep 0.2; done
  t1=$(date +%s.%N)
  local n
  n=$(ls "$out"/frame_*.json 2>/dev/null | wc -l)
  [ "$n" -eq "$frames" ] || { echo "only $n of $frames frames" >&2; cat "$work"/logs/* >&2; exit 1; }
  python3 -c "
t = $t1 - $t0
print('tasks=%d threads_per_task=%d frames=%d seconds=%.1f frames_per_hour=%.0f' % ($tasks, $threads, $n, t, $n * 3600 / t))"
  rm -rf "$work/logs"
}
run 1 "$ncpu"
[ "$ncpu" -ge 2 ] && run 2 1
run 4 1
diff -r "$work/out_1_$ncpu" "$work/out_4_1" > /dev/null && echo "the 1-task and 4-task datasets are identical"
