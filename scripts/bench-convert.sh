#!/usr/bin/env bash
# End-to-end speed against error: `matbake convert` vs `oiiotool --no-autopremult --colorconvert
# sRGB linear` (the only exact oiiotool form for RGBA) on the same 8-bit PNG, to the same EXR type
# and compression. Inputs: a 2048x2048 RGBA noise worst case, and the Khronos sample models' PNG
# textures in ../shared/testdata/gltf (those of 256x256 and more; skipped when absent). Prints the
# mean wall time of RUNS runs (default 5; 3 for the corpus), each output's size and its error
# against the float64 formula; stops if a run fails. Also runs the kernel benchmark.
# Usage: scripts/bench-convert.sh [--kernels-only | --end-to-end-only | --codecs]
#   --codecs: matbake alone on the corpus with every EXR compression it has (size and time).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/build.sh" "$root/build" >/dev/null
runs=${RUNS:-5}
matbake=$root/build/cli/matbake
corpus_dir=$root/../shared/testdata/gltf
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset OCIO  # oiiotool's built-in sRGB and linear, as on a machine without a config
mode=${1:-}

if [ "$mode" != "--end-to-end-only" ] && [ "$mode" != "--codecs" ]; then
  echo "== kernels: one core, 2048x2048 RGBA (errors against the float64 formula)"
  "$root/build/bench/bench_convert_kernels" --benchmark_min_time=0.5
fi
[ "$mode" = "--kernels-only" ] && exit 0

# A texture-like worst case: a colour gradient with noise, and a noisy alpha (unassociated).
oiiotool --pattern fill:topleft=0.9,0.2,0.1:topright=0.1,0.8,0.3:bottomleft=0.2,0.3,0.9:bottomright=0.95,0.9,0.8 2048x2048 3 \
  --pattern noise:type=uniform:min=-0.1:max=0.1:seed=7 2048x2048 3 --add \
  --pattern noise:type=uniform:min=0.2:max=1:mono=1:seed=8 2048x2048 1 \
  --chappend --chnames R,G,B,A --attrib oiio:UnassociatedAlpha 1 -d uint8 -o "$work/noise.png"
corpus=()
if [ -d "$corpus_dir" ]; then
  while IFS= read -r file; do
    size=$(oiiotool --info "$file" | sed -E 's/.*: *([0-9]+) x *([0-9]+),.*/\1 \2/')
    read -r w h <<<"$size"
    [ "$w" -ge 256 ] && [ "$h" -ge 256 ] && corpus+=("$file")
  done < <(find "$corpus_dir" -iname '*.png' | sort)
else
  echo "bench-convert: $corpus_dir is absent; the Khronos corpus is skipped" >&2
fi

mean_seconds() {  # runs command... : mean wall time over `runs` runs; stops the script if a run fails
  local n=$1 total=0 start end
  shift
  for _ in $(seq "$n"); do
    start=$(date +%s%N)
    if ! "$@" >/dev/null 2>"$work/stderr.txt"; then
      echo "bench-convert: failed: $* ($(head -1 "$work/stderr.txt"))" >&2
      exit 1
    fi
    end=$(date +%s%N)
    total=$((total + end - start))
  done
  awk -v ns="$total" -v n="$n" 'BEGIN { printf "%.3f", ns / n / 1e9 }'
}
megabytes() { awk -v b="$(stat -c %s "$1")" 'BEGIN { printf "%.2f", b / 1e6 }'; }

if [ "$mode" = "--codecs" ]; then
  echo "== matbake's EXR compressions on the Khronos corpus (${#corpus[@]} textures), mean of ${RUNS:-3} runs, summed"
  printf '%-6s %-8s %-9s %s\n' type codec seconds "size MB"
  for type in half float; do
    for codec in none zip:1 zip zip:9 zips piz; do
      seconds=0 bytes=0
      for file in "${corpus[@]}"; do
        s=$(mean_seconds "${RUNS:-3}" "$matbake" --quiet convert "$file" -o "$work/c.exr" --bits "$type" --compression "$codec")
        seconds=$(awk -v a="$seconds" -v b="$s" 'BEGIN { print a + b }')
        bytes=$((bytes + $(stat -c %s "$work/c.exr")))
      done
      printf '%-6s %-8s %-9.2f %.2f\n' "$type" "$codec" "$seconds" "$(awk -v b="$bytes" 'BEGIN { print b / 1e6 }')"
    done
  done
  exit 0
fi

# One row per tool: time, size, error. For the corpus, times and sizes are also summed per tool.
compare() {  # input runs type compression label
  local input=$1 n=$2 type=$3 compression=$4 label=$5 m o
  m=$(mean_seconds "$n" "$matbake" --quiet convert "$input" -o "$work/m.exr" --bits "$type" --compression "$compression")
  o=$(mean_seconds "$n" oiiotool --no-autopremult "$input" --colorconvert sRGB linear -d "$type" \
        --compression "$compression" -o "$work/o.exr")
  printf '%-34s %-6s %-6s %-8s %-8s %-6s %-9s %-9s %s | %s\n' "$label" "$type" "$compression" "$m" "$o" \
    "$(awk -v a="$m" -v b="$o" 'BEGIN { printf "%.2f", b / a }')" "$(megabytes "$work/m.exr")" \
    "$(megabytes "$work/o.exr")" "$("$root/build/bench/image_error" "$input" "$work/m.exr")" \
    "$("$root/build/bench/image_error" "$input" "$work/o.exr")"
  echo "$type $compression $m $o $(stat -c %s "$work/m.exr") $(stat -c %s "$work/o.exr")" >>"$work/totals.txt"
}
header() {
  printf '%-34s %-6s %-6s %-8s %-8s %-6s %-9s %-9s %s\n' input type codec matbake oiiotool ratio "MB ours" \
    "MB oiio" "error ours | oiiotool (vs float64)"
}

echo "== end to end: 8-bit PNG -> EXR, $(nproc) cores; seconds are the mean of the runs"
echo "-- noise worst case, 2048x2048 RGBA, $runs runs"
header
for type in half float; do
  for compression in zip none; do compare "$work/noise.png" "$runs" "$type" "$compression" noise-2048-rgba; done
done
[ ${#corpus[@]} -eq 0 ] && exit 0
corpus_runs=${RUNS:-3}
echo "-- Khronos corpus: ${#corpus[@]} textures, $corpus_runs runs"
header
: >"$work/totals.txt"
for type in half float; do
  for compression in zip none; do
    for file in "${corpus[@]}"; do compare "$file" "$corpus_runs" "$type" "$compression" "$(basename "$file")"; done
  done
done
echo "-- Khronos corpus, summed over its ${#corpus[@]} textures"
printf '%-6s %-6s %-9s %-9s %-6s %-9s %s\n' type codec matbake oiiotool ratio "MB ours" "MB oiio"
awk '{ k = $1 " " $2; m[k] += $3; o[k] += $4; ms[k] += $5; os[k] += $6; if (!(k in seen)) { seen[k] = 1; order[n++] = k } }
     END { for (i = 0; i < n; i++) { k = order[i]; split(k, p, " ");
           printf "%-6s %-6s %-9.2f %-9.2f %-6.2f %-9.2f %.2f\n", p[1], p[2], m[k], o[k], o[k] / m[k], ms[k] / 1e6, os[k] / 1e6 } }' \
  "$work/totals.txt"
