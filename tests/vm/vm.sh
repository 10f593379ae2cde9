#!/usr/bin/env bash
# vm.sh - boot Debian's own kernel under qemu with the real v4l2loopback,
# vivid and gpio-sim drivers and the USB gadget stack (dummy_hcd,
# libcomposite, FunctionFS), and run one script inside it.
#
#   vm.sh prepare              build (or find cached) kernel, modules, gpio-sim
#   vm.sh run SCRIPT OUTDIR [TIMEOUT_S] [ARGS...]
#
# The guest is a busybox initramfs that loads the modules, then mounts the
# host's root file system read-only over 9p and chroots into it, so NavCam's
# binaries run inside the guest with the very libraries they were built
# against; OUTDIR is shared read-write for results. SCRIPT runs as
# `bash SCRIPT OUTDIR ARGS...` and its exit status comes back through
# qemu's isa-debug-exit port. A panic, a hang past TIMEOUT_S or a missing
# status is a failure; the guest console is kept in OUTDIR/console.log and
# printed on failure.
#
# Facts this relies on: ../shared/notes/kernel-drivers-in-qemu.md.
# Cache: $NAVCAM_VM_CACHE (default /var/cache/navcam-vm), one directory per
# kernel version and version of this script (a changed module list or recipe
# rebuilds); delete it to rebuild.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
cache_root=${NAVCAM_VM_CACHE:-/var/cache/navcam-vm}

die() { echo "vm.sh: $*" >&2; exit 1; }

# apt-get download into the current directory; refresh the package lists
# once if they are missing or stale.
apt_download() {
    apt-get download -q "$@" >/dev/null 2>&1 && return
    apt-get update -qq >/dev/null 2>&1 && apt-get download -q "$@" >/dev/null 2>&1
}

# The kernel whose headers are installed (scripts/install-deps.sh installs
# linux-headers-amd64 and v4l2loopback-dkms, which dkms builds for it).
kernel_version() {
    local dep
    dep=$(dpkg-query -W -f='${Depends}' linux-headers-amd64 2>/dev/null) ||
        die "linux-headers-amd64 is not installed (run scripts/install-deps.sh)"
    dep=${dep%% *}
    echo "${dep#linux-headers-}"
}

# The uncompressed ELF vmlinux inside a bzImage (its payload is xz): booting
# it through PVH saves about 6 s of decompression under TCG.
extract_vmlinux() {
    local bz=$1 out=$2 off
    off=$(grep -abo $'\xfd7zXZ\x00' "$bz" | head -1 | cut -d: -f1) || true
    [[ -n $off ]] || die "$bz: no xz payload found"
    tail -c +$((off + 1)) "$bz" | xz -dc --single-stream >"$out" 2>/dev/null || true
    [[ $(head -c 4 "$out" | od -An -c | tr -d ' ') == 177ELF ]] || die "$bz: payload is not an ELF kernel"
}

# gpio-sim is not built in Debian's 6.1 kernel: build it out of tree from the
# matching linux-source, with irq_sim linked in (irq_to_desc() is not
# exported; generic_handle_domain_irq() does the same lookup and call).
build_gpio_sim() {
    local kver=$1 work=$2 out=$3 srcver
    srcver=${kver%%-*}; srcver=${srcver%.*}   # 6.1.0-56-amd64 -> 6.1
    (cd "$work" && apt_download "linux-source-$srcver") ||
        die "apt-get download linux-source-$srcver failed"
    local d=linux-source-$srcver
    dpkg-deb --fsys-tarfile "$work"/linux-source-"$srcver"_*.deb |
        tar -xO "./usr/src/$d.tar.xz" |
        tar -xJ -C "$work" "$d/drivers/gpio/gpio-sim.c" "$d/drivers/gpio/gpiolib.h" "$d/kernel/irq/irq_sim.c"
    mkdir -p "$work/gpio-sim"
    cp "$work/$d/drivers/gpio/gpio-sim.c" "$work/$d/drivers/gpio/gpiolib.h" "$work/gpio-sim/"
    sed 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_domain_irq(work_ctx->domain, offset);/' \
        "$work/$d/kernel/irq/irq_sim.c" >"$work/gpio-sim/irq_sim.c"
    grep -q generic_handle_domain_irq "$work/gpio-sim/irq_sim.c" || die "irq_sim.c: the irq_to_desc() call was not found"
    printf 'obj-m := gpio-sim.o\ngpio-sim-y := gpio-sim-core.o irq_sim.o\n' >"$work/gpio-sim/Kbuild"
    mv "$work/gpio-sim/gpio-sim.c" "$work/gpio-sim/gpio-sim-core.c"
    make -s -C "/usr/src/linux-headers-$kver" M="$work/gpio-sim" modules >"$work/gpio-sim/build.log" 2>&1 ||
        { cat "$work/gpio-sim/build.log" >&2; die "gpio-sim build failed"; }
    cp "$work/gpio-sim/gpio-sim.ko" "$out"
}

prepare() {
    local kver cache work
    kver=$(kernel_version)
    cache=$cache_root/$kver-$(sha256sum "$here/vm.sh" | cut -c1-12)
    if [[ -f $cache/ready ]]; then
        echo "$cache"
        return
    fi
    local dkms_ko=/lib/modules/$kver/updates/dkms/v4l2loopback.ko
    [[ -f $dkms_ko ]] || die "$dkms_ko missing: dkms did not build v4l2loopback for $kver (is v4l2loopback-dkms installed?)"
    rm -rf "$cache_root/$kver" "$cache_root/$kver"-* # guests of older versions of this script
    mkdir -p "$cache"
    work=$(mktemp -d)
    trap 'rm -rf "$work"' RETURN
    echo "vm.sh: building the guest for $kver in $cache" >&2
    (cd "$work" && apt_download "linux-image-$kver") || die "apt-get download linux-image-$kver failed"
    dpkg-deb -x "$work"/linux-image-"$kver"_*.deb "$work/img"
    extract_vmlinux "$work/img/boot/vmlinuz-$kver" "$cache/vmlinux"
    build_gpio_sim "$kver" "$work" "$work/gpio-sim.ko"
    # The module tree: the image's modules plus ours, then only the closure
    # of what the guest loads goes into the initramfs (see run()).
    local mods=$work/img/lib/modules/$kver
    mkdir -p "$mods/updates"
    cp "$dkms_ko" "$work/gpio-sim.ko" "$mods/updates/"
    depmod -b "$work/img" "$kver"
    local root=$cache/modroot
    mkdir -p "$root/lib/modules/$kver"
    cp "$mods"/modules.builtin* "$mods"/modules.order "$root/lib/modules/$kver/"
    local m line path
    for m in virtio_pci 9pnet_virtio 9p configfs videodev v4l2loopback vivid gpio-sim dummy_hcd libcomposite usb_f_fs; do
        while read -r line; do
            [[ $line == insmod* ]] || continue
            path=${line#insmod }; path=${path%% *}
            mkdir -p "$root/$(dirname "${path#"$work/img"}")"
            cp -n "$path" "$root/${path#"$work/img"}"
        done < <(modprobe -d "$work/img" -S "$kver" --show-depends "$m")
    done
    depmod -b "$root" "$kver"
    echo "$kver" >"$cache/ready"
    echo "$cache"
}

run() {
    local script=$1 outdir=$2 timeout_s=${3:-300}
    shift 3 || shift $#
    [[ -f $script ]] || die "$script: no such script"
    local cache kver
    cache=$(prepare)
    kver=$(cat "$cache/ready")
    mkdir -p "$outdir"
    outdir=$(cd "$outdir" && pwd)
    script=$(cd "$(dirname "$script")" && pwd)/$(basename "$script")
    # The initramfs: busybox, the modules, /init, and what to run.
    local rd
    rd=$(mktemp -d)
    mkdir -p "$rd"/{bin,dev,proc,sys,host}
    cp /bin/busybox "$rd/bin/busybox"
    ln -s busybox "$rd/bin/sh"
    cp -a "$cache/modroot/lib" "$rd/"
    cp "$here/init" "$rd/init"
    chmod +x "$rd/init"
    printf 'NAVCAM_VM_OUT=%s\n' "$outdir" >"$rd/vm.env"
    {
        printf 'export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin TMPDIR=/run/tmp\nmkdir -p /run/tmp\ncd %q || exit 1\nexec bash %q %q' "$outdir" "$script" "$outdir"
        printf ' %q' "$@"
        printf '\n'
    } >"$outdir/launch.sh"
    (cd "$rd" && find . | cpio -o -H newc --quiet) >"$outdir/initramfs.cpio"
    rm -rf "$rd"
    # A guest that has not reached its /init (which prints "init: up" first)
    # within boot_s never does: qemu's TCG has hung early in the boot (seen
    # once in many runs here, with nothing on the console after the BIOS).
    # Such a boot is started again, once, and said so; a hang after /init is
    # the test's own and fails it.
    local rc try boot_s=${NAVCAM_VM_BOOT_S:-120}
    for try in 1 2; do
        rc=0
        # No AVX in the guest CPU: TCG emulates AVX2 so slowly that a 64x48
        # frame takes 640 ms with Embree's and SLEEF's AVX2 code and 96 ms with
        # their SSE/libm paths (one run here).
        timeout --foreground -k 5 "$timeout_s" qemu-system-x86_64 \
            -accel tcg,thread=multi -cpu "${NAVCAM_VM_CPU:-Nehalem}" -machine q35 -m 2048 -smp 2 -nographic -no-reboot \
            -kernel "$cache/vmlinux" -initrd "$outdir/initramfs.cpio" \
            -append "console=ttyS0 panic=-1 quiet loglevel=4 rdinit=/init" \
            -device isa-debug-exit,iobase=0xf4,iosize=0x04 \
            -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
            -virtfs local,path="$outdir",mount_tag=out,security_model=none,multidevs=remap \
            -nic none </dev/null >"$outdir/console.log" 2>&1 &
        local qemu=$! waited=0
        while kill -0 "$qemu" 2>/dev/null && ! grep -q 'init: up' "$outdir/console.log" && ((waited < boot_s)); do
            sleep 1
            waited=$((waited + 1))
        done
        if ((try == 1)) && kill -0 "$qemu" 2>/dev/null && ! grep -q 'init: up' "$outdir/console.log"; then
            kill "$qemu" 2>/dev/null
            wait "$qemu" 2>/dev/null || true
            echo "vm.sh: the guest did not reach its /init within ${boot_s} s (console: $(tr -cd '[:print:]' <"$outdir/console.log" | tail -c 120)); booting it again" >&2
            continue
        fi
        wait "$qemu" || rc=$?
        break
    done
    rm -f "$outdir/initramfs.cpio"
    # isa-debug-exit: the guest writes N, qemu exits (N << 1) | 1.
    # The guest writes 1 for pass and 2 for fail.
    local verdict
    case $rc in
        3) return 0 ;;
        5) verdict="the guest script failed" ;;
        124 | 137) verdict="timeout after ${timeout_s} s" ;;
        0) verdict="the guest panicked or powered off without a status" ;;
        *) verdict="qemu exited with status $rc" ;;
    esac
    echo "vm.sh: $verdict; guest console ($outdir/console.log):" >&2
    cat "$outdir/console.log" >&2
    return 1
}

case ${1:-} in
    prepare) prepare ;;
    run) shift; [[ $# -ge 2 ]] || die "usage: vm.sh run SCRIPT OUTDIR [TIMEOUT_S] [ARGS...]"; run "$@" ;;
    *) echo "usage: vm.sh prepare | vm.sh run SCRIPT OUTDIR [TIMEOUT_S] [ARGS...]" >&2; exit 2 ;;
esac
