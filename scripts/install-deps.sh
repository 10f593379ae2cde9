#!/usr/bin/env bash
# Installs the Debian packages NavCam needs to build, test and run, and nothing else.
# Idempotent: packages already present are not touched and apt is not called at all.
#   install-deps.sh          what building and running NavCam needs
#   install-deps.sh --test   also what the tests need, including the qemu guest
#                            of tests/vm (Debian's kernel headers, v4l2loopback
#                            built by dkms, qemu, busybox), the plate solver
#                            (astrometry.net with its Tycho-2 index files for
#                            fields of 1 to 33 degrees' quads) and the star
#                            catalogue below, and a single-node Slurm
#                            (slurmctld, slurmd, munge) for navcam batch
#   install-deps.sh --stars  also the star catalogue: KStars' stars.dat
#                            (Hipparcos and Tycho, V <= 8.99, J2000, GPL-2+ as
#                            Debian ships it) taken out of the kstars-data
#                            package without installing KStars, to
#                            /usr/local/share/navcam/stars.dat (docs/stars.md)
set -euo pipefail
stars_dat=/usr/local/share/navcam/stars.dat

pkgs=(cmake make gcc g++ pkg-config libembree-dev libopenimageio-dev libyaml-dev libcfitsio-dev libfftw3-dev librandom123-dev zlib1g-dev
      libmeshoptimizer-dev python3 libaravis-dev libusb-1.0-0-dev libgpiod-dev
      gnuplot-nox)
case "$(uname -m)" in x86_64) pkgs+=(libsleef-dev) ;; esac
if [ "${1:-}" = --test ]; then
  pkgs+=(clang libclang-rt-14-dev valgrind python3-astropy aravis-tools-cli gpiod v4l-utils astrometry.net
         astrometry-data-tycho2-10-19-littleendian slurmctld slurmd slurm-client munge)
  case "$(uname -m)" in
    x86_64) pkgs+=(qemu-system-x86 busybox-static cpio kmod xz-utils dkms linux-headers-amd64 v4l2loopback-dkms udev) ;;
  esac
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive

missing=()
for p in "${pkgs[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ -n "$sudo" ] && ! command -v sudo >/dev/null; then
    echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
    exit 1
  fi
  echo "install-deps: installing ${missing[*]}"
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The star catalogue: one file out of kstars-data (its other 120 MB and
# KStars itself are not needed).
if { [ "${1:-}" = --test ] || [ "${1:-}" = --stars ]; } && [ ! -s "$stars_dat" ]; then
  echo "install-deps: extracting stars.dat from kstars-data to $stars_dat"
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  (cd "$tmp" && { apt-get download -qq kstars-data 2>/dev/null || { $sudo apt-get update -qq && apt-get download -qq kstars-data; }; })
  $sudo mkdir -p "$(dirname "$stars_dat")"
  dpkg-deb --fsys-tarfile "$tmp"/kstars-data_*.deb | tar -xO ./usr/share/kstars/stars.dat > "$tmp/stars.dat"
  [ -s "$tmp/stars.dat" ] || { echo "install-deps: no stars.dat in kstars-data" >&2; exit 1; }
  $sudo install -m 0644 "$tmp/stars.dat" "$stars_dat"
fi
