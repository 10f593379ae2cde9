#!/usr/bin/env python3
"""test_layers.py - the folders are layers, and the build keeps them so.

Checks, on the source tree and the built static libraries:
  1. includes: every #include "..." of a file in a layer folder resolves to a
     file in the same or a lower layer (core < render < camera < proto <
     emulator < drivers < app; include/navcam, the public headers, lowest,
     and they include nothing internal);
  2. links: every undefined symbol of a layer's library is defined in a
     library of the same or a lower layer (no upward call, no link cycle);
  3. library code never prints to stderr itself (core/log.c does) and never
     installs a signal handler;
  4. no source file (tests and benchmarks too) is over 520 lines, but the
     render hot path;
  5. adapters/ (programs for other boards, such as the USB trigger adapter)
     use the wire protocols and core/ only: proto/, core/, include/;
  6. drivers stand alone (docs/writing-drivers.md): a driver's files
     (drivers/output_NAME.c or trigger_NAME.c and drivers/NAME/) include no
     other driver's and, of the emulator, emulator/output.h and trigger.h
     alone; its main file exports its struct nc_KIND_NAME alone.
Usage: test_layers.py SOURCE_DIR BUILD_DIR
"""
import os
import re
import subprocess
import sys

LAYERS = ["include", "core", "render", "camera", "proto", "emulator", "drivers", "app", "adapters"]
ADAPTERS_MAY_USE = {"include", "core", "proto", "adapters"}
RANK = {name: i for i, name in enumerate(LAYERS)}
LIBS = {"navcam_core": "core", "navcam_render": "render", "navcam_camera": "camera", "navcam_proto": "proto",
        "navcam_client": "proto", "navcam_emulator": "emulator", "navcam_drivers": "drivers", "navcam_cli": "app"}
HOT_PATH = {"render/render.c", "render/rt_embree.c"}
MAX_LINES = 520
GENERATED = {"core/version.h", "drivers/navcam_genicam_xml.h"}
GENERATED_DRIVER = {"drivers/navcam_genicam_xml.h": "gige"}  # generated headers and the driver they belong to
DRIVER_API = {"emulator/output.h", "emulator/trigger.h"}  # what a driver may include of the emulator

src, build = sys.argv[1], sys.argv[2]
failures = []
checked = 0
edges = {}  # (from layer, to layer) -> number of includes: the include graph


def layer_of(rel):
    top = rel.split("/")[0]
    return top if top in RANK else None


def driver_of(rel):
    """The driver a file of drivers/ belongs to (None: shared, such as the registry)."""
    if rel in GENERATED_DRIVER:
        return GENERATED_DRIVER[rel]
    parts = rel.split("/")
    if len(parts) == 3:
        return parts[1]
    m = re.match(r"(?:output|trigger)_(\w+)\.c$", parts[1])
    return m.group(1) if m else None


def sources():
    for layer in LAYERS:
        for root, _, files in os.walk(os.path.join(src, layer)):
            for f in sorted(files):
                if f.endswith((".c", ".h", ".cpp", ".c.in", ".h.in")):
                    yield os.path.relpath(os.path.join(root, f), src)


def resolve(rel, inc):
    here = os.path.dirname(rel)
    for cand in (os.path.join(here, inc), inc, os.path.join("include", inc)):
        if os.path.isfile(os.path.join(src, cand)):
            return os.path.normpath(cand)
    if inc in GENERATED:
        return inc
    return None


for rel in sources():
    layer = layer_of(rel)
    text = open(os.path.join(src, rel), encoding="utf-8").read()
    for n, line in enumerate(text.splitlines(), 1):
        m = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
        if not m:
            continue
        checked += 1
        target = resolve(rel, m.group(1))
        if target is None:
            failures.append(f"{rel}:{n}: #include \"{m.group(1)}\" does not name a file of the tree")
            continue
        tl = layer_of(target)
        if tl is not None and tl != layer:
            edges[(layer, tl)] = edges.get((layer, tl), 0) + 1
        if tl is None or RANK[tl] > RANK[layer]:
            failures.append(f"{rel}:{n}: {layer}/ includes {target} from the higher layer {tl}/")
        elif layer == "adapters" and tl not in ADAPTERS_MAY_USE:
            failures.append(f"{rel}:{n}: an adapter program includes {target}: adapters use proto/ and core/ only")
        elif layer == tl == "drivers" and driver_of(rel) and driver_of(target) not in (None, driver_of(rel)):
            failures.append(f"{rel}:{n}: the driver '{driver_of(rel)}' includes {target} of the driver "
                            f"'{driver_of(target)}': a driver uses no other driver's code")
        elif layer == "drivers" and driver_of(rel) and tl == "emulator" and target not in DRIVER_API:
            failures.append(f"{rel}:{n}: the driver '{driver_of(rel)}' includes {target}: of the emulator, a "
                            f"driver includes {' or '.join(sorted(DRIVER_API))} alone")
    lines = text.count("\n")
    if lines > MAX_LINES and rel not in HOT_PATH:
        failures.append(f"{rel}: {lines} lines (at most {MAX_LINES} outside the render hot path)")
    if layer not in ("app", "adapters") and rel != "core/log.c":
        code = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
        if re.search(r"\bstderr\b|\bperror\s*\(", code):
            failures.append(f"{rel}: a library writes to stderr itself (use core/log.h)")
        if re.search(r"\bsigaction\s*\(|\bsignal\s*\(", code):
            failures.append(f"{rel}: a library installs a signal handler (the program does that)")

# Tests and benchmarks: the same size limit.
for top in ("tests", "bench"):
    for root, _, files in os.walk(os.path.join(src, top)):
        for f in sorted(files):
            if f.endswith((".c", ".h", ".py", ".sh")):
                rel = os.path.relpath(os.path.join(root, f), src)
                lines = open(os.path.join(src, rel), encoding="utf-8").read().count("\n")
                if lines > MAX_LINES:
                    failures.append(f"{rel}: {lines} lines (at most {MAX_LINES})")

# Links: who defines what, then who needs what.
defined, needs = {}, {}
for lib, layer in LIBS.items():
    path = os.path.join(build, f"lib{lib}.a")
    if not os.path.isfile(path):
        failures.append(f"{path}: missing (build first)")
        continue
    out = subprocess.run(["nm", "-g", path], capture_output=True, text=True, check=True).stdout
    needs[lib] = set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1] in "TDBRVWCG":
            defined.setdefault(parts[2], set()).add(lib)
        elif len(parts) == 2 and parts[0] == "U":
            needs[lib].add(parts[1])
links = 0
for lib, syms in needs.items():
    for sym in sorted(syms):
        for owner in sorted(defined.get(sym, ())):
            if owner == lib:
                continue
            links += 1
            if RANK[LIBS[owner]] > RANK[LIBS[lib]]:
                failures.append(f"lib{lib}.a ({LIBS[lib]}/) calls {sym} of lib{owner}.a ({LIBS[owner]}/), a higher layer")

# A driver's main file exports its struct alone (everything else static).
out = subprocess.run(["nm", "-g", "-A", "--defined-only", os.path.join(build, "libnavcam_drivers.a")],
                     capture_output=True, text=True).stdout
exported = {}
for line in out.splitlines():
    _, member, rest = line.split(":", 2)  # ARCHIVE:MEMBER:ADDRESS TYPE SYMBOL
    if not rest.split()[-1].startswith(("__odr_asan", "__asan", "__ubsan")):  # the sanitizers' own, in an ASan build
        exported.setdefault(member, set()).add(rest.split()[-1])
for member, syms in sorted(exported.items()):
    m = re.match(r"(output|trigger)_(\w+)\.c\.o$", member)
    if m and syms != {f"nc_{m.group(1)}_{m.group(2)}"}:
        failures.append(f"drivers/{member[:-2]} exports {', '.join(sorted(syms))}: a driver's main file exports "
                        f"nc_{m.group(1)}_{m.group(2)} alone")

print("include graph between folders (from -> to: includes):")
for (a, b), n in sorted(edges.items(), key=lambda e: (RANK[e[0][0]], RANK[e[0][1]])):
    print(f"  {a:9s} -> {b:9s} {n:3d}{'' if RANK[b] < RANK[a] else '   UPWARD'}")
for f in failures:
    print("FAIL:", f)
print(f"{checked} includes and {links} cross-library symbol uses checked")
print(f"{1 if not failures else 0} passed, {1 if failures else 0} failed")
sys.exit(1 if failures else 0)
