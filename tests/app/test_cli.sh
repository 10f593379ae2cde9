#!/usr/bin/env bash
# test_cli.sh - the navcam program through its real command line: help,
# version, renders to every format, overrides, and error messages/exit codes;
# each command linking only what it uses; docs/drivers.md as the drivers'
# tables print it.
# Usage: test_cli.sh NAVCAM TMPDIR SOURCE_DIR
set -u
. "$(dirname "$0")/expect.sh" # navcam, tmp (made afresh), src; ok, bad, expect
small=(--set camera.width_px=96 --set camera.height_px=96 --set bodies.0.shape.subdivisions=4)

expect 0 "render [SCENE.yaml] -o OUT" -- "$navcam" --help
expect 0 "navcam 0." -- "$navcam" --version
expect 0 "Usage: navcam render [SCENE.yaml] -o OUT" -- "$navcam" help render
expect 2 "navcam: unknown option '--bogus'" -- "$navcam" --bogus
expect 0 "--quantity" -- "$navcam" render --help
expect 0 "--set KEY=VALUE" -- "$navcam" render --help
expect 2 "Usage: navcam" -- "$navcam"
expect 2 "unknown command 'paint'" -- "$navcam" paint
# serve: the drivers this build has, and trigger configuration errors.
expect 0 "timer: a pulse train" -- "$navcam" serve --help
expect 0 "rate_hz                default 10; 0.001..10000 Hz: pulses per second" -- "$navcam" serve --help
expect 0 "strobe.active" -- "$navcam" serve --help
# --stats-json into a directory that is not there fails at start, not after the run
expect 1 "s.json: cannot write into directory '$tmp/none'" -- "$navcam" serve --stats-json "$tmp/none/s.json" -n 1 \
  --set serve.udp_port=5798 --set serve.tcp_port=5799
# docs/drivers.md is generated from the same tables (make docs).
"$navcam" serve --driver-docs > "$tmp/drivers.md"
diff -u "$src/docs/drivers.md" "$tmp/drivers.md" > "$tmp/drivers.diff" && ok ||
  bad "docs/drivers.md differs from \`navcam serve --driver-docs\` (run make docs): $(head -20 "$tmp/drivers.diff")"
# Unknown driver keys: file, line, key and what the driver takes, before any device is touched.
printf 'base: builtin:default\noutputs:\n  - driver: file\n    patern: f_%%06llu.png\n' > "$tmp/outs.yaml"
expect 1 "outs.yaml:4: outputs[0].patern: unknown key for output driver 'file'; did you mean 'pattern'? (it takes: driver, directory, pattern, fits_row_order, sidecar)" -- \
  "$navcam" serve "$tmp/outs.yaml"
expect 1 "serve.trigger.strobe.levle: unknown key for trigger driver 'gpio'" -- "$navcam" serve --set serve.mode=trigger \
  --set "serve.trigger={driver: gpio, line: X, strobe: {line: Y, levle: low}}"
expect 1 "trigger source 'software' gives commands, not line edges" -- "$navcam" serve --set serve.mode=trigger \
  --set "serve.trigger={driver: software, debounce_s: 0.01}"
# a trigger map without a driver is the software trigger, its documented default
expect 1 "trigger source 'software' gives commands, not line edges" -- "$navcam" serve --set serve.mode=trigger \
  --set "serve.trigger={debounce_s: 0.01}"
# Each command is its own program and loads only the libraries it uses.
libexec=$(dirname "$navcam")/libexec/navcam
needed() { readelf -d "$1" | sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' | tr '\n' ' '; }
case "$(needed "$navcam")" in *OpenImageIO*|*embree*|*aravis*|*gpiod*) bad "navcam itself links $(needed "$navcam")" ;; *) ok ;; esac
for c in render expose brdf scene replay pose; do
  case "$(needed "$libexec/navcam-$c")" in *aravis*|*gpiod*) bad "navcam-$c links a driver's library: $(needed "$libexec/navcam-$c")" ;; *) ok ;; esac
done
for c in replay pose; do
  case "$(needed "$libexec/navcam-$c")" in *OpenImageIO*|*embree*|*yaml*) bad "navcam-$c links the renderer: $(needed "$libexec/navcam-$c")" ;; *) ok ;; esac
done
# OpenImageIO (and the 260 libraries it pulls in: about 0.4 s to load) is the
# module navcam-oiio.so, loaded only by a command that reads or writes EXR,
# TIFF or PNG files.
for c in render expose serve batch bench compare texture stars brdf scene population; do
  case "$(needed "$libexec/navcam-$c")" in *OpenImageIO*) bad "navcam-$c links OpenImageIO itself" ;; *) ok ;; esac
done
case "$(needed "$libexec/navcam-oiio.so")" in *OpenImageIO*) ok ;; *) bad "navcam-oiio.so does not link OpenImageIO" ;; esac
loaded() { LD_DEBUG=files "$@" 2>&1 >/dev/null | grep -c 'file=.*\(OpenImageIO\|navcam-oiio\)' ; }
[ "$(loaded "$navcam" render --help)" = 0 ] && ok || bad "navcam render --help loads OpenImageIO"
[ "$(loaded "$navcam" render -o "$tmp/lazy.fits" "${small[@]}")" = 0 ] && ok || bad "a FITS render loads OpenImageIO"
[ "$(loaded "$navcam" render -o "$tmp/lazy.png" "${small[@]}")" -ge 2 ] && ok || bad "a PNG render does not load OpenImageIO"
[ "$(loaded "$navcam" render -o "$tmp/lazy.png" "${small[@]}" --set render.samples=4)" = 0 ] && ok ||
  bad "a PNG render's configuration error loads OpenImageIO"
expect 0 "wrote $tmp/lazy.png" -- "$navcam" render -o "$tmp/lazy.png" "${small[@]}"
# (the list goes on with the drivers this build has: gpio and usb when their libraries were found, and any added)
expect 1 "serve.trigger.driver: unknown trigger driver 'timr'; did you mean 'timer'? (this build has: software, timer" -- \
  "$navcam" serve --set serve.mode=trigger --set "serve.trigger={driver: timr}"
# The serve section, the trigger's and the outputs' keys and values are
# checked before the scene is built: no scene line comes before the error.
# (gpio and usb: a required key missing, an id of the wrong form; or, in a build without them, unknown drivers)
for s in "serve.frame_rate=5" "serve.trigger={driver: timer, rate_hz: 1e9}" "outputs=[{driver: file, directry: x}]" \
         "serve.trigger={driver: gpio}" "serve.trigger={driver: usb, id: 1209-0001}"; do
  out=$("$navcam" serve --set serve.mode=trigger --set "$s" 2>&1)
  case "$out" in *"scene: body"*) bad "serve --set $s built the scene before its error: $out" ;;
    *unknown\ key*|*expected\ a\ number*|*"line: missing required key"*|*"is not VID:PID"*|*"unknown trigger driver"*) ok ;;
    *) bad "serve --set $s: $out" ;; esac
done
expect 1 "serve.frame_rate: unknown key; did you mean 'frame_rate_hz'?" -- "$navcam" serve --set serve.frame_rate=5
# Every section, a misspelt one and the bodies' keys included, is read and
# checked before the bodies are built.
for s in "camera.widht_px=64" "render.samples=4" "optics.f_numbr=4" "sensor.read_noise=5" "exposure.time=1" \
         "rendr.seed=1" "bodies.0.shape.craters.sloep=2" "bodies.0.material.theta_bra=20"; do
  for c in "render -o $tmp/early.fits" serve; do
    out=$("$navcam" $c --set "$s" 2>&1)
    case "$out" in *"scene: body"*) bad "$c --set $s built the scene before its error: $out" ;; *"unknown key; did you mean"*) ok ;;
      *) bad "$c --set $s: $out" ;; esac
  done
done
expect 1 "base is a scene file's key" -- "$navcam" render -o "$tmp/early.fits" --set base=builtin:default
# An output's or a trigger's values that need no device are checked before the scene too (an outside check
# found a file pattern and a pulse width reported after the scene was built).
for s in "outputs=[{driver: file, pattern: 'f_%d.png'}]" "outputs=[{driver: file, pattern: 'f_%llu.jpg'}]" \
         "outputs=[{driver: file, pattern: 'f_%llu.png', fits_row_order: bottom_up}]" \
         "serve.trigger={driver: timer, rate_hz: 10, pulse_width_s: 0.2}"; do
  out=$("$navcam" serve --set serve.mode=trigger --set "$s" 2>&1)
  case "$out" in *"scene: body"*) bad "serve --set $s built the scene before its error: $out" ;;
    *"outputs[0].pattern: "* | *"outputs[0].fits_row_order: "* | *"serve.trigger.pulse_width_s: "*) ok ;;
    *) bad "serve --set $s: $out" ;; esac
done
expect 1 "serve.trigger does not apply to lock-step mode" -- "$navcam" serve --set serve.mode=lockstep --set "serve.trigger={driver: timer}"
expect 1 "serve.trigger.activation" -- "$navcam" serve --set serve.mode=trigger \
  --set "serve.trigger={driver: timer, activation: sideways}"
# gpio and v4l2 (the host has neither GPIO chips nor video devices; tests/vm
# runs them against real drivers): configuration errors name the key.
expect 1 "serve.trigger.line: no GPIO chip has a line named 'NOPE'" -- "$navcam" serve --set serve.mode=trigger \
  --set "serve.trigger={driver: gpio, line: NOPE}"
expect 1 "a line offset needs \`chip\`" -- "$navcam" serve --set serve.mode=trigger --set "serve.trigger={driver: gpio, line: 3}"
expect 1 "serve.trigger.chip: cannot open GPIO chip 'gpiochip7'" -- "$navcam" serve --set serve.mode=trigger \
  --set "serve.trigger={driver: gpio, chip: gpiochip7, line: 0}"
expect 1 "serve.trigger.strobe.active" -- "$navcam" serve --set serve.mode=trigger \
  --set "serve.trigger={driver: gpio, line: X, strobe: {line: Y, active: sideways}}"
expect 1 "no video output device with card label 'NoSuchCam'" -- "$navcam" serve \
  --set "outputs=[{driver: v4l2, card: NoSuchCam}]"
expect 1 "outputs[0].card: a V4L2 card label has at most 31 characters" -- "$navcam" serve \
  --set "outputs=[{driver: v4l2, card: $(printf 'C%.0s' $(seq 32))}]"
expect 1 "no video output device with card label '$(printf 'C%.0s' $(seq 31))'" -- "$navcam" serve \
  --set "outputs=[{driver: v4l2, card: $(printf 'C%.0s' $(seq 31))}]"
expect 1 "give either \`device\` or \`card\`" -- "$navcam" serve --set "outputs=[{driver: v4l2, device: /dev/video0, card: X}]"
expect 1 "GREY holds 8 bits; the camera's ADC has 12" -- "$navcam" serve --set "outputs=[{driver: v4l2, format: GREY}]"
expect 1 "v4l2 output: /dev/nonexistent-video: No such file or directory" -- "$navcam" serve \
  --set "outputs=[{driver: v4l2, device: /dev/nonexistent-video}]"
expect 2 "missing -o OUT" -- "$navcam" render
# pose send refuses what the protocol refuses, naming the option (nothing is sent)
expect 2 "--gain abc: expected a number" -- "$navcam" pose send -P 0,-6000,0 -g abc
expect 2 "--attitude 0,0,0,0: not a unit quaternion" -- "$navcam" pose send -P 0,-6000,0 -A 0,0,0,0
expect 2 "--sun 0,0,0: a zero vector" -- "$navcam" pose send -P 0,-6000,0 -S 0,0,0
expect 2 "--exposure -1: not within 0 to 3600 s" -- "$navcam" pose send -P 0,-6000,0 -e -1
# a host name is refused as a bad option (names are never looked up)
expect 2 "--host expects a numeric IPv4 address such as 127.0.0.1" -- "$navcam" pose send -P 0,-6000,0 -H localhost
expect 2 "--host expects a numeric IPv4 address such as 127.0.0.1" -- "$navcam" replay builtin:approach -H localhost
expect 2 "--port 99999: not a port" -- "$navcam" pose send -P 0,-6000,0 -p 99999
expect 1 "outputs[0].pattern: expected a file name with one %llu conversion" -- "$navcam" serve \
  --set "outputs=[{driver: file, pattern: 'x%s_llu.png'}]"
expect 1 "outputs[0].pattern: makes file names longer than 255 bytes" -- "$navcam" serve \
  --set "outputs=[{driver: file, pattern: 'f_%099llu_$(printf 'x%.0s' $(seq 160)).png'}]"
expect 1 "unknown output driver 'nul'; did you mean 'null'?" -- "$navcam" serve --set "outputs=[{driver: nul}]"
expect 2 "--position nan,0,0: not finite" -- "$navcam" pose send -P nan,0,0
expect 2 "navcam pose send: unrecognized option '--bogus'" -- "$navcam" pose send --bogus
expect 2 "navcam render: unrecognized option '--bogus'" -- "$navcam" render --bogus
# an option's value that is itself an option is refused, not taken (getopt would read "--set --set k=v" as a
# --set of "--set" and a file "k=v")
expect 2 "navcam render: --set needs a value, got the option '--set'" -- "$navcam" render --set --set a=1 -o x.exr
expect 2 "navcam batch: -o needs a value, got the option '--json'" -- "$navcam" batch builtin:approach -o --json
expect 2 "navcam pose send: --host needs a value, got the option '--port'" -- "$navcam" pose send --host --port 1
expect 2 "navcam render: -o needs a value, got the option '-q'" -- "$navcam" render -o -q iof
expect 2 "navcam render: --set needs a value, got the option '-j'" -- "$navcam" render --set -j -o x.exr
expect 0 "wrote --x.png" -- env -C "$tmp" "$navcam" render --output=--x.png "${small[@]}" # attached: as written
expect 0 "navcam stars info INDEX" -- "$navcam" stars info --help
# Number options: the whole argument a number in range, else exit 2 naming it.
expect 2 "navcam replay: --speed expects 0..1e+06, got 'abc'" -- "$navcam" replay builtin:approach --speed abc
expect 2 "navcam replay: --port expects 1..65535, got '99999'" -- "$navcam" replay builtin:approach -p 99999
expect 2 "navcam replay: --timeout-ms expects 1..86400000, got '-5'" -- "$navcam" replay builtin:approach -T -5
expect 2 "navcam serve: --threads expects 0..1024, got '-1'" -- "$navcam" serve -j -1
# A free-run trajectory whose time goes back: refused before anything is sent (nothing listens on port 9).
printf '0,0,-5000,0,1,0,0,0,1,0,0\n4,0,-4000,0,1,0,0,0,1,0,0\n3,0,-3000,0,1,0,0,0,1,0,0\n' > "$tmp/back.csv"
expect 1 "back.csv:3: t_s 3 s is before the row before's 4 s (line 2): free-run poses go forward" -- \
  "$navcam" replay "$tmp/back.csv" -p 9
expect 2 "navcam serve: --max-frames expects 1.." -- "$navcam" serve -n 2x
# Times beyond what 64-bit ns hold with room for an exposure: refused where they are read.
printf '0,0,-5000,0,1,0,0,0,1,0,0\n9.3e9,0,-4000,0,1,0,0,0,1,0,0\n' > "$tmp/far.csv"
expect 1 "far.csv:2: t_s 9.3e+09 s is beyond +-4.6e+09 s" -- "$navcam" replay "$tmp/far.csv" -p 9
expect 2 "navcam pose send: --time -5e9: beyond +-4.6e9 s" -- "$navcam" pose send -P 0,0,0 -t -5e9
expect 2 "navcam pose send: --position 0,2e15,0: farther than 1e15 m" -- "$navcam" pose send -P 0,2e15,0
# replay --lockstep started before the server: it waits (--wait) until the
# server listens, then streams; the README's tour runs its two lines so.
port=$((20000 + RANDOM % 20000))
"$navcam" replay builtin:approach --lockstep -p "$port" --wait 60 > "$tmp/early.out" 2> "$tmp/early.err" &
early=$!
for _ in $(seq 100); do grep -q "trying for up to 60 s" "$tmp/early.err" && break; sleep 0.1; done
"$navcam" serve --set serve.mode=lockstep --set serve.tcp_port=$port --set serve.udp_port=$((port + 1)) "${small[@]}" \
  --set "outputs=[{driver: null}]" > /dev/null 2>&1 &
srv=$!
if wait "$early" && grep -q "8 frames delivered" "$tmp/early.out"; then ok
else bad "replay before serve: $(cat "$tmp/early.out" "$tmp/early.err")"; fi
kill "$srv" 2> /dev/null
wait "$srv" 2> /dev/null
expect 2 "unsupported output format" -- "$navcam" render -o "$tmp/x.bmp"
expect 2 "rock_id needs FITS, TIFF or EXR" -- "$navcam" render -q rock_id -o "$tmp/x.png"
expect 1 "--set serve.bind=localhost: serve.bind: 'localhost' is not an IPv4 address" -- \
  "$navcam" serve --set serve.bind=localhost --max-frames 1
expect 2 "rock_id needs FITS, TIFF or EXR" -- "$navcam" batch builtin:approach -o "$tmp/rocks" -q rock_id -F png
expect 2 "unknown quantity 'flux'" -- "$navcam" render -o "$tmp/x.exr" --quantity flux
expect 2 "--threads expects" -- "$navcam" render -o "$tmp/x.exr" --threads 1025
# The camera's 1e15 m limit is a distance, not a coordinate.
# an item a --set adds to a list is blamed, not the file's line of the list;
# a --set that replaces an item of a list too short in its file is not
expect 1 "--set camera.position_m.3=5: camera.position_m[3]: expected a list of 3 numbers" -- \
  "$navcam" render -o "$tmp/long.fits" --set camera.position_m.3=5
printf 'base: builtin:default\ncamera:\n  position_m: [0, -6000]\n' > "$tmp/short.yaml"
expect 1 "short.yaml:3: camera.position_m: expected a list of 3 numbers" -- \
  "$navcam" render "$tmp/short.yaml" -o "$tmp/short.fits" --set camera.position_m.1=-5000
expect 1 "camera.position_m: 1.55885e+15 m from the scene's origin, beyond 1e+15 m" -- \
  "$navcam" render -o "$tmp/far.fits" --set 'camera.position_m=[9e14,9e14,9e14]'
# A camera inside the body (20 m from the centre of the default asteroid) is warned of.
expect 0 "camera-ray samples that met a surface met its back, inner side: is the camera inside a body (or a mesh wound inward)?" -- \
  "$navcam" render "${small[@]}" -o "$tmp/inside.fits" --set 'camera.position_m=[0,-20,0]'
expect 0 "$(nproc) threads" -- "$navcam" render "${small[@]}" -o "$tmp/j0.exr" --threads 0 --set render.threads=1
expect 0 "bodies:" -- "$navcam" scene

# The built-in default scene with no config at all.
expect 0 "wrote $tmp/default.png" -- "$navcam" render -o "$tmp/default.png" "${small[@]}"
[ -s "$tmp/default.png" ] && ok || bad "default.png not written"
for q in radiance iof range; do
  for e in exr tif fits png; do
    expect 0 "wrote $tmp/$q.$e" -- "$navcam" render -o "$tmp/$q.$e" --quantity "$q" "${small[@]}" -j 1
  done
done

# A float TIFF is deflated without the floating-point predictor (3), which
# Python's tifffile cannot undo without imagecodecs; its strips inflate with
# zlib alone to the image's 4-byte floats.
python3 - "$tmp/radiance.tif" <<'PY' && ok || bad "radiance.tif: predictor or strips"
import struct, sys, zlib
b = open(sys.argv[1], 'rb').read()
assert b[:4] == b'II*\0'
ifd = struct.unpack_from('<I', b, 4)[0]
tags = {}
for i in range(struct.unpack_from('<H', b, ifd)[0]):
    tag, typ, n, v = struct.unpack_from('<HHII', b, ifd + 2 + 12 * i)
    short = struct.unpack_from('<H', b, ifd + 2 + 12 * i + 8)[0]
    tags[tag] = (typ, n, short if typ == 3 and n == 1 else v)
def vals(tag):
    typ, n, v = tags[tag]
    if n == 1:
        return [v]
    return list(struct.unpack_from('<%d%s' % (n, 'H' if typ == 3 else 'I'), b, v))
assert tags[259][2] == 8 and tags[339][2] == 3 and tags.get(317, (3, 1, 1))[2] == 1, tags
raw = b''.join(zlib.decompress(b[o:o + c]) for o, c in zip(vals(273), vals(279)))
assert len(raw) == 4 * tags[256][2] * tags[257][2]
PY

# A scene file plus overrides; the printed scene is itself a valid scene.
"$navcam" scene > "$tmp/scene.yaml"
expect 0 "wrote" -- "$navcam" render "$tmp/scene.yaml" -o "$tmp/s.exr" "${small[@]}" \
  --set camera.position_m=[0,-4000,0] --set bodies.0.material.w=0.07

# Config errors: file, line, key and what was expected; exit 1.
printf 'bodies:\n  - shape: {type: sphere, radius_m: 100}\n    material: {model: lambert, A: 0.1}\nsun: {direction: [1, 0, 0]}\ncamera:\n  width_px: 32\n  height_px: 32\n  fx_px: 40\n  fy_px: 40\n  position_m: [0, 0, -500]\n  attitude_q: [1, 0, 0, 0]\n  shutter: global\n' > "$tmp/bad.yaml"
expect 1 "$tmp/bad.yaml:12: camera.shutter: unknown key" -- "$navcam" render "$tmp/bad.yaml" -o "$tmp/b.exr"
expect 1 "--set camera.width_px=wide: camera.width_px: expected a whole number" -- \
  "$navcam" render -o "$tmp/b.exr" --set camera.width_px=wide
expect 1 "nowhere.yaml: cannot open" -- "$navcam" render "$tmp/nowhere.yaml" -o "$tmp/b.exr"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n' > "$tmp/quad.obj"
expect 1 "quad.obj:5: face with 4 vertices" -- "$navcam" render -o "$tmp/b.exr" \
  --set "bodies.0.shape={type: mesh, file: $tmp/quad.obj, unit: m}"
expect 1 "cannot write into directory '/nonexistent-dir'" -- "$navcam" render -o /nonexistent-dir/x.exr "${small[@]}"

# FITS row order: an option of FITS output only, recorded in ROWORDER.
expect 0 "wrote $tmp/up.fits" -- "$navcam" render -o "$tmp/up.fits" --fits-rows bottom_up "${small[@]}"
grep -a -q "ROWORDER= 'BOTTOM-UP'" "$tmp/up.fits" && ok || bad "up.fits lacks ROWORDER = 'BOTTOM-UP'"
grep -a -q "ROWORDER= 'TOP-DOWN'" "$tmp/radiance.fits" && ok || bad "radiance.fits lacks ROWORDER = 'TOP-DOWN'"
expect 2 "--fits-rows: applies to .fits output only" -- "$navcam" render -o "$tmp/x.png" --fits-rows bottom_up
expect 1 "fits_row_order: applies to .fits patterns only" -- "$navcam" serve \
  --set "outputs=[{driver: file, fits_row_order: bottom_up}]"
# One pixel pitch for geometry and radiometry.
expect 1 "sensor.pixel_pitch_m: 6e-06 m disagrees with the camera's pixel pitch 5.5e-06 m" -- \
  "$navcam" render -o "$tmp/x.fits" -q dn --set sensor.pixel_pitch_m=6e-6

# navcam brdf: one geometry, standard input, errors.
expect 0 "i_deg,e_deg,g_deg,r,brdf,radf,reff" -- "$navcam" brdf --model lambert --param A=0.5 --geometry 60,0,60
expect 0 "60,0,60,0.079577471545947687,0.15915494309189535,0.25000000000000006,0.5" -- \
  "$navcam" brdf --model lambert --param A=0.5 --geometry 60,0,60
expect 0 "30,30,0,0.011936620731892153,0.013783222385544804,0.037500000000000006" -- "$navcam" brdf --model lommel_seeliger --param w=0.3 --geometry 30,30,0
expect 0 "95,10,100,0,0,0,0" -- "$navcam" brdf --model hapke --param w=0.3 --geometry 95,10,100
expect 0 "preset comet_67p" -- "$navcam" brdf --list
expect 0 "theta_bar" -- "$navcam" brdf --help
out=$(printf 'i,e,g\n30,30,0\n\n60,0,60\n' | "$navcam" brdf --preset moon --no-header)
[ "$(printf '%s\n' "$out" | wc -l)" -eq 2 ] && ok || bad "brdf stdin: want 2 rows, got: $out"
expect 1 "stdin:3: phase angle g = 100 deg cannot occur with i = 10 and e = 20" -- \
  sh -c "printf '30,30,0\n0,0,0\n10,20,100\n' | '$navcam' brdf --model lambert --param A=0.1"
expect 1 "stdin:2: expected \"i,e,g\" in degrees, got \"30;30;0\" (field i)" -- \
  sh -c "printf '30,30,0\n30;30;0\n' | '$navcam' brdf --model lambert --param A=0.1"
expect 1 "(field e)" -- sh -c "printf '30,x,0\n' | '$navcam' brdf --model lambert --param A=0.1"
# a run refused at its first geometry prints no header
out=$("$navcam" brdf --preset moon --geometry 30,20,50.0000015 2> /dev/null)
[ -z "$out" ] && ok || bad "brdf: a refused geometry printed '$out'"
expect 2 "phase angle g = 50.0000015 deg cannot occur with i = 30 and e = 20 (it must be within 10..50, give or take 1e-6" \
  -- "$navcam" brdf --preset moon --geometry 30,20,50.0000015
expect 2 "parameter w must be in [0, 1], got 1.5" -- "$navcam" brdf --model hapke --param w=1.5 --geometry 0,0,0
expect 2 "theta_bar must be in [0, 60]" -- "$navcam" brdf --model hapke --param w=0.5 --param theta_bar=70 --geometry 0,0,0
expect 2 "phi must be in [0, 0.752]" -- "$navcam" brdf --model hapke --param w=0.5 --param phi=0.8 --geometry 0,0,0
expect 2 "h_S must be > 0 when B_S0 > 0" -- "$navcam" brdf --model hapke --param w=0.5 --param B_S0=1 --param h_S=0 --geometry 0,0,0
expect 2 "parameter w is required" -- "$navcam" brdf --model hapke --geometry 0,0,0
expect 2 "no parameter named 'w'" -- "$navcam" brdf --model lambert --param w=0.5 --geometry 0,0,0
expect 2 "angles must be within 0..180" -- "$navcam" brdf --model lambert --param A=0.5 --geometry 190,0,190
expect 2 "give --model NAME or --preset NAME" -- "$navcam" brdf --geometry 0,0,0
# a bad option value exits 2 and names the option (a bad line of standard input exits 1)
expect 2 "navcam brdf: --model: unknown reflectance model 'foo'" -- "$navcam" brdf --model foo
expect 2 "navcam brdf: --preset: unknown preset 'mars'" -- "$navcam" brdf --preset mars

# The camera model: DN and electrons from a render (navcam expose: test_expose.sh).
expect 0 "dn [DN]" -- "$navcam" render -o "$tmp/dn.png" -q dn "${small[@]}"
expect 0 "electrons [e-]" -- "$navcam" render -o "$tmp/e.exr" -q electrons "${small[@]}" --exposure 0.001
expect 0 "dn [DN]" -- "$navcam" render -o "$tmp/dn.fits" -q dn "${small[@]}" --frame 7
expect 2 "--exposure expects" -- "$navcam" render -o "$tmp/x.png" -q dn --exposure -1
# numbers typed: decimal digits, a value given, a frame number as typed (-f 1e30 was frame 0), no wrap past 2^64 - 1
for f in 1e30 -1; do expect 2 "--frame expects a whole number" -- "$navcam" render -o "$tmp/x.fits" -f $f; done
for e in '' 0x10; do expect 2 "--exposure expects 0..3600, got '$e'" -- "$navcam" render -o "$tmp/x.fits" -e "$e"; done
# a body's name with a quote and a backslash: the dataset's JSON stays JSON
"$navcam" batch builtin:approach -o "$tmp/bq" --shard 0/8 --no-geometry "${small[@]}" \
  --set 'bodies.0.name=rock "A"\1' > /dev/null 2>&1 &&
  python3 -c "import json, sys; assert json.load(open(sys.argv[1]))['bodies'][0]['name'] == 'rock \"A\"\\\\1'" \
  "$tmp/bq/frame_000000.json" && ok || bad "batch JSON with a quoted body name: $(head -c 300 "$tmp/bq/frame_000000.json")"
# a SUM file's path with a quote in it: the file named, not a YAML error about an option never typed
expect 1 "it's.SUM: No such file or directory" -- "$navcam" render -o "$tmp/s.fits" --sumfile "$tmp/it's.SUM"

# The shading choice is recorded in the file.
"$navcam" render "${small[@]}" --set bodies.0.shape.normals=smooth -o "$tmp/smooth.fits" >/dev/null 2>&1
head -c 28800 "$tmp/smooth.fits" | grep -aq "NORMALS = 'asteroid=smooth'" && ok || bad "smooth.fits lacks NORMALS = 'asteroid=smooth'"
# SUNVIEW only with the Sun in or near the field (it was in every file; the default scene's is 140 deg off)
head -c 28800 "$tmp/smooth.fits" | grep -aq "SUNVIEW" && bad "smooth.fits has SUNVIEW with the Sun far off" || ok
"$navcam" render "${small[@]}" --set "sun.direction=[0.001, 1, 0]" -o "$tmp/sunview.fits" >/dev/null 2>&1
head -c 28800 "$tmp/sunview.fits" | grep -aq "SUNVIEW = 'off_axis_deg=0.0573 .* in_field=1 " && ok \
  || bad "sunview.fits: $(head -c 28800 "$tmp/sunview.fits" | grep -ao "SUNVIEW[^/]*")"
# Boulders below the cut (8 px: 10 m here) are folded into the Hapke roughness:
# said on stdout and recorded in the file.
expect 0 "folded into the reflectance: theta_bar 16 ->" -- "$navcam" render "${small[@]}" \
  --set "bodies.0.boulders={preset: bennu, min_diameter_m: 2}" --set render.boulder_min_px=8 -o "$tmp/fold.fits"
head -c 28800 "$tmp/fold.fits" | grep -aq "ROCKFOLD= 'asteroid=" && ok || bad "fold.fits lacks ROCKFOLD"
# Which rock each pixel shows.
expect 0 "rock_id [1 (index in the body's boulder list" -- "$navcam" render "${small[@]}" \
  --set "bodies.0.boulders={preset: bennu, min_diameter_m: 2}" -q rock_id -o "$tmp/rocks.fits"

# Every example scene renders (the camera-only ones overlay a scene; the
# shape models come from ../shared/data/shapes, next to the checkout). Not in
# the sanitizer tree (NAVCAM_TEST_SANITIZED, set by tests/CMakeLists.txt):
# `make test` runs this loop in the optimised tree.
examples=("$src"/configs/examples/*.yaml)
[ -n "${NAVCAM_TEST_SANITIZED:-}" ] && examples=() && echo "note: example scenes are rendered in the optimised tree"
for f in "${examples[@]}"; do
  grep -q '^bodies:' "$f" || continue
  if grep -q 'shared/data/shapes' "$f" && [ ! -d "$src/../shared/data/shapes" ]; then
    echo "note: $f needs $src/../shared/data/shapes, which this checkout has not beside it"
    continue
  fi
  extra=()
  if grep -q 'moon/ldem_16.tif' "$f" && [ ! -f "$src/configs/examples/moon/ldem_16.tif" ]; then
    # LOLA's map is a download (see the file): a synthetic one in its place,
    # +-5 km in bands of latitude, float32 km as the real one is.
    echo "note: $f: configs/examples/moon/ldem_16.tif not downloaded; rendering with a synthetic elevation map"
    python3 - "$tmp/ldem.fits" <<'PY'
import math, struct, sys
w, h = 360, 180
rows = [[5 * math.sin(math.radians(4 * (90 - (r + 0.5)))) for _ in range(w)] for r in range(h)]
cards = ["SIMPLE  =                    T", "BITPIX  =                  -32", "NAXIS   =                    2",
         f"NAXIS1  = {w:20d}", f"NAXIS2  = {h:20d}", "END"]
head = "".join(c.ljust(80) for c in cards)
head += " " * (-len(head) % 2880)
data = b"".join(struct.pack(">%df" % w, *row) for row in rows)
open(sys.argv[1], "wb").write(head.encode() + data + b"\0" * (-len(data) % 2880))
PY
    extra=(--set "bodies.0.shape.elevation_map.file=$tmp/ldem.fits" --set bodies.0.shape.subdivisions=5)
  fi
  expect 0 "wrote $tmp/example.png: 48x48" -- "$navcam" render "$f" -o "$tmp/example.png" \
    --set camera.width_px=48 --set camera.height_px=48 "${extra[@]}"
done

# navcam compare: a render against itself moved by 2 px (the principal
# point), with plots; sizes that differ; --render's --sumfile errors.
expect 0 "--register R" -- "$navcam" compare --help
whole=("${small[@]}" --set camera.pixel_pitch_m=5.5e-5)  # the whole body in the frame
"$navcam" render -o "$tmp/real.fits" "${whole[@]}" > /dev/null 2>&1
"$navcam" render -o "$tmp/moved.fits" "${whole[@]}" --set camera.cx_px=49.5 > /dev/null 2>&1
"$navcam" compare "$tmp/real.fits" "$tmp/moved.fits" --register 3 -o "$tmp/cmp" > "$tmp/cmp.json" 2> "$tmp/cmp.err" &&
  python3 -c "
import json, sys; d = json.load(open(sys.argv[1]))
dx, dy = d['shift_px']
assert abs(dx + 2) < 0.15 and abs(dy) < 0.15 and d['limb_iou'] > 0.95 and d['relative_error']['p95'] < 0.1, d
a, b = d['texture']['real'], d['texture']['render']  # the same scene: the same texture over the same pixels
assert a['region_px'] == b['region_px'] == d['foreground_px'] and a['corners'] > 0, d
assert abs(b['grad_mean'] / a['grad_mean'] - 1) < 0.1 and abs(b['psd_beta'] - a['psd_beta']) < 0.2, d" \
  "$tmp/cmp.json" && [ ! -s "$tmp/cmp.err" ] && ok || bad "navcam compare of a 2 px shift: $(cat "$tmp/cmp.json" "$tmp/cmp.err")"
for f in relative_error.png error_histogram.png error_histogram.csv relative_error.fits; do
  [ -s "$tmp/cmp/$f" ] && ok || bad "navcam compare -o: no $f"
done
# a directory name no shell parses: gnuplot runs in it, nothing else runs
odd="$tmp/cmp'; touch $tmp/injected; '"
"$navcam" compare "$tmp/real.fits" "$tmp/moved.fits" -o "$odd" > /dev/null 2>&1 && [ -s "$odd/relative_error.png" ] &&
  [ ! -e "$tmp/injected" ] && [ ! -e "$odd/.compare.gp" ] && ok ||
  bad "navcam compare -o with a quote in the name: $(ls -a "$odd" 2>&1)"
# gnuplot failing (a stand-in that exits 1): a warning, no plots; the map, the histogram's numbers and the
# JSON written, no temporaries left
mkdir -p "$tmp/nognu" && printf '#!/bin/sh\nexit 1\n' > "$tmp/nognu/gnuplot" && chmod +x "$tmp/nognu/gnuplot"
PATH="$tmp/nognu:$PATH" "$navcam" compare "$tmp/real.fits" "$tmp/moved.fits" -o "$tmp/cmp_nognu" \
  --json "$tmp/cmp_nognu.json" > /dev/null 2> "$tmp/cmp_nognu.err" && grep -q "no plots: gnuplot failed" \
  "$tmp/cmp_nognu.err" && [ -s "$tmp/cmp_nognu/relative_error.fits" ] && [ -s "$tmp/cmp_nognu.json" ] &&
  [ -s "$tmp/cmp_nognu/error_histogram.csv" ] && [ ! -e "$tmp/cmp_nognu/.compare.gp" ] &&
  [ ! -e "$tmp/cmp_nognu/.relative_error.f32" ] && ok ||
  bad "navcam compare without gnuplot: $(cat "$tmp/cmp_nognu.err"; ls -A "$tmp/cmp_nognu")"
"$navcam" render -o "$tmp/other.fits" "${small[@]}" --set camera.width_px=64 > /dev/null 2>&1
expect 1 "is 96x96 but $tmp/other.fits is 64x96: the images must have the same size" -- \
  "$navcam" compare "$tmp/real.fits" "$tmp/other.fits"
expect 2 "--fit expects scale, histogram or none" -- "$navcam" compare a b --fit gamma
# --flip-real: a copy of the render turned by 180 degrees (its float32 rows
# and columns reversed, the header kept) compares exactly once turned back.
python3 - "$tmp/real.fits" "$tmp/turned.fits" <<'PY'
import sys
d = open(sys.argv[1], "rb").read()
end = next(i for i in range(0, len(d), 80) if d[i:i + 8] == b"END     ")
start = (end // 2880 + 1) * 2880
n = 96 * 96 * 4
px = [d[start + i:start + i + 4] for i in range(0, n, 4)]
open(sys.argv[2], "wb").write(d[:start] + b"".join(reversed(px)) + d[start + n:])
PY
"$navcam" compare "$tmp/turned.fits" "$tmp/real.fits" --flip-real xy > "$tmp/flip.json" &&
  "$navcam" compare "$tmp/turned.fits" "$tmp/real.fits" --flip-real y > "$tmp/flip_y.json" &&
  python3 -c "
import json, sys; a, b = (json.load(open(f)) for f in sys.argv[1:])
assert a['flip_real'] == 'xy' and a['relative_error']['p95'] == 0 and a['limb_iou'] == 1, a
assert b['flip_real'] == 'y' and b['relative_error']['p95'] > 0.01, b" "$tmp/flip.json" "$tmp/flip_y.json" &&
  ok || bad "navcam compare --flip-real: $(cat "$tmp/flip.json" "$tmp/flip_y.json")"
expect 2 "--flip-real expects none, x, y or xy" -- "$navcam" compare a b --flip-real z
# A pixel missing in one image is missing in both, for the texture too: the render with a block of NaN
# against itself whole, either way round, gives both images the same texture (an outside check found REAL's
# pixels read on the FAST circle where RENDER's were missing: 300 corners against 275).
python3 - "$tmp/real.fits" "$tmp/holed.fits" <<'PY'
import sys
d = bytearray(open(sys.argv[1], "rb").read())
end = next(i for i in range(0, len(d), 80) if d[i:i + 8] == b"END     ")
start = (end // 2880 + 1) * 2880
for y in range(30, 60):
    for x in range(20, 70):
        o = start + 4 * (96 * y + x)
        d[o:o + 4] = b"\x7f\xc0\x00\x00"
open(sys.argv[2], "wb").write(bytes(d))
PY
"$navcam" compare "$tmp/real.fits" "$tmp/holed.fits" --fit none > "$tmp/hole1.json" &&
  "$navcam" compare "$tmp/holed.fits" "$tmp/real.fits" --fit none > "$tmp/hole2.json" &&
  python3 -c "
import json, sys; a, b = (json.load(open(f))['texture'] for f in sys.argv[1:])
t = [a['real'], a['render'], b['real'], b['render']]
assert len({(x['corners'], x['region_px']) for x in t}) == 1, t" "$tmp/hole1.json" "$tmp/hole2.json" &&
  ok || bad "navcam compare with missing pixels: $(cat "$tmp/hole1.json" "$tmp/hole2.json")"
expect 1 "no.SUM: No such file or directory" -- "$navcam" render -o "$tmp/s.fits" --sumfile "$tmp/no.SUM" \
  --set sun.distance_au=1
# navcam texture: two renders at once (JSON fields, the region, --gsd), and
# its argument and file errors.
expect 0 "FastFeatureDetector" -- "$navcam" texture --help
# -j is --threads where a command renders: here there is none, and -j 2 is
# refused (it wrote the JSON into a file named 2)
expect 2 "invalid option" -- "$navcam" texture -j 2 "$tmp/real.fits"
expect 2 "invalid option" -- "$navcam" compare -j 2 "$tmp/real.fits" "$tmp/real.fits"
"$navcam" texture "$tmp/real.fits" "$tmp/other.fits" --region otsu --gsd 2 > "$tmp/tex.json" 2> "$tmp/tex.err" &&
  python3 -c "
import json, sys; d = json.load(open(sys.argv[1]))
assert len(d) == 2 and d[0]['width'] == 96 and d[1]['width'] == 64 and d[0]['region'] == 'otsu', d
a = d[0]
assert 0 < a['region_px'] < 96 * 96 and a['corners'] > 0 and a['psd_beta'] is not None and a['grad_mean'] > 0, a
assert abs(a['corners_per_m2'] - a['corners'] / (a['region_px'] * 4.0)) < 1e-9 * a['corners_per_m2'], a" \
  "$tmp/tex.json" && [ ! -s "$tmp/tex.err" ] && ok || bad "navcam texture: $(cat "$tmp/tex.json" "$tmp/tex.err")"
# --crop: the whole frame as a crop measures as the frame; a window is its own size.
"$navcam" texture "$tmp/real.fits" --region otsu > "$tmp/tex_all.json" &&
  "$navcam" texture "$tmp/real.fits" "$tmp/real.fits" --region otsu --crop 0,0,96,96 > "$tmp/tex_c.json" &&
  "$navcam" texture "$tmp/real.fits" --crop 16,8,64,80 > "$tmp/tex_w.json" &&
  python3 -c "
import json, sys; a, c, w = (json.load(open(f)) for f in sys.argv[1:])
assert a[0]['crop'] is None and c[0]['crop'] == [0, 0, 96, 96], (a, c)
assert all(c[0][k] == a[0][k] for k in a[0] if k != 'crop'), (a, c)
assert w[0]['width'] == 64 and w[0]['height'] == 80 and w[0]['region_px'] == 64 * 80, w" \
  "$tmp/tex_all.json" "$tmp/tex_c.json" "$tmp/tex_w.json" && ok || bad "navcam texture --crop"
expect 1 "--crop 40,0,64,64 reaches beyond its 96x96 pixels" -- "$navcam" texture "$tmp/real.fits" --crop 40,0,64,64
expect 2 "--crop expects X,Y,W,H in pixels" -- "$navcam" texture a.fits --crop 1,2,0,4
expect 2 "--band expects FLO,FHI cycles per pixel" -- "$navcam" texture a.fits --band 0.3,0.2
expect 2 "--threshold expects an integer 0..254" -- "$navcam" texture a.fits -t 300
expect 2 "give at least one image" -- "$navcam" texture
expect 1 "navcam texture: $tmp/none.fits" -- "$navcam" texture "$tmp/none.fits"
expect 0 "--shard K/N" -- "$navcam" batch --help

# The reference USB trigger adapter: its help, its argument errors, and the
# stand-alone build its README gives (board-side: no NavCam libraries).
adapter=$(dirname "$navcam")/navcam-usb-adapter
if [ -x "$adapter" ]; then
  expect 0 "--ffs DIR" -- "$adapter" --help
  expect 2 "usage: navcam-usb-adapter" -- "$adapter" --chip gpiochip0
  expect 1 "$tmp/no-ffs/ep0: No such file or directory (is FunctionFS mounted there?)" -- \
    "$adapter" --ffs "$tmp/no-ffs" --chip /dev/null --input 0
  build_cmd=$(grep -A1 '^gcc ' "$src/adapters/usb-trigger/README.md" | sed 's/\\$//' | tr -d '\n')
  (cd "$src" && eval "${build_cmd/-o navcam-usb-adapter/-o $tmp/adapter -Wall -Wextra -Werror}") && [ -x "$tmp/adapter" ] && ok ||
    bad "the stand-alone build in adapters/usb-trigger/README.md failed: $build_cmd"
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
