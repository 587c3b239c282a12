#!/usr/bin/env bash
# The cluster cost model's per-job figures (docs/cluster.md, "Cost model"): one material job
# (`matbake build --only`, as a Slurm array task runs it) at 512² to 4096², with 1 and 2 cores:
# wall time and peak memory (best of 3), the bytes it reads and writes; and the example's scene
# job. Then the expected wall time for 10,000 2048² materials on 1, 8, 64 and 256 nodes.
#   scripts/bench-cluster.sh [BUILD_DIR]     (about 3 minutes on 2 cores)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
matbake=$(cd "${1:-$root/build}" && pwd)/cli/matbake
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# One material of the size: an sRGB noise base colour (validation off: noise is no material),
# constant metallic and roughness, the glTF ORM layout. Prints "seconds peak_MB read_MB written_MB".
measure() {  # size, cores
  local dir=$work/m$1 best=
  if [ ! -f "$dir/m.toml" ]; then
    mkdir -p "$dir"
    oiiotool --pattern noise:type=uniform "$1x$1" 3 -d uint8 -o "$dir/noise.png"
    printf '[materials.m]\nsources = { base_color = "noise.png", metallic = 0.0, roughness = 0.5 }\nlayout = "gltf-orm"\nvalidate = { enabled = false }\n' >"$dir/m.toml"
  fi
  for _ in 1 2 3; do
    /usr/bin/time -f "%e %M" -o "$work/time" "$matbake" --jobs "$2" build "$dir/m.toml" --only material:m --force --quiet
    read -r seconds kb <"$work/time"
    if [ -z "$best" ] || awk -v a="$seconds" -v b="${best%% *}" 'BEGIN {exit !(a < b)}'; then best="$seconds $kb"; fi
  done
  local read_mb written_mb
  read_mb=$(du -k "$dir/noise.png" | awk '{printf "%.1f", $1 / 1024}')
  written_mb=$(du -sk "$dir/out/materials" | awk '{printf "%.1f", $1 / 1024}')
  echo "$best" | awk -v r="$read_mb" -v w="$written_mb" '{printf "%s %.0f %s %s\n", $1, $2 / 1024, r, w}'
}

echo "| texture | cores | time (s) | peak memory (MB) | model's request (MB) | read (MB) | written (MB) |"
echo "|---|---|---|---|---|---|---|"
for size in 512 1024 2048 4096; do
  for cores in 1 2; do
    read -r seconds peak read_mb written_mb < <(measure "$size" "$cores")
    model=$(awk -v p=$((size * size)) 'BEGIN {m = (32 + 64 * p / 1048576) * 1.25; printf "%d", int((m + 63.999) / 64) * 64}')
    echo "| ${size}² | $cores | $seconds | $peak | $model | $read_mb | $written_mb |"
    if [ "$size" = 2048 ] && [ "$cores" = 1 ]; then job_2048=$seconds written_2048=$written_mb; fi
  done
done

mkdir -p "$work/example" && cp "$root"/examples/showroom.{toml,gltf,bin} "$work/example/" && cp -r "$root/examples/textures" "$work/example/"
"$matbake" build "$work/example/showroom.toml" --quiet
/usr/bin/time -f "%e %M" -o "$work/time" "$matbake" --jobs 2 build "$work/example/showroom.toml" --only scene:showroom --force --quiet
read -r scene_seconds scene_kb <"$work/time"
echo
echo "scene job (the example, AO textures baked, 2 cores): $scene_seconds s, $((scene_kb / 1024)) MB peak"

# The model: nodes of 32 cores and 128 GB, one core per job (32 jobs a node, memory permitting), the
# 2048² one-core job time above; the scene jobs after the last material (Amdahl); the shared
# filesystem writing at most 1 GB/s in all.
echo
echo "| nodes (32 cores) | materials at once | material phase | filesystem floor | expected wall time |"
echo "|---|---|---|---|---|"
for nodes in 1 8 64 256; do
  awk -v n="$nodes" -v t="$job_2048" -v w="$written_2048" -v s="$scene_seconds" 'BEGIN {
    jobs = 10000; per_node = 32; mem_jobs = int(128 * 1024 / 384); if (mem_jobs < per_node) per_node = mem_jobs
    at_once = n * per_node; waves = int((jobs + at_once - 1) / at_once)
    phase = waves * t; floor_s = jobs * w / 1024
    wall = (phase > floor_s ? phase : floor_s) + s
    printf "| %d | %d | %.0f s | %.0f s | %.1f min |\n", n, at_once, phase, floor_s, wall / 60 }'
done
