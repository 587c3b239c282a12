#!/usr/bin/env bash
# End-to-end speed against error: `matbake convert` vs `oiiotool --no-autopremult --colorconvert
# sRGB linear` (the only exact oiiotool form for RGBA) on the same 2048x2048 RGBA 8-bit PNG, to the
# same EXR type and compression. Prints the mean wall time of RUNS runs (default 5), each output's
# size and its error against the float64 formula; stops if a run fails. Also runs the kernel
# benchmark.
# Usage: scripts/bench-convert.sh [--kernels-only | --end-to-end-only]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/build.sh" "$root/build" >/dev/null
runs=${RUNS:-5}
matbake=$root/build/cli/matbake
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset OCIO  # oiiotool's built-in sRGB and linear, as on a machine without a config

if [ "${1:-}" != "--end-to-end-only" ]; then
  echo "== kernels: one core, 2048x2048 RGBA (errors against the float64 formula)"
  "$root/build/bench/bench_convert_kernels" --benchmark_min_time=0.5
fi
[ "${1:-}" = "--kernels-only" ] && exit 0

echo "== end to end: 2048x2048 RGBA 8-bit PNG -> EXR, $(nproc) cores, mean of $runs runs"
# A texture-like input: a colour gradient with noise, and a noisy alpha (unassociated).
oiiotool --pattern fill:topleft=0.9,0.2,0.1:topright=0.1,0.8,0.3:bottomleft=0.2,0.3,0.9:bottomright=0.95,0.9,0.8 2048x2048 3 \
  --pattern noise:type=uniform:min=-0.1:max=0.1:seed=7 2048x2048 3 --add \
  --pattern noise:type=uniform:min=0.2:max=1:mono=1:seed=8 2048x2048 1 \
  --chappend --chnames R,G,B,A --attrib oiio:UnassociatedAlpha 1 -d uint8 -o "$work/in.png"

mean_seconds() {  # command... : mean wall time over $runs runs; stops the script if a run fails
  local total=0 start end
  for _ in $(seq "$runs"); do
    start=$(date +%s%N)
    if ! "$@" >/dev/null 2>"$work/stderr.txt"; then
      echo "bench-convert: failed: $* ($(head -1 "$work/stderr.txt"))" >&2
      exit 1
    fi
    end=$(date +%s%N)
    total=$((total + end - start))
  done
  awk -v ns="$total" -v n="$runs" 'BEGIN { printf "%.3f", ns / n / 1e9 }'
}

printf '%-9s %-6s %-11s %-9s %-9s %s\n' tool type compression seconds "size MB" "error vs float64"
for type in half float; do
  for compression in zip none; do
    m=$(mean_seconds "$matbake" --quiet convert "$work/in.png" -o "$work/m.exr" --bits "$type" --compression "$compression")
    o=$(mean_seconds oiiotool --no-autopremult "$work/in.png" --colorconvert sRGB linear -d "$type" \
          --compression "$compression" -o "$work/o.exr")
    for tool in matbake oiiotool; do
      file=$work/${tool:0:1}.exr
      seconds=$([ "$tool" = matbake ] && echo "$m" || echo "$o")
      printf '%-9s %-6s %-11s %-9s %-9.2f %s\n' "$tool" "$type" "$compression" "$seconds" \
        "$(awk -v b="$(stat -c %s "$file")" 'BEGIN { print b / 1e6 }')" "$("$root/build/bench/image_error" "$work/in.png" "$file")"
    done
  done
done
