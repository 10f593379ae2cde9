# guest_lib.sh - what the guest scripts (guest_v4l2_gpio.sh, guest_usb.sh)
# share; sourced, inside the test guest.

step() { echo "== $*"; }

# sim_chip NAME NUM_LINES: a live gpio-sim chip whose lines 0 and 1 are
# named TRIG and STROBE; sets $chip (gpiochipN) and $sim (its sysfs
# directory, where sim_gpioK/pull drives line K and sim_gpioK/value reads it).
sim_chip() {
    local cfs=/sys/kernel/config/gpio-sim/$1
    mkdir "$cfs" "$cfs/bank0"
    echo "$2" >"$cfs/bank0/num_lines"
    mkdir "$cfs/bank0/line0" "$cfs/bank0/line1"
    echo TRIG >"$cfs/bank0/line0/name"
    echo STROBE >"$cfs/bank0/line1/name"
    echo 1 >"$cfs/live"
    chip=$(cat "$cfs/bank0/chip_name")
    sim=/sys/devices/platform/$(cat "$cfs/dev_name")/$chip
}

# listening PID LOG: wait until navcam serve (PID) says in LOG that it
# listens (up to 60 s: the scene takes seconds to build under TCG); fails
# if it exits first or never says so.
listening() {
    for _ in $(seq 600); do
        grep -q "SIGINT or SIGTERM stops" "$2" 2>/dev/null && return 0
        kill -0 "$1" 2>/dev/null || return 1
        sleep 0.1
    done
    return 1
}

# The small scene every phase renders: 64x48 frames, 50 ms exposures (an
# easy strobe to see) through an ND filter, so that 8-bit frames are not
# saturated and every frame's noise differs; triggered.
small=(--set camera.width_px=64 --set camera.height_px=48 --set bodies.0.shape.subdivisions=4
       --set render.samples_per_pixel=1 --set serve.stats_interval_s=0 --set sensor.adc_bits=8
       --set sensor.gain_e_per_dn=10 --set exposure.time_s=0.05 --set optics.transmission=0.002
       --set serve.mode=trigger)
