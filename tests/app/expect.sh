# expect.sh - the command-line tests' start, sourced by a test run as
# TEST NAVCAM TMPDIR SOURCE_DIR: navcam, tmp (made afresh) and src from its
# arguments; ok and bad count, expect runs a command. The test ends with
#   echo "$pass passed, $fail failed"; [ "$fail" -eq 0 ]
navcam=$1
tmp=$2
src=$3
rm -rf "$tmp" && mkdir -p "$tmp"
pass=0
fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*" >&2; }
# expect CODE NEEDLE -- command...: exit code and a substring of stdout+stderr
expect() {
  local code=$1 needle=$2
  shift 3
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -ne "$code" ]; then bad "$* -> exit $rc, want $code: $out"; return; fi
  case "$out" in *"$needle"*) ok ;; *) bad "$* -> output lacks '$needle': $out" ;; esac
}
