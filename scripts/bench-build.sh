#!/usr/bin/env bash
# Benchmark of `matbake build` at scale (not part of the test run): N generated materials of
# SIZE² (default 200 of 2048²), each a metal-rough base colour and roughness PNG packed into
# glTF ORM textures and validated, built with png_compression = "fast" (--jobs 2), then with the
# default level at --jobs 1 and --jobs 2 (each from scratch). Prints wall time, speed-up, peak RSS and the size of
# the PNGs written, and the time of a second run (nothing to do). Stops at the first failing run.
# The sources are generated once into WORK (default /tmp/matbake-bench-build, about 3 GB for
# 200 × 2048²) and kept for later runs.
#   scripts/bench-build.sh [N [SIZE [WORK]]]
# With --noop [N [WORK]] instead: N materials (default 10,000) of one 4x4 source file each, built
# once, then the time of runs with nothing to do (the stamps read and checked; the best of 5).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [ "${1:-}" = "--noop" ]; then
  n=${2:-10000}
  work=${3:-/tmp/matbake-bench-noop}
  bash "$root/scripts/build.sh" "$root/build" >/dev/null
  matbake=$root/build/cli/matbake
  if [ "$(cat "$work/made" 2>/dev/null)" != "$n" ]; then
    rm -rf "$work" && mkdir -p "$work/src"
    oiiotool --pattern constant:color=0.5,0.4,0.3 4x4 3 -d uint8 -o "$work/one.png"
    {
      echo 'validate = { enabled = false }'
      for ((i = 0; i < n; i++)); do
        cp "$work/one.png" "$work/src/m$i.png"
        printf '[materials.m%05d]\nsources = { base_color = "src/m%d.png", metallic = 0.0, roughness = 0.5 }\nlayout = "gltf-orm"\n' "$i" "$i"
      done
    } >"$work/m.toml"
    echo "$n" >"$work/made"
  fi
  rm -rf "$work/out"
  /usr/bin/time -f "%e" -o "$work/time.txt" "$matbake" build "$work/m.toml" --quiet
  echo "$n materials from scratch: $(cat "$work/time.txt") s"
  best=
  for _ in 1 2 3 4 5; do
    /usr/bin/time -f "%e %M" -o "$work/time.txt" "$matbake" build "$work/m.toml" --quiet
    read -r s kb <"$work/time.txt"
    if [ -z "$best" ] || awk -v a="$s" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$s best_kb=$kb; fi
  done
  echo "nothing to do, $n materials: $best s (best of 5), peak RSS $((best_kb / 1024)) MB"
  exit 0
fi
n=${1:-200}
size=${2:-2048}
work=${3:-/tmp/matbake-bench-build}
bash "$root/scripts/build.sh" "$root/build" >/dev/null
matbake=$root/build/cli/matbake

mkdir -p "$work/src"
if [ "$(cat "$work/made" 2>/dev/null)" != "$n $size" ]; then
  echo "generating $n materials of ${size}x${size} in $work/src ..." >&2
  # Each material its own colour and grain: gradients with low noise, as painted textures are
  # (they compress like real ones, unlike pure noise). The noise comes from 8 files made first
  # (oiiotool's noise pattern is the slow part).
  for ((k = 0; k < 8; k++)); do
    oiiotool --pattern noise:type=uniform:min=-0.03:max=0.03:mono=1:seed=$k ${size}x${size} 3 \
      -d half -o "$work/src/noise$k.exr" &
    [ $((k % $(nproc))) -eq $(($(nproc) - 1)) ] && wait
  done
  wait
  seq 0 $((n - 1)) | xargs -P "$(nproc)" -I{} bash -c '
    i=$1; size=$2; out=$3; noise=$out/noise$(($1 % 8)).exr
    # Every fourth one a metal (bright, F0 above 0.45), the others painted dielectrics.
    if [ $((i % 4)) -eq 0 ]; then top=0.97,0.92,0.85; bottom=0.93,0.88,0.80
    else top=$(awk -v i="$i" "BEGIN { printf \"%.2f,%.2f,0.3\", 0.25 + (i % 7) / 10, 0.2 + (i % 5) / 10 }"); bottom=0.5,0.4,0.3; fi
    oiiotool --pattern fill:top=$top:bottom=$bottom ${size}x${size} 3 "$noise" --add -d uint8 -o "$out/m$i-base.png"
    oiiotool --pattern checker:width=64:height=64:color1=0.35:color2=0.6 ${size}x${size} 1 \
      "$noise" --ch R --mulc 1.5 --add -d uint8 -o "$out/m$i-rough.png"' _ {} "$size" "$work/src"
  {
    for ((i = 0; i < n; i++)); do
      printf '[materials.m%03d]\nsources = { base_color = "src/m%d-base.png", roughness = "src/m%d-rough.png", metallic = %s }\nlayout = "gltf-orm"\n' \
        "$i" "$i" "$i" "$([ $((i % 4)) -eq 0 ] && echo 1.0 || echo 0.0)"
    done
  } >"$work/materials.toml"
  echo "$n $size" >"$work/made"
fi

# png_compression = "fast" for iteration builds: the same manifest with the key on top.
{ echo 'png_compression = "fast"'; cat "$work/materials.toml"; } >"$work/materials-fast.toml"

declare -A seconds rss
run() {  # name manifest jobs
  rm -rf "$work/out"
  sync
  if ! /usr/bin/time -f "%e %M" -o "$work/time.txt" "$matbake" build "$2" --jobs "$3" --quiet; then
    echo "bench-build: matbake build $2 --jobs $3 failed" >&2
    exit 1
  fi
  local s kb
  read -r s kb <"$work/time.txt"
  seconds[$1]=$s
  rss[$1]=$kb
  local bytes
  bytes=$(find "$work/out" -name '*.png' -printf '%s\n' | awk '{ s += $1 } END { print s }')
  awk -v name="$1" -v s="${seconds[$1]}" -v n="$n" -v kb="${rss[$1]}" -v bytes="$bytes" \
    'BEGIN { printf "%-22s %6.1f s  %.2f materials/s  peak RSS %d MB  PNG output %.1f MB\n", name, s, n / s, kb / 1024, bytes / 1e6 }'
}
run "jobs 2, png fast" "$work/materials-fast.toml" 2
run "jobs 1" "$work/materials.toml" 1
run "jobs 2" "$work/materials.toml" 2  # last: the second run below finds these outputs
awk -v a="${seconds[jobs 1]}" -v b="${seconds[jobs 2]}" 'BEGIN { printf "speed-up with 2 jobs: %.2fx\n", a / b }'
# A second run finds everything up to date (stamps only; no decoding, no hashing).
/usr/bin/time -f "%e" -o "$work/time.txt" "$matbake" build "$work/materials.toml"
echo "second run: $(cat "$work/time.txt") s"
