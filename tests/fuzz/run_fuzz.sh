#!/usr/bin/env bash
# run_fuzz.sh - builds the libFuzzer targets (tests/fuzz/CMakeLists.txt, with
# clang: AddressSanitizer and UndefinedBehaviorSanitizer on) and runs each for
# a bounded time from a seed corpus of valid inputs. Fails on any crash, leak
# or sanitizer report.
# Usage: run_fuzz.sh SOURCE_DIR BUILD_DIR SECONDS
set -euo pipefail
src=$1 out=$2 secs=${3:-20}
mkdir -p "$out"
cc=$(command -v clang || command -v clang-14)
cmake -S "$src/tests/fuzz" -B "$out/build" -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=Debug >"$out/configure.log" 2>&1 ||
  { cat "$out/configure.log"; echo "FAIL: configuring the fuzz targets"; exit 1; }
cmake --build "$out/build" -j 2 >"$out/build.log" 2>&1 || { cat "$out/build.log"; echo "FAIL: building the fuzz targets"; exit 1; }

# Seeds: valid messages of every flag combination, the repository's scenes,
# and a small valid file of each format the readers take (the first byte
# picks the reader: 0 OBJ, 1 PLY, 2 ICQ, 3 SUM, 4 trajectory CSV, 5 KStars
# stars.dat, 6 NavCam's star index).
rm -rf "$out/corpus_protocol" "$out/corpus_config" "$out/corpus_readers"
mkdir -p "$out/corpus_protocol" "$out/corpus_config" "$out/corpus_readers"
"$out/build/make_seeds" "$out/corpus_protocol"
cp "$src"/configs/examples/*.yaml "$out/corpus_config/"
r=$out/corpus_readers
printf '\0v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf -3/1/1 -2//2 -1 # c\n' > "$r/obj"
printf '\1ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n%s' \
  'element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' > "$r/ply"
printf '\1ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n%s' \
  'property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n' > "$r/plyb"
head -c 36 /dev/zero >> "$r/plyb" && printf '\3\0\0\0\0\1\0\0\0\2\0\0\0' >> "$r/plyb"
{ printf '\2 1\n'; for i in $(seq 24); do printf '%d.0D+00 0.5 -0.25E+01\n' "$i"; done; } > "$r/icq"
printf '\3EX1\n2020 JAN 15 12:00:00.000\n    96    64    10 65535   NPX, NLN, THRSH\n%s%s%s%s%s%s%s' \
  '    0.1D+03    0.475D+02    0.315D+02  MMFL, CTR\n   -4.0    2.0   -1.0  SCOBJ\n' \
  '    0.4472135955    0.8944271910    0.0  CX\n    0.1951800146   -0.09759000729   -0.9759000729  CY\n' \
  '   -0.8728715609    0.4364357805   -0.2182178902  CZ\n    0.7990018711    0.5992514033    0.04993761694  SZ\n' \
  '  20.0   0.0   0.0   0.0  20.0   0.0  K-MATRIX\n' '    0.0D+00 0.0D+00 0.0D+00 0.0D+00  DISTORTION\n' \
  'END FILE\n' > "$r/sum"
printf '\4t_s,cam_x_m,cam_y_m,cam_z_m,q_w,q_x,q_y,q_z,sun_x,sun_y,sun_z\n0,0,-6000,0,0.7071068,-0.7071068,0,0,1,0,0\n' \
  > "$r/csv"
printf '\5# a comment\n%s\n%s\n' '183656.34 +384701.3 +000201.0+000287.500128.9 00.03-0.00A0 0            , alp Lyr, Vega' \
  '064508.92 -164258.0 -000546.0-001223.100379.2 -1.4400.01A0 1' > "$r/dat"
# the index: magic, star count 1 and epoch J1991.25 (little-endian), then one
# star's RA and Dec (rad, f64), proper motions (mas/yr), V and B-V (f32)
{ printf '\6NCSTARS1\1\0\0\0\0\0\0\0\0\0\0\0\0\x1d\x9f\x40'
  printf '\0\0\0\0\0\0\xf0\x3f\0\0\0\0\0\0\xe0\x3f\0\0\x80\x3f\0\0\0\x40\0\0\xa0\x40\0\0\0\0'; } > "$r/stars"

for t in protocol config readers; do
  echo "fuzzing $t for $secs s"
  # a finding's input is kept beside the logs (crash-*, oom-*, leak-*, timeout-*)
  "$out/build/fuzz_$t" -max_total_time="$secs" -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$out/" \
    "$out/corpus_$t" > "$out/fuzz_$t.log" 2>&1 || { tail -40 "$out/fuzz_$t.log"; echo "FAIL: fuzz_$t"; exit 1; }
  grep -E "stat::number_of_executed_units|Done" "$out/fuzz_$t.log" | tail -2
done
echo "3 passed, 0 failed"
