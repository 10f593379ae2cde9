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

# Seeds: valid messages of every flag combination, and the repository's scenes.
rm -rf "$out/corpus_protocol" "$out/corpus_config"
mkdir -p "$out/corpus_protocol" "$out/corpus_config"
"$out/build/make_seeds" "$out/corpus_protocol"
cp "$src"/configs/examples/*.yaml "$out/corpus_config/"

for t in protocol config; do
  echo "fuzzing $t for $secs s"
  "$out/build/fuzz_$t" -max_total_time="$secs" -rss_limit_mb=2048 -print_final_stats=1 "$out/corpus_$t" \
    > "$out/fuzz_$t.log" 2>&1 || { tail -40 "$out/fuzz_$t.log"; echo "FAIL: fuzz_$t"; exit 1; }
  grep -E "stat::number_of_executed_units|Done" "$out/fuzz_$t.log" | tail -2
done
echo "2 passed, 0 failed"
