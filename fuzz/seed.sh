#!/usr/bin/env bash
# fuzz/seed.sh [BUILD]: writes the seed corpora fuzz/corpus/<target>/ from the shipped scenes,
# meshes and lamps, and from tiny renders of grids.json by BUILD/wedge (default build/). Small on
# purpose: libFuzzer mutates short inputs fastest, and the repository stays small. The JPEG seeds
# need cjpeg (Debian: libjpeg-turbo-progs); the corpus is committed, so only this script does.
set -euo pipefail
cd "$(dirname "$0")/.."
wedge=${1:-build}/wedge
out=fuzz/corpus
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rm -rf "$out"
mkdir -p "$out"/{scene,obj,png,jpeg,exr,pfm,compare}

sep() { printf '\n@@@ %s\n' "$1"; }  # starts a further file of an input (fuzz/targets.h)

# Images: grids at a few tiny sizes, one sample per pixel.
render() {  # render WxH OUT...
  local size=$1
  shift
  local outs=()
  for o in "$@"; do outs+=(-o "$o"); done
  "$wedge" render scenes/grids/grids.json --resolution "$size" --spp 1 --quiet "${outs[@]}"
}
render 8x8 "$tmp/a.png" "$tmp/a.pfm" "$tmp/a.exr"
render 5x3 "$tmp/b.png" "$tmp/b.pfm" "$tmp/b.exr"
render 8x8 "$tmp/c.png" "$tmp/c.pfm"
{ printf 'P6\n8 8\n255\n'; for i in $(seq 0 63); do printf "\\x$(printf %02x $((i * 4)))\\x40\\x$(printf %02x $((255 - i * 3)))"; done; } > "$tmp/a.ppm"

cp "$tmp/a.png" "$out/png/grids-8x8.png"
cp "$tmp/b.png" "$out/png/grids-5x3.png"
cp "$tmp/a.pfm" "$out/pfm/grids-8x8.pfm"
cp "$tmp/b.pfm" "$out/pfm/grids-5x3.pfm"
cp "$tmp/a.exr" "$out/exr/grids-8x8-buffers.exr"
cp "$tmp/b.exr" "$out/exr/grids-5x3-buffers.exr"
cjpeg -quality 90 "$tmp/a.ppm" > "$out/jpeg/rgb.jpg"
cjpeg -quality 60 -progressive "$tmp/a.ppm" > "$out/jpeg/progressive.jpg"
cjpeg -grayscale "$tmp/a.ppm" > "$out/jpeg/grey.jpg"
cjpeg -sample 1x1 -optimize "$tmp/a.ppm" > "$out/jpeg/444-optimized.jpg"

# compare: TEST, then "@@@ NAME" and REF; a first line "@@@ NAME" names TEST's format.
{ cat "$tmp/a.exr"; sep ref.exr; cat "$tmp/a.exr"; } > "$out/compare/exr-exr"
{ sep a.png; cat "$tmp/a.png"; sep c.png; cat "$tmp/c.png"; } | tail -c +2 > "$out/compare/png-png"
{ sep a.pfm; cat "$tmp/a.pfm"; sep c.png; cat "$tmp/c.png"; } | tail -c +2 > "$out/compare/pfm-png"
{ sep b.pfm; cat "$tmp/b.pfm"; sep a.pfm; cat "$tmp/a.pfm"; } | tail -c +2 > "$out/compare/size-mismatch"

# Scenes: as shipped where they name no file, with their meshes (and a texture) served otherwise.
cp scenes/grids/grids.json "$out/scene/grids.json"
cp docs/lamps/sphere.json "$out/scene/lamp-sphere.json"
cp docs/lamps/square-fan.json "$out/scene/lamp-square-fan.json"
cp docs/motion.json "$out/scene/motion.json"
cp scenes/raster/pan.json "$out/scene/raster-pan.json"
cat > "$out/scene/turning.json" <<'JSON'
{"camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "up": [0, 1, 0], "fov_y": 40, "resolution": [16, 16],
            "shutter": [0, 0.5], "velocity": [0.2, 0, 0], "look_at_velocity": [0, 0, 0.1]},
 "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
 "lights": [{"type": "parallelogram", "corner": [-0.5, 3, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": [5, 5, 5]}],
 "objects": [{"type": "box", "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5], "material": "white",
              "angular_velocity": [0, 1, 0, 60], "pivot": [0, 0, 0], "velocity": [0, 0, 0.3]},
             {"type": "quad", "corner": [-3, 0, 3], "edge1": [6, 0, 0], "edge2": [0, 0, -6], "material": "white",
              "angular_velocity": [1, 0, 0, 5]}]}
JSON
{ cat scenes/cornell/cornell.json; sep CornellBox-Original.obj; cat scenes/cornell/CornellBox-Original.obj
  sep CornellBox-Original.mtl; cat scenes/cornell/CornellBox-Original.mtl; } > "$out/scene/cornell-with-mesh"
{ cat docs/lamps/disc-and-triangle.json; sep disc.obj; cat docs/lamps/disc.obj; sep disc.mtl; cat docs/lamps/disc.mtl
  printf 'map_Kd t.png\n'; sep t.png; cat "$tmp/a.png"; } > "$out/scene/disc-textured"

# OBJ/MTL: the meshes with their materials and textures.
{ cat scenes/cornell/CornellBox-Original.obj; sep CornellBox-Original.mtl; cat scenes/cornell/CornellBox-Original.mtl; } > "$out/obj/cornell"
{ cat docs/lamps/disc.obj; sep disc.mtl; cat docs/lamps/disc.mtl; } > "$out/obj/disc"
{ cat docs/lamps/disc.obj; sep disc.mtl; cat docs/lamps/disc.mtl; printf 'map_Kd -s 2 2 1 t.jpg\n'; sep t.jpg
  cat "$out/jpeg/rgb.jpg"; } > "$out/obj/disc-textured"
cp docs/lamps/disc250.obj "$out/obj/disc250.obj"

du -sh "$out"
