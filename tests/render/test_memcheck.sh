#!/usr/bin/env bash
# The file readers' unit tests under valgrind's memcheck: a read of memory
# never written (which AddressSanitizer does not see while it stays inside a
# buffer) fails the test. Usage: test_memcheck.sh TMPDIR TEST_PROGRAM...
set -euo pipefail
tmp=$1
shift
command -v valgrind >/dev/null || { echo "valgrind is missing (scripts/install-deps.sh --test installs it)"; exit 1; }
status=0
for t in "$@"; do
    name=$(basename "$t")
    mkdir -p "$tmp/$name"
    if NC_TEST_TMP="$tmp/$name" valgrind -q --error-exitcode=99 "$t" >"$tmp/$name.log" 2>&1; then
        echo "ok: $name under memcheck"
    else
        echo "FAIL: $name under memcheck (exit $?):"
        grep -m 20 -A 8 "==[0-9]*== [A-Z]" "$tmp/$name.log" || tail -20 "$tmp/$name.log"
        status=1
    fi
done
exit $status
