#!/usr/bin/env bash
# The baker against Blender's (docs/bake.md): on four pairs with known geometry (bench/bake_pairs.cpp:
# sphere, bump, sculpt, rivets), the tangent-space normal map, the position map, the colour transfer
# and binary AO baked by `matbake bake` and by Blender's Cycles "selected to active"
# (scripts/bench-bake-blender.py) with the same cage, the same AO distance, 2 threads each, at equal
# samples; each compared with a high-sample reference (bake_pairs error: the texels the low-poly's
# UVs cover, 8 bits but for positions). matbake's time is its bake (set-up and trace, from --json; its whole run in brackets);
# Blender's the bake call alone (not its start, imports or write).
# Each time is the fastest of BENCH_BAKE_REPEATS runs (3; this VM's speed drifts by a third from one
# minute to the next), the references' one run. Markdown on stdout.
# Usage: scripts/bench-bake-blender.sh   (about 25 minutes on 2 cores)
# BENCH_BAKE_WORK=DIR keeps the pairs and every image there; BENCH_BAKE_SECTIONS="normal position
# transfer ao outside" (the default) names the tables to make (normal: the normal maps and their
# renders; position: the high-poly's positions; transfer: its vertex colours; ao: binary AO;
# outside: normal maps of three pairs made from ../shared/testdata, skipped without it).
set -euo pipefail
bench=bench-bake-blender work_variable=BENCH_BAKE_WORK repeats_variable=BENCH_BAKE_REPEATS
source "$(dirname "${BASH_SOURCE[0]}")/bench-blender-setup.sh"
"$pairs_tool" write "$work"
ao_distance=0.5
sections=" ${BENCH_BAKE_SECTIONS:-normal position transfer ao outside} "

# matbake_bake RUNS PAIR FRONT BACK MAP SIZE NAME FLAGS...: bakes into $work/NAME/ RUNS times, leaves
# the map at $work/NAME.png (a float map beside the glTF: $work/NAME.exr) and, of the run whose bake was fastest, the whole run's time in
# $run_seconds and the bake's (set-up and trace, from --json: what Blender's bake call spans) in $seconds.
matbake_bake() {
  local runs=$1 pair=$2 front=$3 back=$4 map=$5 size=$6 name=$7
  shift 7
  local start run bake
  seconds=
  for ((r = 0; r < runs; ++r)); do
    rm -rf "${work:?}/$name" && mkdir -p "$work/$name"
    start=$(now)
    # --no-average-normals: Blender extrudes a flat-shaded low-poly (the sphere pair's icosphere, its
    # vertices split per face) along each face's normal; so does matbake with it: the same rays.
    "$matbake" --json bake "$(pair_file "$pair" low)" --from "$(pair_file "$pair" "$high")" -o "$work/$name/out.gltf" --maps "$map" \
      --size "$size" --front "$front" --back "$back" --absolute-cage --no-average-normals --padding 0 --jobs "$threads" "$@" >"$work/$name.json"
    run=$(elapsed "$start")
    bake=$(python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); print("%.3f" % (r["setup_seconds"] + r["trace_seconds"]))' "$work/$name.json")
    keep_fastest "$bake" "$run"
  done
  local made
  for made in "$work/$name"/*_"$map".png "$work/$name"/*_"$map".exr; do
    if [ -f "$made" ]; then cp "$made" "$work/$name.${made##*.}"; fi
  done
}

# pair_file PAIR low|high|painted: the pair's file of that name in $work, .gltf or .glb.
pair_file() {
  if [ -f "$work/${1}_$2.glb" ]; then echo "$work/${1}_$2.glb"; else echo "$work/${1}_$2.gltf"; fi
}

# blender_bake PAIR FRONT BACK MAP SIZE SAMPLES NAME [by_name]: bakes $work/NAME.exr $repeats times,
# the fastest bake call's time in $seconds (by_name: the sum of each part's call).
blender_bake() {
  local pair=$1 front=$2 back=$3 map=$4 size=$5 samples=$6 name=$7
  blender_run "$(pair_file "$pair" low)" "$(pair_file "$pair" "$high")" "$work/$name.exr" "$map" "$size" "$samples" "$front" \
    "$(echo "$front $back" | awk '{print $1 + $2}')" "$ao_distance" "$threads" "$repeats" ${8:+"$8"}
}

# error KIND PAIR REFERENCE IMAGE: IMAGE's two error figures against REFERENCE, space-separated.
error() {
  "$pairs_tool" error "$1" "$(pair_file "$2" low)" "$work/$3" "$work/$4" | sed -E 's/^[^ ]+ texels=[0-9]+ //; s/[a-z0-9_]+=//g'
}

blender_version=$(blender -b --factory-startup --python-expr 'import bpy; print("version=" + bpy.app.version_string)' 2>/dev/null |
  sed -n 's/^version=//p')
echo "matbake $("$matbake" --version | head -1 | awk '{print $NF}') against Blender $blender_version (Cycles, CPU), $threads threads each, $(nproc) cores."
echo "Time: matbake's bake (set-up and trace; in brackets its whole run: reading, tangents, PNG and glTF"
echo "written) and Blender's bake call (its start, imports and image write left out)."
echo
high=high  # the high-poly the bakes read: PAIR_high.gltf, or PAIR_painted.gltf (vertex colours) for transfer
# pair, cage front and back (scene units).
pairs=("sphere 0.3 0.3" "bump 0.6 0.05" "sculpt 0.15 0.15" "rivets 0.05 0.02")

if [[ "$sections" == *" normal "* ]]; then
  echo "### Tangent-space normal map, 1024², against matbake at 64 positions a texel"
  echo
  echo "| pair | rays a texel | matbake (s) | Blender (s) | faster | matbake error: mean, 99th pct (°) | Blender error (°) |"
  echo "|---|---|---|---|---|---|---|"
  for p in "${pairs[@]}"; do
    read -r pair front back <<<"$p"
    matbake_bake 1 "$pair" "$front" "$back" normal 1024 "${pair}_normal_ref" --texel-samples 64
    matbake_bake "$repeats" "$pair" "$front" "$back" normal 1024 "${pair}_normal_m1" --texel-samples 1
    m_seconds=$seconds m_run=$run_seconds
    read -r m_mean m_p99 <<<"$(error normal "$pair" "${pair}_normal_ref.png" "${pair}_normal_m1.png")"
    blender_bake "$pair" "$front" "$back" normal 1024 1 "${pair}_normal_blender"
    read -r b_mean b_p99 <<<"$(error normal "$pair" "${pair}_normal_ref.png" "${pair}_normal_blender.exr")"
    echo "| $pair | 1 | $m_seconds ($m_run) | $seconds | $(ratio "$seconds" "$m_seconds") | $m_mean, $m_p99 | $b_mean, $b_p99 |"
    matbake_bake "$repeats" "$pair" "$front" "$back" normal 1024 "${pair}_normal_m4" --texel-samples 4
    read -r m_mean m_p99 <<<"$(error normal "$pair" "${pair}_normal_ref.png" "${pair}_normal_m4.png")"
    echo "| $pair | 4 | $seconds ($run_seconds) | — | | $m_mean, $m_p99 | (no anti-aliasing) |"
  done
  echo

  # In three.js (tests/runtime/render.mjs, as the runtime tests): the low-poly bare, with matbake's
  # one-ray and 4-position normal maps, and with Blender's (its EXR as the same 8-bit linear PNG, in a
  # copy of matbake's output: the same TANGENT, MikkTSpace as Blender's own), each render's PSNR
  # against the high-poly's, mean of the three views.
  if bash "$root/scripts/install-runtime.sh" >/dev/null 2>&1; then
    echo "### In three.js: render PSNR against the high-poly's (dB, mean of three views), normal maps of 1024²"
    echo
    echo "| pair | low-poly bare | matbake, 1 ray | matbake, 4 positions | Blender, 1 sample |"
    echo "|---|---|---|---|---|"
    for p in "${pairs[@]}"; do
      read -r pair front back <<<"$p"
      rm -rf "${work:?}/${pair}_normal_blender_gltf" && cp -r "$work/${pair}_normal_m1" "$work/${pair}_normal_blender_gltf"
      "$matbake" convert "$work/${pair}_normal_blender.exr" --from linear --to linear --bits 8 \
        -o "$(ls "$work/${pair}_normal_blender_gltf"/*_normal.png)" >/dev/null
      rm -rf "${work:?}/${pair}_renders"
      node "$root/tests/runtime/render.mjs" --out "$work/${pair}_renders" --size 512 high="$work/${pair}_high.gltf" \
        bare="$work/${pair}_low.gltf" m1="$work/${pair}_normal_m1/out.gltf" m4="$work/${pair}_normal_m4/out.gltf" \
        blender="$work/${pair}_normal_blender_gltf/out.gltf" >/dev/null
      row="| $pair"
      for model in bare m1 m4 blender; do
        sum=0
        for view in fit near far; do
          sum=$(echo "$sum $("$pairs_tool" psnr "$work/${pair}_renders/high-$view.png" "$work/${pair}_renders/$model-$view.png")" | awk '{print $1 + $2}')
        done
        row="$row | $(echo "$sum" | awk '{printf "%.2f", $1 / 3}')"
      done
      echo "$row |"
    done
    echo
  else
    echo "(three.js in Chromium could not be installed here: no render comparison)"
    echo
  fi
fi

# one_ray_table MAP ERROR_KIND EXT ERRORS TITLE: a table of MAP at 1024², one ray a texel, by both
# bakers against matbake at 64 positions (its file $work/NAME.EXT), ERRORS naming bake_pairs'
# ERROR_KIND figures.
one_ray_table() {
  local map=$1 kind=$2 ext=$3 errors=$4 title=$5
  echo "### $title, 1024², against matbake at 64 positions a texel"
  echo
  echo "| pair | rays a texel | matbake (s) | Blender (s) | faster | matbake error: $errors | Blender error |"
  echo "|---|---|---|---|---|---|---|"
  for p in "${pairs[@]}"; do
    read -r pair front back <<<"$p"
    matbake_bake 1 "$pair" "$front" "$back" "$map" 1024 "${pair}_${map}_ref" --texel-samples 64
    matbake_bake "$repeats" "$pair" "$front" "$back" "$map" 1024 "${pair}_${map}_m1" --texel-samples 1
    m_seconds=$seconds m_run=$run_seconds
    read -r m_first m_second <<<"$(error "$kind" "$pair" "${pair}_${map}_ref.$ext" "${pair}_${map}_m1.$ext")"
    blender_bake "$pair" "$front" "$back" "$map" 1024 1 "${pair}_${map}_blender"
    read -r b_first b_second <<<"$(error "$kind" "$pair" "${pair}_${map}_ref.$ext" "${pair}_${map}_blender.exr")"
    echo "| $pair | 1 | $m_seconds ($m_run) | $seconds | $(ratio "$seconds" "$m_seconds") | $m_first, $m_second | $b_first, $b_second |"
  done
  echo
}

if [[ "$sections" == *" position "* ]]; then
  one_ray_table position position exr "mean, 99th pct" "Position map (floats, scene units; each pair about 2 across)"
fi
if [[ "$sections" == *" transfer "* ]]; then
  high=painted
  one_ray_table transfer colour png "RMSE, largest" "Colour transfer (the high-poly's vertex colours; sRGB, 8 bits)"
  high=high
fi

if [[ "$sections" == *" outside "* ]]; then
  # Pairs the project did not design (scripts/bench-bake-outside.py makes them in Blender from
  # ../shared/testdata): the Stanford bunny onto its 3% decimation; Khronos NormalTangentMirrorTest
  # (mirrored UVs) onto itself, its own normal map the detail; OrientationTest's thirteen parts, each
  # bevelled as its high-poly, matched by name (Blender: one bake call a part). Each 2 to 3.6 across.
  testdata=$root/../shared/testdata
  if [ -d "$testdata/gltf" ]; then
    timeout 600 blender -b --factory-startup --python "$root/scripts/bench-bake-outside.py" -- "$testdata" "$work" >/dev/null 2>&1 ||
      { echo "$bench: Blender could not make the outside pairs" >&2; exit 1; }
    for side in low high; do cp "$testdata/gltf/NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb" "$work/mirror_$side.glb"; done
    echo "### Pairs from outside: tangent-space normal map, 1024², against matbake at 64 positions a texel"
    echo
    echo "| pair | rays a texel | matbake (s) | Blender (s) | faster | matbake error: mean, 99th pct (°) | Blender error (°) |"
    echo "|---|---|---|---|---|---|---|"
    # pair, front, back, matbake's flags (Blender's own way of the same: a last word for blender_bake)
    for p in "bunny 0.02 0.02" "mirror 0.02 0.02 --high-normal-maps" "hard 0.01 0.01 --match by_name"; do
      read -r pair front back flags <<<"$p"
      read -ra flag_words <<<"${flags:-}"
      matbake_bake 1 "$pair" "$front" "$back" normal 1024 "${pair}_normal_ref" --texel-samples 64 "${flag_words[@]}"
      matbake_bake "$repeats" "$pair" "$front" "$back" normal 1024 "${pair}_normal_m1" --texel-samples 1 "${flag_words[@]}"
      m_seconds=$seconds m_run=$run_seconds
      read -r m_mean m_p99 <<<"$(error normal "$pair" "${pair}_normal_ref.png" "${pair}_normal_m1.png")"
      blender_bake "$pair" "$front" "$back" normal 1024 1 "${pair}_normal_blender" "$([ "$pair" = hard ] && echo by_name)"
      read -r b_mean b_p99 <<<"$(error normal "$pair" "${pair}_normal_ref.png" "${pair}_normal_blender.exr")"
      echo "| $pair | 1 | $m_seconds ($m_run) | $seconds | $(ratio "$seconds" "$m_seconds") | $m_mean, $m_p99 | $b_mean, $b_p99 |"
    done
    echo
  else
    echo "(no ../shared/testdata: no pairs from outside)"
    echo
  fi
fi

[[ "$sections" == *" ao "* ]] || exit 0
echo "### Binary AO (distance $ao_distance), 256², against matbake at 16 positions × 4096 rays a texel"
echo
echo "| pair | rays a texel | matbake (s) | Blender (s) | faster | matbake error: RMSE, largest | Blender error |"
echo "|---|---|---|---|---|---|---|"
for p in "${pairs[@]}"; do
  read -r pair front back <<<"$p"
  ao_flags=(--ao-falloff none --ao-max-distance "$ao_distance")
  matbake_bake 1 "$pair" "$front" "$back" ao 256 "${pair}_ao_ref" --texel-samples 16 --ao-samples 4096 "${ao_flags[@]}"
  for s in 16 64 256 1024; do
    matbake_bake "$repeats" "$pair" "$front" "$back" ao 256 "${pair}_ao_m$s" --texel-samples 1 --ao-samples "$s" "${ao_flags[@]}"
    m_seconds=$seconds m_run=$run_seconds
    read -r m_rmse m_largest <<<"$(error scalar "$pair" "${pair}_ao_ref.png" "${pair}_ao_m$s.png")"
    blender_bake "$pair" "$front" "$back" ao 256 "$s" "${pair}_ao_blender$s"
    read -r b_rmse b_largest <<<"$(error scalar "$pair" "${pair}_ao_ref.png" "${pair}_ao_blender$s.exr")"
    echo "| $pair | $s | $m_seconds ($m_run) | $seconds | $(ratio "$seconds" "$m_seconds") | $m_rmse, $m_largest | $b_rmse, $b_largest |"
  done
done
