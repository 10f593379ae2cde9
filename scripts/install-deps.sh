#!/usr/bin/env bash
# Installs the Debian packages NavCam needs to build, test and run, and nothing else.
# Idempotent: packages already present are not touched and apt is not called at all.
#   install-deps.sh          what building and running NavCam needs
#   install-deps.sh --test   also what the tests need, including the qemu guest
#                            of tests/vm (Debian's kernel headers, v4l2loopback
#                            built by dkms, qemu, busybox)
set -euo pipefail

pkgs=(cmake make gcc g++ pkg-config libembree-dev libopenimageio-dev libyaml-dev libcfitsio-dev libfftw3-dev librandom123-dev zlib1g-dev
      libmeshoptimizer-dev python3 libaravis-dev libusb-1.0-0-dev libgpiod-dev
      gnuplot-nox)
case "$(uname -m)" in x86_64) pkgs+=(libsleef-dev) ;; esac
if [ "${1:-}" = --test ]; then
  pkgs+=(clang libclang-rt-14-dev aravis-tools-cli gpiod v4l-utils)
  case "$(uname -m)" in
    x86_64) pkgs+=(qemu-system-x86 busybox-static cpio kmod xz-utils dkms linux-headers-amd64 v4l2loopback-dkms) ;;
  esac
fi

missing=()
for p in "${pkgs[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
