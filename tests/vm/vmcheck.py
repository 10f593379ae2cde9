"""vmcheck.py - what the guest scripts' checks (check.py, check_usb.py) share:
a pass/fail list, and readers for the files the phases leave behind
(stdlib only: it runs inside the guest)."""
import json
import os

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def records(path):
    """The JSON lines of a frames.jsonl sidecar."""
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def csv_rows(path):
    with open(path) as f:
        return [[int(x) for x in line.split(",")] for line in f if line.strip()]


def stats(out, d):
    """The summary navcam serve printed last in OUT/D/stats.json."""
    with open(os.path.join(out, d, "stats.json")) as f:
        return json.loads(f.read().strip().splitlines()[-1])


def level_at(samples, t):
    """A watched line's level at t, from its (mono_ns, value) changes."""
    v = samples[0][1]
    for ts, val in samples:
        if ts > t:
            break
        v = val
    return v
