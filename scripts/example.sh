#!/usr/bin/env bash
# README command 1: installs what is missing, builds matbake, and builds the bundled example
# (examples/showroom.toml: five materials and a scene with instances) into examples/out/:
# packed glTF textures and validation reports per material, showroom.glb with the materials and
# per-vertex AO, then checks showroom.glb with the Khronos glTF-Validator and renders a preview of
# the materials. Safe to re-run: a second run builds nothing and says so.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/build.sh" "$root/build"
matbake=$root/build/cli/matbake
"$matbake" build "$root/examples/showroom.toml"
"$matbake" preview --materials "$root/examples/preview.json" --model ggx --size 96 \
  -o "$root/examples/out/materials-preview.png"
if bash "$root/scripts/install-gltf-validator.sh"; then
  node "$root/scripts/gltf-validator/validate.js" "$root/examples/out/showroom.glb"
else
  echo "matbake: the glTF-Validator could not be installed; examples/out/showroom.glb was not checked" >&2
fi
