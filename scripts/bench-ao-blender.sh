#!/usr/bin/env bash
# Texture AO of small scenes against Blender's AO bake (docs/bake-ao.md): each scene's occlusion
# onto its own UVs, by `matbake bake-ao --texture` and by Cycles' AO bake (scripts/bench-bake-blender.py,
# kind ao_self: every mesh, each material into its own image), binary AO within the same distance
# (matbake's default, a quarter of the scene's radius), 2 threads each, at equal samples. Scenes:
# ../shared/testdata's NormalTangentMirrorTest (5,240 triangles) and NormalTangentTest (7,774),
# both one material, and SpecGlossVsMetalRough (9,028, four materials).
# Time: matbake's bake (set-up, texels and rays, from --json; in brackets its whole run, reading
# the scene and writing it with its PNGs) against Blender's bake call alone (its start, the import
# and the image write left out); each the fastest of BENCH_AO_REPEATS runs (3). Error (one-material
# scenes): against matbake at 4 positions × 4096 rays a texel, over the texels the UVs cover, 8 bits.
# Markdown on stdout.
# Usage: scripts/bench-ao-blender.sh   (about 12 minutes on 2 cores)
# BENCH_AO_WORK=DIR keeps every image there.
set -euo pipefail
bench=bench-ao-blender work_variable=BENCH_AO_WORK repeats_variable=BENCH_AO_REPEATS
testdata="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/../shared/testdata/gltf"
[ -d "$testdata" ] || { echo "$bench: $testdata is absent (the project's shared folder)" >&2; exit 1; }
source "$(dirname "${BASH_SOURCE[0]}")/bench-blender-setup.sh"
size=512

json_field() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])' "$1" "$2"; }

# matbake_bake RUNS SCENE NAME FLAGS...: bakes SCENE's textures into $work/NAME/ RUNS times; of the
# run whose bake was fastest, the bake's time in $seconds and the whole run's in $run_seconds.
matbake_bake() {
  local runs=$1 scene=$2 name=$3
  shift 3
  local start run bake
  seconds=
  for ((r = 0; r < runs; ++r)); do
    rm -rf "${work:?}/$name" && mkdir -p "$work/$name"
    start=$(now)
    "$matbake" --json bake-ao "$scene" --texture "$size" --padding 0 --falloff none --existing-occlusion replace --jobs "$threads" \
      -o "$work/$name/out.gltf" "$@" >"$work/$name.json"
    run=$(elapsed "$start")
    bake=$(python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
print("%.3f" % (r["setup_seconds"] + r["texel_seconds"] + r["ray_seconds"]))' "$work/$name.json")
    keep_fastest "$bake" "$run"
  done
}

# blender_bake SCENE SAMPLES DISTANCE NAME: bakes $work/NAME.exr (the first material's) $repeats
# times, the fastest bake call's time in $seconds.
blender_bake() {
  blender_run "$1" - "$work/$4.exr" ao_self "$size" "$2" 0 0 "$3" "$threads" "$repeats"
}

# error SCENE REFERENCE IMAGE: IMAGE's RMSE and largest error against REFERENCE, space-separated.
error() {
  "$pairs_tool" error scalar "$1" "$2" "$3" | sed -E 's/^[^ ]+ texels=[0-9]+ //; s/[a-z0-9_]+=//g'
}

echo "matbake $("$matbake" --version | head -1 | awk '{print $NF}') against Blender's Cycles AO bake (CPU), $threads threads each, $(nproc) cores."
echo
echo "### Texture AO, binary, ${size}², against matbake at 4 positions × 4096 rays a texel"
echo
echo "| scene | triangles | rays a texel | matbake (s) | Blender (s) | faster | matbake error: RMSE, largest | Blender error |"
echo "|---|---|---|---|---|---|---|---|"
scenes=("NormalTangentMirrorTest 5240 $testdata/NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb"
  "NormalTangentTest 7774 $testdata/NormalTangentTest/glTF-Binary/NormalTangentTest.glb"
  "SpecGlossVsMetalRough 9028 $testdata/SpecGlossVsMetalRough/glTF/SpecGlossVsMetalRough.gltf")
for s in "${scenes[@]}"; do
  read -r name triangles scene <<<"$s"
  # The distance matbake derives from the scene's radius, given to both.
  matbake_bake 1 "$scene" "${name}_distance" --samples 1
  distance=$(json_field "$work/${name}_distance.json" max_distance)
  materials=$(ls "$work/${name}_distance"/*_occlusion.png | wc -l)
  [ "$materials" != 1 ] || matbake_bake 1 "$scene" "${name}_ref" --texel-samples 4 --samples 4096
  for samples in 16 64 256; do
    matbake_bake "$repeats" "$scene" "${name}_m$samples" --samples "$samples"
    m_seconds=$seconds m_run=$run_seconds
    blender_bake "$scene" "$samples" "$distance" "${name}_blender$samples"
    m_error="—" b_error="—"
    if [ "$materials" = 1 ]; then
      reference=$(ls "$work/${name}_ref"/*_occlusion.png)
      m_error=$(error "$scene" "$reference" "$(ls "$work/${name}_m$samples"/*_occlusion.png)" | sed 's/ /, /')
      b_error=$(error "$scene" "$reference" "$work/${name}_blender$samples.exr" | sed 's/ /, /')
    fi
    echo "| $name | $triangles | $samples | $m_seconds ($m_run) | $seconds | $(ratio "$seconds" "$m_seconds") | $m_error | $b_error |"
  done
done
