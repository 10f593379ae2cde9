#!/usr/bin/env bash
# The pictures of docs/terrain.md: the example scenes, and the built-in
# default scene's asteroid close up with a million rough boulders (twice),
# each at
# 512x512 (the example scenes' 1024x1024 views with the pixel pitch doubled:
# the same field of view), as navcam render's 16-bit linear previews.
# bennu_rubble.yaml reads the Bennu shape model from ../shared/data/shapes.
# Usage: scripts/terrain_pictures.sh NAVCAM_BINARY [OUTDIR (default docs/terrain)]
set -euo pipefail
navcam=$(readlink -f "${1:?usage: terrain_pictures.sh NAVCAM [OUTDIR]}")
here=$(cd "$(dirname "$0")/.." && pwd)
out=${2:-$here/docs/terrain}
mkdir -p "$out"
half=(--set camera.width_px=512 --set camera.height_px=512)
for scene in procedural_asteroid bennu_rubble lunar_tile; do
  yaml=$here/configs/examples/$scene.yaml
  pitch=$(awk '$1 == "pixel_pitch_m:" { print 2 * $2 }' "$yaml")
  "$navcam" render "$yaml" -o "$out/$scene.png" "${half[@]}" --set camera.pixel_pitch_m="$pitch"
done
# 526 m from the centre (about 300 m above the ground) and 376 m (about
# 150 m: rocks of 2 m and more are detailed surfaces), 0.45 m to 64 m rocks
for at in 526 376; do
  name=default_rocks_close; [ "$at" = 376 ] && name=default_rocks_150m
  "$navcam" render -o "$out/$name.png" "${half[@]}" \
    --set 'bodies[0].boulders={preset: bennu, min_diameter_m: 0.45, roughness_deg: 20}' \
    --set "camera.position_m=[0, -$at, 0]"
done
