#!/bin/sh
# navcam-usb-gadget.sh - make (or remove) the configfs USB gadget that
# navcam-usb-adapter serves: one configuration with one FunctionFS function,
# mounted where the adapter reads it. The adapter binds the gadget to the
# USB device controller itself, once it has written its descriptors.
#
#   navcam-usb-gadget.sh setup    [--name N] [--ffs DIR] [--id VID:PID] [--serial S]
#   navcam-usb-gadget.sh teardown [--name N] [--ffs DIR]
#
# Defaults: --name navcam, --ffs /run/navcam-usb-adapter, --id 1209:0001
# (pid.codes' test ID: fine in a lab, not for a product), --serial from
# /etc/machine-id. Needs root, configfs and the libcomposite and usb_f_fs
# modules (Raspberry Pi OS: dtoverlay=dwc2 in config.txt, then modprobe dwc2).
set -eu
usage() { sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
[ $# -ge 1 ] || usage
cmd=$1; shift
name=navcam ffs=/run/navcam-usb-adapter id=1209:0001
serial=$(cut -c1-16 /etc/machine-id 2>/dev/null || echo 0001)
while [ $# -gt 0 ]; do
    case $1 in
        --name) name=$2; shift 2 ;;
        --ffs) ffs=$2; shift 2 ;;
        --id) id=$2; shift 2 ;;
        --serial) serial=$2; shift 2 ;;
        *) usage ;;
    esac
done
g=/sys/kernel/config/usb_gadget/$name

case $cmd in
setup)
    modprobe libcomposite 2>/dev/null || true
    modprobe usb_f_fs 2>/dev/null || true
    [ -d /sys/kernel/config/usb_gadget ] || mount -t configfs none /sys/kernel/config
    [ -d /sys/kernel/config/usb_gadget ] || { echo "navcam-usb-gadget.sh: no usb_gadget in configfs (is libcomposite loaded?)" >&2; exit 1; }
    [ ! -e "$g" ] || { echo "navcam-usb-gadget.sh: $g exists (teardown first)" >&2; exit 1; }
    mkdir "$g"
    echo "0x${id%%:*}" >"$g/idVendor"
    echo "0x${id##*:}" >"$g/idProduct"
    echo 0x0100 >"$g/bcdDevice"
    echo 0x0200 >"$g/bcdUSB"
    mkdir "$g/strings/0x409"
    echo "$serial" >"$g/strings/0x409/serialnumber"
    echo NavCam >"$g/strings/0x409/manufacturer"
    echo "NavCam USB trigger adapter" >"$g/strings/0x409/product"
    mkdir "$g/configs/c.1" "$g/configs/c.1/strings/0x409"
    echo trigger >"$g/configs/c.1/strings/0x409/configuration"
    echo 100 >"$g/configs/c.1/MaxPower"
    mkdir "$g/functions/ffs.$name"
    ln -s "$g/functions/ffs.$name" "$g/configs/c.1/"
    mkdir -p "$ffs"
    mount -t functionfs "$name" "$ffs"
    echo "navcam-usb-gadget.sh: gadget $g, FunctionFS at $ffs (id $id, serial $serial)"
    ;;
teardown)
    [ -e "$g/UDC" ] && { echo "" >"$g/UDC"; } 2>/dev/null || true
    umount "$ffs" 2>/dev/null || true
    rm -f "$g/configs/c.1/ffs.$name"
    for d in "$g/configs/c.1/strings/0x409" "$g/configs/c.1" "$g/functions/ffs.$name" "$g/strings/0x409" "$g"; do
        [ ! -d "$d" ] || rmdir "$d"
    done
    ;;
*) usage ;;
esac
