#!/usr/bin/env bash
# test_expose.sh - navcam expose through its command line: flats and darks of
# a camera model alone, their header and options; a scene file read as
# `navcam render` reads it (`base: builtin:default`, the camera's rates,
# which it ignores); a mirrored SUM camera's flat stored as render stores
# its frames.
# Usage: test_expose.sh NAVCAM TMPDIR SOURCE_DIR
set -u
. "$(dirname "$0")/expect.sh" # navcam, tmp (made afresh), src; ok, bad, expect

expect 2 "expected top_down" -- "$navcam" expose "$src/configs/examples/navcam_camera.yaml" -L 1 -o "$tmp/x.fits" --fits-rows up
cam="$tmp/cam.yaml"
printf 'camera: {width_px: 64, height_px: 48, focal_length_m: 0.02, pixel_pitch_m: 1.0e-5}\noptics: {f_number: 4}\nsensor: {read_noise_e: 5, full_well_e: 10000, gain_e_per_dn: 2, bias_dn: 20, adc_bits: 12}\n' > "$cam"
expect 0 "wrote $tmp/flat.fits: 4 frames of 64x48, 12-bit" -- "$navcam" expose "$cam" -L 3 -e 0.001 -n 4 -o "$tmp/flat.fits"
expect 0 "wrote $tmp/dark_0005.png" -- "$navcam" expose "$cam" --dark -e 0.5 -n 2 --first-frame 4 -o "$tmp/dark.png"
# what every image carries (docs/config.md): the maker, the quantity and its units, the intrinsics
for k in "CREATOR = 'NavCam" "QUANTITY= 'dn" "BUNIT   = 'adu" "INTRINS = '\[" "FRAME   =                    0"; do
  grep -aq "$k" "$tmp/flat.fits" && ok || bad "navcam expose's FITS header lacks $k"
done
expect 2 "bad value '' for --radiance" -- "$navcam" expose "$cam" -L '' -o "$tmp/x.fits"
expect 2 "bad value '1e30' for --first-frame" -- "$navcam" expose "$cam" -L 1 --first-frame 1e30 -o "$tmp/x.fits"
expect 2 "--first-frame 18446744073709551615 with 2 frames goes past frame 2^64 - 1" -- \
  "$navcam" expose "$cam" -L 1 -n 2 --first-frame 18446744073709551615 -o "$tmp/x.fits"
[ -s "$tmp/dark_0004.png" ] && ok || bad "dark_0004.png not written"
# Same command, same frames: bit for bit.
"$navcam" expose "$cam" -L 3 -e 0.001 -n 4 -o "$tmp/flat2.fits" >/dev/null
cmp -s "$tmp/flat.fits" "$tmp/flat2.fits" && ok || bad "expose is not reproducible"
expect 1 "cam.yaml:3: sensor.gain: unknown key" -- sh -c "sed 's/gain_e_per_dn/gain/' '$cam' > '$tmp/cam.yaml.bad' && mv '$tmp/cam.yaml.bad' '$tmp/cam2.yaml' && '$navcam' expose '$tmp/cam2.yaml' -L 1 -o '$tmp/x.fits' 2>&1 | sed 's/cam2/cam/'; exit 1"
expect 2 "missing --radiance L (or --dark)" -- "$navcam" expose "$cam" -o "$tmp/x.fits"
expect 0 "photon transfer" -- "$navcam" expose --help

# A scene file works as it does for render: laid over the built-in default
# scene, and its camera's rates ignored with its pose (both were refused).
printf 'base: builtin:default\ncamera:\n  width_px: 64\n  height_px: 48\n  velocity_m_s: [1, 0, 0]\n  angular_velocity_rad_s: [0, 0.01, 0]\n' > "$tmp/scene.yaml"
expect 0 "wrote $tmp/scene.fits: 1 frames of 64x48, 12-bit" -- "$navcam" expose "$tmp/scene.yaml" -L 1 -o "$tmp/scene.fits"
expect 0 "wrote $tmp/gige.fits: 1 frames of 1024x1024" -- "$navcam" expose "$src/configs/examples/gige.yaml" -L 1 \
  -o "$tmp/gige.fits"

# A mirrored SUM camera (K22 < 0; the stored principal point at row 29.5 of
# 48, the view's at 17.5): the flat's vignetting is the render's, row for
# row (it was upside down), and the flat says it is mirrored.
printf '%s\n' 'MIR' '2020 JAN 15 12:00:00.000' '    64    48     0  4095   NPX, NLN, THRSH' \
  '    0.1D+01    20.5    30.5   MMFL, CTR' '    0.0D+00  0.0D+00  0.3D+01   SCOBJ' '    1.0D+00  0.0D+00  0.0D+00   CX' \
  '    0.0D+00  1.0D+00  0.0D+00   CY' '    0.0D+00  0.0D+00  1.0D+00   CZ' '    0.0D+00  0.0D+00 -1.0D+00   SZ' \
  '    50.0 0.0 0.0 0.0 -25.0 0.0   K-MATRIX' 'END FILE' > "$tmp/mir.SUM"
printf '%s\n' 'bodies: [{name: s, shape: {type: sphere, radius_m: 2900}, material: {model: lambert, A: 0.3}}]' \
  'sun: {distance_au: 1}' 'camera: {sumfile: mir.SUM}' 'render: {samples_per_pixel: 1}' \
  'optics: {f_number: 4, vignetting: cos4, psf: {type: none}}' \
  'sensor: {shot_noise: false, read_noise_e: 0, full_well_e: 1.0e9, gain_e_per_dn: 1, adc_bits: 16}' > "$tmp/mir.yaml"
expect 0 "wrote $tmp/mflat.fits" -- "$navcam" expose "$tmp/mir.yaml" -L 0.02 -o "$tmp/mflat.fits"
expect 0 "electrons [e-]" -- "$navcam" render "$tmp/mir.yaml" -q electrons -o "$tmp/me.fits"
expect 0 "radiance [W m^-2 sr^-1]" -- "$navcam" render "$tmp/mir.yaml" -q radiance -o "$tmp/mL.fits"
/usr/bin/python3 - "$tmp" <<'PY' && ok || bad "a mirrored camera's flat is not the render's vignetting"
import sys
import numpy as np
from astropy.io import fits
t = sys.argv[1]
flat = fits.getdata(t + "/mflat.fits").astype(float).reshape(48, 64)
e, L = fits.getdata(t + "/me.fits").astype(float), fits.getdata(t + "/mL.fits").astype(float)
assert (L > 0).all(), "the sphere fills the frame"
v = e / L
flat, v = flat / flat.max(), v / v.max()
assert np.abs(flat - v).max() < 2e-3, np.abs(flat - v).max()
assert np.argmax(flat[:, 20]) in (29, 30), np.argmax(flat[:, 20])
assert "rows=1 columns=0" in repr(fits.getheader(t + "/mflat.fits")), "IMAGE_MIRRORED"
PY

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
