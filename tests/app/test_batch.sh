#!/usr/bin/env bash
# navcam batch (docs/batch.md) through its command line: a dataset of a
# trajectory with its ground truth; the same bytes from shards in any order
# and thread count; resuming after a crash; SUM-like trajectory rows; and a
# Slurm job array of 4 tasks on a single-node cluster started here (slurmctld,
# slurmd, munge from Debian): its merged output identical to one process.
# usage: test_batch.sh NAVCAM TMPDIR SOURCE_DIR
set -euo pipefail
navcam=$1
tmp=$2
src=$3
rm -rf "$tmp"
mkdir -p "$tmp"
cd "$tmp"
fail() { echo "FAIL: $*" >&2; exit 1; }

# A small camera on the default asteroid (craters), with boulders, 8 poses.
scene=(--set camera.width_px=192 --set camera.height_px=160 --set render.samples_per_pixel=1
       --set 'bodies.0.boulders={density_per_km2: 4000, slope: 2.2, min_diameter_m: 2, max_diameter_m: 20}')
python3 - <<'PY'
import math
with open("traj.csv", "w") as f:
    f.write("t_s,cam_x_m,cam_y_m,cam_z_m,q_w,q_x,q_y,q_z,sun_x,sun_y,sun_z\n")
    for i in range(8):
        a = 0.2 * i
        p = (2500 * math.sin(a), -2500 * math.cos(a), 300.0)
        # camera looking at the origin, +z up in the image: X = Z x up, Y = Z x X
        n = math.sqrt(sum(v * v for v in p))
        z = [-c / n for c in p]
        x = [z[1], -z[0], 0.0]
        n = math.sqrt(sum(v * v for v in x)); x = [v / n for v in x]
        y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]]
        m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
        w = math.sqrt(max(0.0, 1 + m[0][0] + m[1][1] + m[2][2])) / 2
        q = (w, (m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w), (m[1][0] - m[0][1]) / (4 * w))
        f.write("%d,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.12f,0.643,-0.766,0.1\n" % ((i,) + p + q))
# the same poses as SUM-like rows: SCOBJ = -p (km), CX CY CZ, SZ
with open("traj.csv") as f, open("traj_sum.csv", "w") as g:
    g.write("t_s,scobj_x_km,scobj_y_km,scobj_z_km,cx_x,cx_y,cx_z,cy_x,cy_y,cy_z,cz_x,cz_y,cz_z,sz_x,sz_y,sz_z\n")
    for line in list(f)[1:]:
        v = [float(t) for t in line.split(",")]
        w, x, y, z = v[4:8]
        R = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
             [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
             [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
        cols = [[R[r][c] for r in range(3)] for c in range(3)]
        s = math.sqrt(0.643 ** 2 + 0.766 ** 2 + 0.01)
        g.write(",".join("%.12g" % t for t in [v[0], -v[1] / 1e3, -v[2] / 1e3, -v[3] / 1e3] + cols[0] + cols[1]
                         + cols[2] + [0.643 / s, -0.766 / s, 0.1 / s]) + "\n")
PY

# One process, two threads: the reference.
"$navcam" batch traj.csv -o ref "${scene[@]}" -j 2 > ref.log 2> ref.err || { cat ref.err; fail "batch"; }
grep -q "8 rendered, 0 failed, 0 already done" ref.log || fail "reference: $(tail -1 ref.log)"
for i in 0 7; do
  f=ref/frame_00000$i
  for x in .fits _geometry.fits .json _boulders.csv _craters.csv; do [ -s "$f$x" ] || fail "missing $f$x"; done
done
python3 - <<'PY' || fail "ground truth"
import json, glob
for j in sorted(glob.glob("ref/frame_*.json")):
    d = json.load(open(j))
    assert d["quantity"] == "dn" and d["camera"]["width_px"] == 192, j
    assert d["geometry_planes"][0] == "range_m" and d["geometry_planes"][-1] == "body", j
    assert d["boulders_in_view"] > 0 and d["craters_in_view"] > 0, (j, d["boulders_in_view"], d["craters_in_view"])
    rows = open(j.replace(".json", "_boulders.csv")).read().split("\n")
    assert rows[0] == "body,index,x_m,y_m,z_m,diameter_m,pixels" and len([r for r in rows[1:] if r]) == d["boulders_in_view"]
    head = open(j.replace(".json", "_geometry.fits"), "rb").read(2880 * 3).decode("ascii", "replace")
    cards = [head[i:i + 80] for i in range(0, len(head), 80)]
    assert any(c.startswith("NAXIS3  =                   11") for c in cards), "11 planes"
    assert any(c.startswith("PLANE1  = 'range_m ") for c in cards) and any(c.startswith("PLANE11 = 'body ") for c in cards)
    # the detail used, as in the frame's own metadata (FITS ROCKMIN, LODERR)
    head = open(j.replace(".json", ".fits"), "rb").read(2880 * 4).decode("ascii", "replace")
    card = {head[i:i + 8].strip(): head[i + 10:i + 80].split("/")[0].strip() for i in range(0, len(head), 80)}
    assert float(card["ROCKMIN"]) == d["boulder_min_m"] and float(card["LODERR"]) == d["lod_error_m"], (j, card["ROCKMIN"], d)
    assert d["boulder_mesh_px"] >= 0 and (d["rock_fold_theta_bar_deg"] == -1) == ("ROCKFOLD" not in card), j
print("ground truth ok")
PY

# Shards in another order, one thread each: the same bytes.
for k in 2 0 1; do "$navcam" batch traj.csv -o shards "${scene[@]}" --shard $k/3 -j 1 > /dev/null 2>&1 || fail "shard $k"; done
diff -r ref shards > /dev/null || fail "3 shards in the order 2, 0, 1 differ from one process: $(diff -rq ref shards | head -3)"

# A crash: frame 5's truth and image gone, its lock file and half-written temporaries left, the image writer's
# own named by the crashed process's id (an outside check found those left for good): the rerun gives the
# reference's bytes and files, nothing more.
cp -r ref crashed
rm crashed/frame_000005.json crashed/frame_000005.fits
: > crashed/.frame_000005.lock
head -c 1000 ref/frame_000005.fits > crashed/.frame_000005.tmp.fits
head -c 1000 ref/frame_000005.fits > crashed/..frame_000005.tmp.4242.tmp.fits
echo '{' > crashed/.frame_000005.json.tmp
"$navcam" batch traj.csv -o crashed "${scene[@]}" > resume.log 2>&1 || fail "resume"
grep -q "1 rendered, 0 failed, 7 already done" resume.log || fail "resume: $(tail -1 resume.log)"
diff -r ref crashed > /dev/null || fail "resumed dataset differs from the reference: $(diff -rq ref crashed | head -3)"

# A row another process is rendering (its lock held) is left to it, not
# rendered twice; once the lock is free, a rerun renders it.
cp -r ref busy
rm busy/frame_000002.json
python3 -c "import fcntl, sys, time; f = open(sys.argv[1], 'w'); fcntl.flock(f, fcntl.LOCK_EX)
open(sys.argv[2], 'w').close(); time.sleep(60)" busy/.frame_000002.lock busy.held &
holder=$!
for _ in $(seq 600); do [ -e busy.held ] && break; sleep 0.1; done # a loaded machine starts python slowly
[ -e busy.held ] || fail "busy: the process holding the lock did not start within 60 s"
"$navcam" batch traj.csv -o busy "${scene[@]}" > busy.log 2>&1 || fail "busy: $(cat busy.log)"
kill $holder; wait $holder 2>/dev/null || true
grep -q "0 rendered, 0 failed, 7 already done, 1 being rendered by another process" busy.log || fail "busy: $(tail -1 busy.log)"
"$navcam" batch traj.csv -o busy "${scene[@]}" > busy.log 2>&1 || fail "busy, rerun"
grep -q "1 rendered, 0 failed, 7 already done;" busy.log || fail "busy, rerun: $(tail -1 busy.log)"
diff -r -x '.frame_*' ref busy > /dev/null || fail "the row rendered after the lock was freed differs"

# -o makes missing parents; a configuration error leaves no directory behind.
"$navcam" batch traj.csv -o nest/a/b "${scene[@]}" --shard 0/8 --no-geometry > /dev/null 2>&1 || fail "-o nest/a/b"
[ -s nest/a/b/frame_000000.json ] || fail "-o nest/a/b: no frame"
"$navcam" batch traj.csv -o none/x "${scene[@]}" --set camera.widht_px=3 2> err.txt && fail "a misspelt key accepted"
[ ! -e none ] || fail "a configuration error left the directory none/"

# A row that cannot be rendered (a body too small an angle for the float rays
# at this focal length) is named by row and line; the other rows are rendered
# and the exit status is 1.
printf 't_s,cam_x_m,cam_y_m,cam_z_m,q_w,q_x,q_y,q_z,sun_x,sun_y,sun_z\n0,0,-3000,0,0.70710678,-0.70710678,0,0,1,-1,0
1,0,-2e9,0,0.70710678,-0.70710678,0,0,1,-1,0\n2,0,-3000,0,0.70710678,-0.70710678,0,0,1,-1,0\n' > far.csv
"$navcam" batch far.csv -o far --no-geometry --set camera.width_px=32 --set camera.height_px=32 \
  --set camera.focal_length_m=100 --set camera.pixel_pitch_m=1e-5 > far.log 2>&1 && fail "a failed row exited 0"
grep -q "^navcam batch: row 1 (line 3): body 'asteroid' is .* px across" far.log || fail "failed row: $(cat far.log)"
grep -q "2 rendered, 1 failed, 0 already done" far.log || fail "failed row: $(tail -1 far.log)"
[ -s far/frame_000002.json ] && [ ! -e far/frame_000001.json ] || fail "failed row: the rows after it not rendered"

# SUM-like rows of the same poses: the same frames (to the pose's rounding).
"$navcam" batch traj_sum.csv -o sum "${scene[@]}" --no-geometry > /dev/null 2>&1 || fail "SUM-like rows"
"$navcam" compare ref/frame_000003.fits sum/frame_000003.fits --fit none > sumcmp.json || fail "compare"
python3 -c "
import json; d = json.load(open('sumcmp.json'))
assert d['relative_error']['p95'] < 0.02 and d['limb_iou'] > 0.99, d
print('SUM-like rows: p95 %.4f, IoU %.4f' % (d['relative_error']['p95'], d['limb_iou']))" || fail "SUM-like rows differ"

# --sumfile: the SUM file's camera (size, intrinsics), each row's pose and Sun.
printf 'EX1\n2020 JAN 15 12:00:00.000\n    96    64    10 65535   NPX, NLN, THRSH\n    0.1D+03    0.475D+02    0.315D+02  MMFL, CTR\n   -4.0    2.0   -1.0  SCOBJ\n    0.4472135955    0.8944271910    0.0  CX\n    0.1951800146   -0.09759000729   -0.9759000729  CY\n   -0.8728715609    0.4364357805   -0.2182178902  CZ\n    0.7990018711    0.5992514033    0.04993761694  SZ\n  20.0   0.0   0.0   0.0  20.0   0.0  K-MATRIX\nEND FILE\n' > cam.SUM
head -2 traj.csv > one.csv
# a camera inside the body (the pose's columns in the wrong order, say): the row is warned of
printf '0,0,-20,0,0.70710678,-0.70710678,0,0,1,0,0\n' > inside.csv
"$navcam" batch inside.csv -o inside --no-geometry --set camera.width_px=32 --set camera.height_px=32 > inside.txt 2>&1 ||
  fail "batch inside.csv"
grep -q "WARNING: row 0 (line 1): .* met its back, inner side: is the camera inside a body (or a mesh wound inward)?" inside.txt ||
  fail "a camera inside the body was not warned of: $(cat inside.txt)"
"$navcam" batch one.csv -o sumcam --sumfile cam.SUM --no-geometry --set render.samples_per_pixel=1 > /dev/null 2>&1 ||
  fail "--sumfile"
python3 -c "
import json; d = json.load(open('sumcam/frame_000000.json')); c = d['camera']; r = open('one.csv').read().split('\n')[1].split(',')
assert (c['width_px'], c['height_px'], c['fx_fy_cx_cy_px']) == (96, 64, [2000, 2000, 46.5, 30.5]), c
assert max(abs(a - float(b)) for a, b in zip(c['position_m'], r[1:4])) < 1e-6, (c, r)
s = [float(v) for v in r[8:11]]; n = sum(v * v for v in s) ** 0.5
assert max(abs(a - b / n) for a, b in zip(d['sun']['direction_body0'], s)) < 1e-9, d['sun']
print('--sumfile: 96x64, fx 2000 px, the row pose')" || fail "--sumfile: not the SUM file's camera with the row's pose"
# render --sumfile on a scene that gives sun.direction (the built-in one): the SUM file's SZ replaces it,
# as docs/compare.md's example runs it
"$navcam" render -o sumr.fits --sumfile cam.SUM --set sun.distance_au=3.6 --set render.samples_per_pixel=1 \
  > sumr.txt 2>&1 || fail "render --sumfile with --set sun.distance_au: $(cat sumr.txt)"
python3 -c "
b = open('sumr.fits', 'rb').read(2880 * 4); cards = [b[i:i + 80].decode('latin-1') for i in range(0, len(b), 80)]
n = {c[:8].strip(): c[10:30].strip() for c in cards if c[:5] == 'NAXIS'}
assert (n['NAXIS1'], n['NAXIS2']) == ('96', '64'), n" || fail "render --sumfile: not the SUM file's size"

# SUM-like rows are in bodies[0]'s frame: with the body moved and turned,
# the camera moves with it and sees the same frame.
"$navcam" batch traj_sum.csv -o sum_moved "${scene[@]}" --no-geometry --set 'bodies.0.position_m=[300,-200,100]' \
  --set 'bodies.0.attitude_q=[0.9238795,0.3826834,0,0]' > /dev/null 2>&1 || fail "SUM-like rows, body moved"
"$navcam" compare sum/frame_000003.fits sum_moved/frame_000003.fits --fit none > movedcmp.json || fail "compare"
python3 -c "
import json; d = json.load(open('movedcmp.json'))
assert d['relative_error']['p95'] < 0.02 and d['limb_iou'] > 0.99, d
print('SUM-like rows, body moved: p95 %.4f, IoU %.4f' % (d['relative_error']['p95'], d['limb_iou']))" ||
  fail "SUM-like rows with bodies[0] moved and turned: the camera did not move with it"

# Stars move with the row's time: proper motion to epoch_jyear + t_s. Sirius
# (-546.0, -1223.1 mas/yr) 100 years on is 133.9 arcsec away: 13.39 px of
# 10 arcsec, the camera still.
printf '064508.92 -164258.0 -000546.0-001223.100379.2 -1.4400.01A0 1            , alp CMa, Sirius\n' > stars.dat
"$navcam" stars index stars.dat -o stars.ncs > /dev/null || fail "stars index"
# `stars info` counts the stars brighter than each whole magnitude: V < N,
# a star of V 2.00 not under 2 (it was counted there before session 63).
printf '100000.00 +100000.0 +000000.0+000000.000000.0 +2.0000.00A0 1            , V two\n' > two.dat
cat stars.dat two.dat > pair.dat
"$navcam" stars index pair.dat -o pair.ncs > /dev/null || fail "stars index of two stars"
"$navcam" stars info pair.ncs > info.txt || fail "stars info"
grep -q "V <  2: 1$" info.txt && grep -q "V <  3: 2$" info.txt || fail "stars info counts: $(cat info.txt)"
python3 - <<'PY'
import math
a, d = math.radians(101.287166667), math.radians(-16.716111111)
z = [math.cos(d) * math.cos(a), math.cos(d) * math.sin(a), math.sin(d)]
x = [z[1], -z[0], 0.0]; n = math.hypot(x[0], x[1]); x = [v / n for v in x]
y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]]
m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
w = math.sqrt(1 + m[0][0] + m[1][1] + m[2][2]) / 2
q = (w, (m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w), (m[1][0] - m[0][1]) / (4 * w))
with open("sirius.csv", "w") as f:
    for t in (0, 100 * 365.25 * 86400):
        f.write("%d,1e7,0,0,%.15f,%.15f,%.15f,%.15f,1,0,0\n" % ((t,) + q))
PY
"$navcam" batch sirius.csv -o sirius -q electrons -e 0.01 --no-geometry --set 'stars={catalogue: stars.ncs}' \
  --set camera.width_px=64 --set camera.height_px=64 --set camera.fx_px=20626.5 --set camera.fy_px=20626.5 \
  --set camera.cx_px=31.5 --set camera.cy_px=31.5 --set camera.focal_length_m=null --set camera.pixel_pitch_m=null \
  --set sensor.pixel_pitch_m=5.5e-6 --set 'optics.psf={type: none}' > /dev/null 2>&1 || fail "batch with stars"
python3 - <<'PY' || fail "stars in navcam batch did not move with the row's time"
import math, struct
def centroid(path):
    b = open(path, "rb").read()
    i = 0; h = {}
    while True:
        c = b[i:i + 80].decode(); i += 80
        if c[8:10] == "= ": h[c[:8].strip()] = c[10:].split("/")[0].strip()
        if c.startswith("END "): break
    i = (i + 2879) // 2880 * 2880
    w, n = int(h["NAXIS1"]), int(h["NAXIS2"])
    v = struct.unpack(">%df" % (w * n), b[i:i + 4 * w * n])
    s = sum(v); sx = sum((k % w) * e for k, e in enumerate(v)); sy = sum((k // w) * e for k, e in enumerate(v))
    return s, sx / s, sy / s
s0, x0, y0 = centroid("sirius/frame_000000.fits")
s1, x1, y1 = centroid("sirius/frame_000001.fits")
moved = math.hypot(x1 - x0, y1 - y0)
print("stars in batch: Sirius moved %.3f px in 100 years (13.39 expected)" % moved)
assert s0 > 0 and abs(s1 / s0 - 1) < 1e-3 and abs(moved - 13.39) < 0.05, (s0, s1, moved)
PY

# navcam population: every rock and crater of the scene, the same as the rows
# the frames list (index, centre, diameter); on a denser population (50 000
# rocks) the slope and density fitted on the list (a truncated power law,
# maximum likelihood) within 5 % of the configured ones.
"$navcam" population "${scene[@]}" -b pop_rocks.csv -c pop_craters.csv > pop.txt 2> pop.err || fail "population: $(cat pop.err)"
"$navcam" population "${scene[@]}" -b pop_dense.csv \
  --set 'bodies.0.boulders={density_per_km2: 3e5, slope: 2.2, min_diameter_m: 2, max_diameter_m: 20}' > /dev/null 2>&1 ||
  fail "population, dense"
python3 - <<'PY' || fail "population"
import csv, glob, math
def rows(path):
    return list(csv.DictReader(l for l in open(path) if not l.startswith("#")))
rocks, craters = rows("pop_rocks.csv"), rows("pop_craters.csv")
by = {int(r["index"]): r for r in rocks}
seen = 0
for f in glob.glob("ref/frame_*_boulders.csv"):
    for r in csv.DictReader(open(f)):
        p = by[int(r["index"])]
        assert all(abs(float(r[k]) - float(p[k])) <= 1e-6 * max(1, abs(float(p[k]))) for k in ("x_m", "y_m", "z_m", "diameter_m")), (r, p)
        seen += 1
head = [l for l in open("pop_dense.csv") if l.startswith("#")][0]
area = float(head.split(" on ")[1].split(" km^2")[0])
d = [float(r["diameter_m"]) for r in rows("pop_dense.csv")]
lo, hi = 2.0, 20.0
assert len(d) > 20000 and min(d) >= lo and max(d) < hi, (len(d), min(d), max(d))
s = sum(math.log(x / lo) for x in d) / len(d)
def score(b):  # d/db of the truncated power law's log-likelihood, per rock
    r = (hi / lo) ** -b
    return 1 / b - s - math.log(hi / lo) * r / (1 - r)
a, c = 0.5, 6.0
for _ in range(100):
    m = (a + c) / 2
    a, c = (m, c) if score(m) > 0 else (a, m)
b = (a + c) / 2
C = len(d) / area / (lo ** -b - hi ** -b)  # N(>1 m) per km^2 of the law
print("population: %d rocks (%d seen in the frames, the same); dense: %d rocks, slope %.4f (2.2), C %.0f per km^2 (3e5); "
      "%d craters" % (len(rocks), seen, len(d), b, C, len(craters)))
assert seen > 0 and abs(b / 2.2 - 1) < 0.05 and abs(C / 3e5 - 1) < 0.05 and len(craters) > 0, (b, C)
PY
"$navcam" population "${scene[@]}" -b /nonexistent/x.csv > /dev/null 2> err.txt && fail "population into a missing directory"
grep -q "/nonexistent/x.csv" err.txt || fail "population error: $(cat err.txt)"

# Errors: bad shard, bad row.
"$navcam" batch traj.csv -o x --shard 3/3 2> err.txt && fail "--shard 3/3 accepted"
grep -q "0 <= K < N" err.txt || fail "shard error: $(cat err.txt)"
printf 't_s,cam_x_m\n0,1,2\n' > bad.csv
"$navcam" batch bad.csv -o x 2> err.txt && fail "bad trajectory accepted"
grep -q "bad.csv:2: 3 columns, expected 11 or 12" err.txt || fail "trajectory error: $(cat err.txt)"
printf 't_s,cam_x_m\n0,1,2,x,0,1,0,0,0,1,0\n' > bad.csv
"$navcam" batch bad.csv -o x 2> err.txt && fail "a word in a row accepted"
grep -q "bad.csv:2: column 4 (cam_z_m): 'x' is not a number" err.txt || fail "trajectory error: $(cat err.txt)"
printf '0,1,2,3,1,0,0,0,0,1,0,0.5\n' > bad.csv
"$navcam" batch bad.csv -o x 2> err.txt && fail "capture 0.5 accepted"
grep -q "bad.csv:1: column 12 (capture): 0.5, expected 0 or 1" err.txt || fail "trajectory error: $(cat err.txt)"
# Columns by name: the first pose with its columns in another order (a scalar-last
# quaternion, capture among them) and the first SUM-like row with its Sun first
# give the same frames as in the layouts' own order.
python3 - <<'PY'
import csv
for src, dst, order in (("traj.csv", "named.csv", [8, 9, 10, 0, 1, 2, 3, 5, 6, 7, 4]),
                        ("traj_sum.csv", "named_sum.csv", [13, 14, 15] + list(range(13)))):
    rows = list(csv.reader(open(src)))
    head = [rows[0][i] for i in order] + ["capture"]
    with open(dst, "w") as f:
        f.write(",".join(head[:5] + head[-1:] + head[5:-1]) + "\n")
        for r in rows[1:3]:
            v = [r[i] for i in order] + ["1"]
            f.write(",".join(v[:5] + v[-1:] + v[5:-1]) + "\n")
PY
"$navcam" batch named.csv -o named "${scene[@]}" --no-geometry > /dev/null 2>&1 || fail "columns by name"
# the same file in capitals, with a UTF-8 byte-order mark and CRLF line ends: the same frames
printf '\xef\xbb\xbf' > named_bom.csv && tr 'a-z' 'A-Z' < named.csv | sed 's/$/\r/' >> named_bom.csv
"$navcam" batch named_bom.csv -o named_bom "${scene[@]}" --no-geometry > /dev/null 2>&1 || fail "BOM, capitals, CRLF"
cmp named_bom/frame_000001.fits named/frame_000001.fits || fail "BOM, capitals, CRLF: not the same frame"
# comments on lines of their own, indented, and after a row: the same frames
{ echo "  # indented"; sed '1s/$/ # the header/; 3s/$/\t# after a row/' named.csv; } > named_cmt.csv
"$navcam" batch named_cmt.csv -o named_cmt "${scene[@]}" --no-geometry > /dev/null 2>&1 || fail "comments"
cmp named_cmt/frame_000001.fits named/frame_000001.fits || fail "comments: not the same frame"
cmp named/frame_000001.fits ref/frame_000001.fits || fail "columns by name: not the reference frame"
"$navcam" batch named_sum.csv -o named_sum "${scene[@]}" --no-geometry > /dev/null 2>&1 || fail "SUM columns by name"
cmp named_sum/frame_000001.fits sum/frame_000001.fits || fail "SUM columns by name: not the frame of ordered rows"
row="0,1,2,3,1,0,0,0,0,1,0" named="cam_x_m,cam_y_m,cam_z_m,q_w,q_x,q_y,q_z,sun_x,sun_y,sun_z"
for c in "t_s,qx,$named|bad.csv:1: header column 2, 'qx', is not a column" \
         "t_s,cam_y_m,cam_x_m|bad.csv:1: the header names its columns in another order than t_s,cam_x_m" \
         "t_s,cam_x_m,cam_x_m|bad.csv:1: the header names cam_x_m twice" \
         "t_s,cam_x_m,cam_y_m,cam_z_m,qx,qy,qz,qw,sun_x,sun_y,sun_z|bad.csv:1: header column 5, 'qx', is not a column" \
         "capture,t_s,$named|bad.csv:2: 11 columns, expected 12 as the header names"; do
  printf '%s\n%s\n' "${c%%|*}" "$row" > bad.csv
  "$navcam" batch bad.csv -o x 2> err.txt && fail "accepted: ${c%%|*}"
  grep -qF "${c#*|}" err.txt || fail "trajectory error for ${c%%|*}: $(cat err.txt)"
done
# a number run into letters, an empty field, semicolons, no rows: each named for what it is
for c in "0,1,2,3x,1,0,0,0,0,1,0|bad.csv:1: column 4 (cam_z_m): '3x' is not a number" \
         "0x10,1,2,3,1,0,0,0,0,1,0|bad.csv:1: column 1 (t_s): '0x10' is not a number" \
         "0,nan,2,3,1,0,0,0,0,1,0|bad.csv:1: column 2 (cam_x_m): 'nan' is not a number" \
         "0,1,,3,1,0,0,0,0,1,0|bad.csv:1: column 3 (cam_y_m) is empty" \
         "0;1;2;3;1;0;0;0;0;1;0|(columns are separated by commas)" "t_s,cam_x_m|bad.csv: no poses"; do
  printf '%s\n' "${c%%|*}" > bad.csv
  "$navcam" batch bad.csv -o x 2> err.txt && fail "accepted: ${c%%|*}"
  grep -qF "${c#*|}" err.txt || fail "trajectory error for ${c%%|*}: $(cat err.txt)"
done
# a NUL byte: the rest of its line (here a capture column) would be lost unseen
printf '0,1,2,3,1,0,0,0,0,1,0\0,0\n' > bad.csv
"$navcam" batch bad.csv -o x 2> err.txt && fail "accepted a NUL byte"
grep -qF "bad.csv:1: a NUL byte at column 22" err.txt || fail "trajectory NUL: $(cat err.txt)"

# Slurm: a job array of 4 tasks into one directory.
slurm=$(mktemp -d /tmp/nc_slurm.XXXXXX)
trap '"$src/scripts/slurm-local.sh" stop "$slurm"' EXIT
SLURM_CONF=$("$src/scripts/slurm-local.sh" start "$slurm")
export SLURM_CONF
mkdir -p logs
NAVCAM=$navcam timeout 300 sbatch --wait --array=0-3 -D "$tmp/logs" "$src/examples/slurm/navcam_batch.sbatch" \
  "$tmp/traj.csv" "$tmp/slurm_out" "${scene[@]}" > sbatch.txt || { cat logs/* >&2; fail "sbatch"; }
for k in 0 1 2 3; do
  grep -q "shard $k/4: 2 of 8 rows are this shard's; 2 rendered" logs/navcam-batch-*_$k.log ||
    fail "task $k: $(cat logs/navcam-batch-*_$k.log)"
done
diff -r ref slurm_out > /dev/null || fail "the Slurm array's merged output differs from one process"
echo "PASS: dataset, shards, resume, SUM-like rows, a 4-task Slurm array identical to one process"
