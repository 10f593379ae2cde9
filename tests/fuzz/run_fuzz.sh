#!/usr/bin/env bash
# run_fuzz.sh - builds the libFuzzer targets with clang (AddressSanitizer and
# UndefinedBehaviorSanitizer on) and runs each for a bounded time from a seed
# corpus of valid inputs. Fails on any crash, leak or sanitizer report.
# Usage: run_fuzz.sh SOURCE_DIR BUILD_DIR SECONDS
set -euo pipefail
src=$1 out=$2 secs=${3:-20}
mkdir -p "$out"
cc=$(command -v clang || command -v clang-14)
flags=(-g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined -D_GNU_SOURCE
       -I"$src/render" -I"$src/emulator")
"$cc" "${flags[@]}" "$src/tests/fuzz/fuzz_protocol.c" "$src/emulator/protocol.c" -lz -lm -o "$out/fuzz_protocol"
"$cc" "${flags[@]}" "$src/tests/fuzz/fuzz_config.c" "$src/render/config.c" "$src/render/error.c" \
  $(pkg-config --cflags --libs yaml-0.1) -lm -o "$out/fuzz_config"

# Seeds: valid messages of every flag combination, and the repository's scenes.
mkdir -p "$out/corpus_protocol" "$out/corpus_config"
"$cc" -D_GNU_SOURCE -I"$src/render" -I"$src/emulator" -x c - "$src/emulator/protocol.c" -lz -lm \
  -o "$out/make_seeds" <<'SEEDS'
#include <stdio.h>
#include "protocol.h"
int main(int argc, char **argv)
{
    for (unsigned f = 0; f <= NC_MSG_KNOWN_FLAGS; f++) {
        struct nc_pose_msg m = {.type = (f & 1) ? NC_MSG_TRIGGER : NC_MSG_POSE, .sequence = f, .flags = f};
        m.cam_attitude_q = m.body_attitude_q = (struct nc_quat){1, 0, 0, 0};
        m.sun = nc_v3(1, 0, 0);
        unsigned char b[NC_PROTO_MAX_BYTES];
        size_t n = nc_msg_encode(&m, b, sizeof b);
        char path[4096];
        snprintf(path, sizeof path, "%s/seed_%03u", argv[1], f);
        FILE *fp = fopen(path, "wb");
        fwrite(b, 1, n, fp);
        fclose(fp);
    }
    return 0;
}
SEEDS
"$out/make_seeds" "$out/corpus_protocol"
cp "$src"/configs/examples/*.yaml "$out/corpus_config/"

for t in protocol config; do
  echo "fuzzing $t for $secs s"
  "$out/fuzz_$t" -max_total_time="$secs" -rss_limit_mb=2048 -print_final_stats=1 "$out/corpus_$t" \
    > "$out/fuzz_$t.log" 2>&1 || { tail -40 "$out/fuzz_$t.log"; echo "FAIL: fuzz_$t"; exit 1; }
  grep -E "stat::number_of_executed_units|Done" "$out/fuzz_$t.log" | tail -2
done
echo "2 passed, 0 failed"
