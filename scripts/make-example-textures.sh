#!/usr/bin/env bash
# Regenerates examples/textures/ (committed; run this only to change them). Small sRGB-authored
# textures for the example materials: painted metal, gold trim, wood, rubber, glass with a mask.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=$root/examples/textures
mkdir -p "$out"
size=256x256
noise() { echo "--pattern noise:type=uniform:min=$1:max=$2:mono=1:seed=$3 $size 3"; }

# Painted metal: blue-grey paint with fine speckle.
oiiotool --pattern constant:color=0.20,0.32,0.45 $size 3 $(noise -0.03 0.03 1) --add \
  -d uint8 -o "$out/painted_metal_albedo.png"
# Gold trim: the specular colour of gold (the material table's F0 0.966, 0.820, 0.389 is sRGB
# 251, 234, 167), slightly brushed: within the table's 10% so that `reference = "gold"` passes.
oiiotool --pattern constant:color=0.990,0.922,0.660 $size 3 $(noise -0.012 0.0 2) --add \
  -d uint8 -o "$out/gold_trim_specular.png"
# Wood: vertical grain bands, 16-bit to exercise the 16-bit path.
oiiotool --pattern fill:left=0.45,0.27,0.13:right=0.62,0.40,0.22 $size 3 \
  --pattern checker:width=6:height=256:color1=0.92,0.9,0.9:color2=1,1,1 $size 3 --mul \
  $(noise -0.02 0.02 3) --add -d uint16 -o "$out/wood_albedo.png"
# Rubber: dark grey, single channel (sRGB 0.2: linear albedo 0.033, above charcoal's 0.02).
oiiotool --pattern constant:color=0.2 $size 1 \
  --pattern noise:type=uniform:min=-0.02:max=0.02:mono=1:seed=4 $size 1 --add \
  -d uint8 -o "$out/rubber_albedo.png"
# Glass: tinted colour with a mask in alpha (unassociated: colour is not multiplied by it).
oiiotool --pattern fill:top=0.55,0.72,0.78:bottom=0.35,0.52,0.60 $size 3 \
  --pattern checker:width=32:height=32:color1=1:color2=0.25 $size 1 \
  --chappend --chnames R,G,B,A --attrib oiio:UnassociatedAlpha 1 -d uint8 -o "$out/glass_albedo_mask.png"
# Glass's second texture of its Schüler pair: F0 0.04 (sRGB 0.2213) in RGB, gloss 0.95 in alpha.
oiiotool --pattern constant:color=0.2213,0.2213,0.2213 $size 3 --pattern constant:color=0.95 $size 1 \
  --chappend --chnames R,G,B,A --attrib oiio:UnassociatedAlpha 1 -d uint8 -o "$out/glass_specular_gloss.png"
ls -l "$out"
