#!/usr/bin/env bash
# Installs the Debian packages NavCam needs to build, test and run, and nothing else.
# Idempotent: packages already present are not touched and apt is not called at all.
set -euo pipefail

pkgs=(cmake make gcc g++ pkg-config libembree-dev libopenimageio-dev libyaml-dev libcfitsio-dev libfftw3-dev librandom123-dev zlib1g-dev
      clang libclang-rt-14-dev python3 libaravis-dev libusb-1.0-0-dev aravis-tools-cli)
case "$(uname -m)" in x86_64) pkgs+=(libsleef-dev) ;; esac

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
