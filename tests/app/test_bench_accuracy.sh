#!/usr/bin/env bash
# test_bench_accuracy.sh - `navcam bench accuracy` end to end on three of
# its scenes at a small size: the CSV is complete and finite, every scene
# has a Pareto front in each error (relative, DN, sigma), the DN error
# falls with samples, render.quality: auto picks indirect light for the
# crater at low Sun and none for the convex sphere, samples for the
# sphere's limb (its pilots sample the whole pixel) with a DN error under
# the camera's noise, every rock where the boulder cut's bias shows, and
# gnuplot draws the chart; a run that measures nothing leaves the results
# of the one before as they were.
# Usage: test_bench_accuracy.sh NAVCAM TMPDIR
set -u
navcam=$1
tmp=$2
rm -rf "$tmp" && mkdir -p "$tmp"
if ! "$navcam" bench accuracy --quick --size 48 --ref-spp 64 --scene sphere --scene crater \
    --scene rubble -o "$tmp/out" \
    > "$tmp/log" 2>&1; then
  cat "$tmp/log" >&2
  echo "FAIL: navcam bench accuracy exited non-zero" >&2
  exit 1
fi
cat "$tmp/log"
python3 - "$tmp/out" <<'PY'
import csv, math, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/accuracy.csv")))
fail = []
def check(cond, msg):
    if not cond:
        fail.append(msg)
scenes = {}
for r in rows:
    scenes.setdefault(r["scene"], {})[r["method"]] = r
    for k in ("time_ms", "rel_rms", "rel_p95", "dn_rms", "dn_p95", "noise_dn", "sigma_rms", "sigma_p95"):
        v = float(r[k])
        check(math.isfinite(v) and v >= 0, "%s %s: %s = %s" % (r["scene"], r["method"], k, r[k]))
    check(float(r["time_ms"]) > 0, "%s %s: time 0" % (r["scene"], r["method"]))
check(sorted(scenes) == ["crater", "rubble", "sphere"], "scenes %s" % sorted(scenes))
for name, m in scenes.items():
    check(len(m) == (8 if name == "rubble" else 7), "%s: %d methods" % (name, len(m)))
    for col in ("pareto", "pareto_dn", "pareto_sigma"):
        check(any(r[col] == "1" for r in m.values()), "%s: no Pareto front in %s" % (name, col))
    check(float(m["4spp"]["dn_rms"]) < float(m["1spp"]["dn_rms"]), "%s: DN error does not fall with samples" % name)
    check(m["auto"]["chosen"].startswith("spp="), "%s: auto chose '%s'" % (name, m["auto"]["chosen"]))
check("bounces=0" in scenes["sphere"]["auto"]["chosen"], "sphere: auto chose %s" % scenes["sphere"]["auto"]["chosen"])
check("bounces=0" not in scenes["crater"]["auto"]["chosen"], "crater: auto chose %s" % scenes["crater"]["auto"]["chosen"])
# One sample at each pixel's centre sees no limb: auto must ask for samples,
# and land under the camera's noise (k = 0.25 of it, plus the 64-sample
# reference's own error at this size).
spp = int(scenes["sphere"]["auto"]["chosen"].split()[0][4:])
check(spp >= 16, "sphere: auto chose %d samples a pixel" % spp)
for name in ("sphere", "crater"):
    a = scenes[name]["auto"]
    check(float(a["dn_rms"]) <= 0.6 * float(a["noise_dn"]),
          "%s: auto's DN error %s against the camera's noise %s" % (name, a["dn_rms"], a["noise_dn"]))
r = scenes["rubble"]
check("rocks=all" in r["auto"]["chosen"], "rubble: auto chose %s (the boulder cut's bias)" % r["auto"]["chosen"])
check(float(r["auto"]["dn_rms"]) < float(r["16spp b1 soft rocks0"]["dn_rms"]),
      "rubble: auto's DN error %s, 16 spp with every rock %s" % (r["auto"]["dn_rms"], r["16spp b1 soft rocks0"]["dn_rms"]))
png = open(d + "/accuracy.png", "rb").read(8)
check(png == b"\x89PNG\r\n\x1a\n", "accuracy.png is not a PNG")
for f in fail:
    print("FAIL:", f, file=sys.stderr)
print("%d rows checked, %d failures" % (len(rows), len(fail)))
sys.exit(1 if fail else 0)
PY
[ $? -eq 0 ] || exit 1
# A run that measures nothing (its shape files missing) leaves the results
# above as they were (it deleted them), and no temporary.
sum_before=$(cat "$tmp/out/accuracy.csv" "$tmp/out/accuracy_front.csv" | md5sum)
if "$navcam" bench accuracy -o "$tmp/out" --scene bennu --shapes /nonexistent > "$tmp/log2" 2>&1; then
  echo "FAIL: bench accuracy with every scene skipped exited 0" >&2; exit 1
fi
[ "$(cat "$tmp/out/accuracy.csv" "$tmp/out/accuracy_front.csv" | md5sum)" = "$sum_before" ] &&
  [ -z "$(ls -A "$tmp/out" | grep '\.tmp$')" ] ||
  { echo "FAIL: a run that measured nothing changed the results: $(ls -A "$tmp/out")" >&2; exit 1; }
echo "a run that measured nothing left the results as they were"
