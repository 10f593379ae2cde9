#!/usr/bin/env python3
"""test_platesolve.py - star fields rendered by NavCam at known attitudes are
solved by an independent plate solver, astrometry.net's solve-field with its
Tycho-2 index files (Debian packages; scripts/install-deps.sh --test).

For fields of view of 5, 10, 20, 40 and 60 degrees, each at its own
pointing and roll: `navcam render` writes DN through the full camera model (noise, PSF)
as a FITS file with row 1 at the bottom (the FITS convention); solve-field
finds the WCS; the sky positions it gives to the boresight pixel and to a
pixel 400 px above it are compared with the pose's:
  pointing within 5 arcsec, roll (the position angle of "up") within 0.05 deg.
And NavCam's own WCS header (RA---TAN, DEC--TAN), read by wcs-xy2rd from the
frame itself, bottom-up and top-down: within 0.01 arcsec of the pose at two
pixels.

Usage: test_platesolve.py NAVCAM TMPDIR   (stars.dat: $NAVCAM_STARS_DAT or
/usr/local/share/navcam/stars.dat)
"""
import math
import os
import shutil
import subprocess
import sys

navcam, tmp = sys.argv[1], sys.argv[2]
stars_dat = os.environ.get("NAVCAM_STARS_DAT", "/usr/local/share/navcam/stars.dat")
shutil.rmtree(tmp, ignore_errors=True)
os.makedirs(tmp)
for need in [stars_dat, shutil.which("solve-field"), shutil.which("wcs-xy2rd")]:
    if not need or not os.path.exists(need):
        sys.exit(f"test_platesolve: missing {need or 'solve-field / wcs-xy2rd'}: run scripts/install-deps.sh --test")
try:
    from astropy.io import fits
    from astropy.wcs import WCS
except ImportError:
    sys.exit("test_platesolve: missing astropy for /usr/bin/python3 (python3-astropy): run scripts/install-deps.sh --test")

index = os.path.join(tmp, "stars.ncs")
subprocess.run([navcam, "stars", "index", stars_dat, "-o", index], check=True, stdout=subprocess.DEVNULL)

W = H = 1024
PITCH = 5.5e-6


def unit(ra, dec):
    return [math.cos(dec) * math.cos(ra), math.cos(dec) * math.sin(ra), math.sin(dec)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def attitude(ra_deg, dec_deg, roll_deg):
    """Camera axes in the ICRS: z the boresight, -y (image up) north turned
    by roll towards east... as the rotation about z gives; returns the
    camera -> scene matrix columns and the quaternion [w, x, y, z]."""
    ra, dec, roll = map(math.radians, (ra_deg, dec_deg, roll_deg))
    z = unit(ra, dec)
    north = [-math.sin(dec) * math.cos(ra), -math.sin(dec) * math.sin(ra), math.cos(dec)]
    y0 = [-c for c in north]          # image down = south at roll 0
    x0 = cross(y0, z)                 # right-handed: x = y cross z
    x = [math.cos(roll) * a + math.sin(roll) * b for a, b in zip(x0, y0)]
    y = [-math.sin(roll) * a + math.cos(roll) * b for a, b in zip(x0, y0)]
    m = [[x[i], y[i], z[i]] for i in range(3)]  # columns x, y, z
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = 2 * math.sqrt(1 + t)
        q = [s / 4, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s]
    else:
        i = max(range(3), key=lambda k: m[k][k])
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2 * math.sqrt(1 + m[i][i] - m[j][j] - m[k][k])
        q = [0.0] * 4
        q[0] = (m[k][j] - m[j][k]) / s
        q[1 + i] = s / 4
        q[1 + j] = (m[j][i] + m[i][j]) / s
        q[1 + k] = (m[k][i] + m[i][k]) / s
    return m, q


def sky_of_pixel(m, f_px, px, py):
    """The ICRS RA, Dec (deg) the pinhole sees at 0-based pixel (px, py)."""
    d = [(px - (W - 1) / 2) / f_px, (py - (H - 1) / 2) / f_px, 1.0]
    v = [sum(m[i][k] * d[k] for k in range(3)) for i in range(3)]
    n = math.sqrt(sum(c * c for c in v))
    return math.degrees(math.atan2(v[1], v[0])) % 360, math.degrees(math.asin(v[2] / n))


def sep_arcsec(a, b):
    (r1, d1), (r2, d2) = [(math.radians(r), math.radians(d)) for r, d in (a, b)]
    c = math.sin(d1) * math.sin(d2) + math.cos(d1) * math.cos(d2) * math.cos(r1 - r2)
    return math.degrees(math.acos(min(1.0, c))) * 3600


def position_angle(a, b):
    """East of north, deg, of b seen from a."""
    (r1, d1), (r2, d2) = [(math.radians(r), math.radians(d)) for r, d in (a, b)]
    return math.degrees(math.atan2(math.sin(r2 - r1) * math.cos(d2),
                                   math.cos(d1) * math.sin(d2) - math.sin(d1) * math.cos(d2) * math.cos(r2 - r1)))


cases = [  # field of view (deg), RA, Dec, roll (deg), exposure (s)
    (5.0, 201.3, -11.2, 20.0, 0.5),
    (20.0, 83.8, -5.4, -30.0, 4.0),
    (60.0, 10.0, 60.0, 75.0, 8.0),
    (10.0, 359.5, 2.0, 150.0, 1.0),    # across RA 0
    (40.0, 270.0, -60.0, -120.0, 6.0),
]
failed = 0
for fov, ra, dec, roll, t in cases:
    f_m = W * PITCH / (2 * math.tan(math.radians(fov) / 2))
    m, q = attitude(ra, dec, roll)
    behind = [-1e7 * c for c in unit(math.radians(ra), math.radians(dec))]  # the body, and the Sun's side
    name = f"fov{fov:g}"
    scene = os.path.join(tmp, name + ".yaml")
    with open(scene, "w") as fh:
        fh.write(f"""# {fov} deg field at RA {ra} Dec {dec} roll {roll}; a body behind the camera
bodies:
  - name: behind
    shape: {{type: sphere, radius_m: 1000}}
    position_m: [{behind[0]!r}, {behind[1]!r}, {behind[2]!r}]
    material: {{model: lambert, A: 0.1}}
sun: {{direction: [{behind[0] / 1e7!r}, {behind[1] / 1e7!r}, {behind[2] / 1e7!r}]}}  # behind the camera
camera: {{width_px: {W}, height_px: {H}, focal_length_m: {f_m!r}, pixel_pitch_m: {PITCH},
         position_m: [0, 0, 0], attitude_q: [{q[0]!r}, {q[1]!r}, {q[2]!r}, {q[3]!r}]}}
render: {{samples_per_pixel: 1}}
optics: {{f_number: 4.0, transmission: 0.9, passband: {{from_m: 5.0e-7, to_m: 7.0e-7}},
         vignetting: cos4, psf: {{type: gaussian, sigma_px: 0.7}}}}
sensor: {{qe: 0.6, dark_current_e_s: 20, dark_ref_temp_k: 293.15, dark_doubling_k: 6.5,
         temperature_k: 283.15, read_noise_e: 8, full_well_e: 20000, gain_e_per_dn: 5.0,
         bias_dn: 64, adc_bits: 12, seed: 3}}
exposure: {{time_s: {t}}}
stars: {{catalogue: '{index}'}}
""")
    img = os.path.join(tmp, name + ".fits")
    out = subprocess.run([navcam, "render", scene, "-o", img, "-q", "dn", "--fits-rows", "bottom_up"],
                         capture_output=True, text=True)
    stars_line = [ln for ln in out.stdout.splitlines() if "stars:" in ln]
    if out.returncode != 0 or not stars_line:
        print(out.stdout, out.stderr)
        sys.exit(f"test_platesolve: {name}: the render failed")
    # NavCam's own WCS in the frame's header (TAN, exact for a pinhole),
    # read by astrometry.net's wcs-xy2rd: bottom-up rows, then the same frame
    # written top-down (image (x, y) is FITS (x + 1, y + 1) there).
    top = os.path.join(tmp, name + "_top.fits")
    if subprocess.run([navcam, "render", scene, "-o", top, "-q", "dn"], capture_output=True).returncode != 0:
        sys.exit(f"test_platesolve: {name}: the top-down render failed")
    cx, cy = (W - 1) / 2, (H - 1) / 2
    for path, row in ((img, lambda y: H - y), (top, lambda y: y + 1)):
        own = []
        for px, py in ((cx, cy), (cx - 300, cy - 400)):
            r = subprocess.run(["wcs-xy2rd", "-w", path, "-x", repr(px + 1), "-y", repr(row(py))],
                               capture_output=True, text=True, check=True)
            a, b = r.stdout.split("RA,Dec")[1].strip().strip("()").split(",")[:2]
            own.append(((float(a), float(b.strip(" )\n"))), sky_of_pixel(m, f_m / PITCH, px, py)))
        worst = max(sep_arcsec(got, want) for got, want in own)
        ok = worst < 0.01
        failed += not ok
        print(f"{name}: NavCam's own WCS ({os.path.basename(path)}): worst {worst:.2e} arcsec "
              f"{'ok' if ok else 'FAILED (0.01 arcsec)'}")
    sol = os.path.join(tmp, name)
    subprocess.run(["solve-field", "--overwrite", "--no-plots", "--no-remove-lines", "--cpulimit", "120",
                    "--scale-units", "degwidth", "--scale-low", str(0.9 * fov), "--scale-high", str(1.1 * fov),
                    "--crpix-center", "--dir", sol, img], capture_output=True, text=True)
    wcs = os.path.join(sol, name + ".wcs")
    if not os.path.exists(os.path.join(sol, name + ".solved")):
        print(f"{name}: NOT SOLVED ({stars_line[0].strip()})")
        failed += 1
        continue
    # FITS pixels are 1-based with row 1 at the bottom: image (x, y) is
    # FITS (x + 1, H - y).
    cx, cy = (W - 1) / 2, (H - 1) / 2
    pts = [(cx, cy), (cx, cy - 400)]
    solved = []
    for px, py in pts:
        r = subprocess.run(["wcs-xy2rd", "-w", wcs, "-x", repr(px + 1), "-y", repr(H - py)],
                           capture_output=True, text=True, check=True)
        # "Pixel (x, y) -> RA,Dec (ra, dec)"
        txt = r.stdout.split("RA,Dec")[1]
        a, b = txt.strip().strip("()").split(",")[:2]
        solved.append((float(a), float(b.strip(" )\n"))))
    truth = [sky_of_pixel(m, f_m / PITCH, px, py) for px, py in pts]
    err_point = sep_arcsec(solved[0], truth[0])
    pa_solved, pa_true = position_angle(solved[0], solved[1]), position_angle(truth[0], truth[1])
    err_roll = (pa_solved - pa_true + 180) % 360 - 180
    ok = err_point < 5 and abs(err_roll) < 0.05
    failed += not ok
    print(f"{name}: {stars_line[0].strip()}; solved centre {solved[0][0]:.5f} {solved[0][1]:.5f} "
          f"(pose {truth[0][0]:.5f} {truth[0][1]:.5f}): pointing off by {err_point:.2f} arcsec, "
          f"roll by {err_roll:+.4f} deg {'ok' if ok else 'FAILED (5 arcsec, 0.05 deg)'}")
# The boresight on the celestial pole (the identity attitude, Dec +90 exactly), NavCam's WCS read by astropy: with
# LONPOLE 180 (FITS's default there is 0; without it every reader turned the frame by 180 deg, stars 693 px off).
f_m = W * PITCH / (2 * math.tan(math.radians(20) / 2))
f_px = f_m / PITCH
pole, pole_fits = os.path.join(tmp, "pole.yaml"), os.path.join(tmp, "pole.fits")
with open(pole, "w") as fh:
    fh.write(f"""bodies: [{{shape: {{type: sphere, radius_m: 1000}}, position_m: [0, 0, -1.0e7],
          material: {{model: lambert, A: 0.1}}}}]
sun: {{direction: [0, 0, -1]}}
camera: {{width_px: {W}, height_px: {H}, focal_length_m: {f_m!r}, pixel_pitch_m: {PITCH}, position_m: [0, 0, 0],
         attitude_q: [1, 0, 0, 0]}}
render: {{samples_per_pixel: 1}}
optics: {{f_number: 4.0, passband: {{from_m: 5.0e-7, to_m: 7.0e-7}}}}
stars: {{catalogue: '{index}'}}
""")
subprocess.run([navcam, "render", pole, "-o", pole_fits, "-q", "electrons"], check=True, capture_output=True)
wcs = WCS(fits.getheader(pole_fits))
cx, cy = (W - 1) / 2, (H - 1) / 2
ident = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
worst = max(sep_arcsec(tuple(wcs.all_pix2world([[px + 1, py + 1]], 1)[0]), sky_of_pixel(ident, f_px, px, py))
            for px, py in ((cx + 100, cy), (cx - 300, cy - 400), (0, H - 1)))
ok = worst < 0.01
failed += not ok
print(f"the pole (identity attitude): NavCam's WCS read by astropy, worst {worst:.2e} arcsec "
      f"{'ok' if ok else 'FAILED (0.01 arcsec)'}")
sys.exit(1 if failed else 0)
