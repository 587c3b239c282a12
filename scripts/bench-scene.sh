#!/usr/bin/env bash
# Reading a large scene: a generated 1M-vertex, 2M-triangle terrain (bench/make_big_scene) through
# `matbake export` (no AO) beside Debian's gltfpack (`-noq`: parses and rewrites the same file
# without quantizing), as .glb and .gltf, RUNS runs each (default 3), wall time and peak RSS; then
# `matbake bake-ao` at 64 samples, with the share of its wall time spent outside ray casting
# (process start, reading, normals, BVH build, writing). Not part of the test run.
# Usage: scripts/bench-scene.sh [N]   (N×N vertices, default 1000)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
n=${1:-1000}
runs=${RUNS:-3}
bash "$root/scripts/build.sh" "$root/build" >/dev/null
missing=()
command -v gltfpack >/dev/null || missing+=(gltfpack)
[ -x /usr/bin/time ] || missing+=(time)
command -v bc >/dev/null || missing+=(bc)
if [ ${#missing[@]} -gt 0 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
matbake=$root/build/cli/matbake
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$root/build/bench/make_big_scene" "$work/big" "$n"

measure() {  # label command...: each run's wall time and peak RSS, then the means
  local label=$1; shift
  local total_s=0 total_kb=0
  for _ in $(seq "$runs"); do
    /usr/bin/time -f "%e %M" -o "$work/time" "$@" >/dev/null 2>"$work/stderr" || { cat "$work/stderr" >&2; exit 1; }
    read -r s kb <"$work/time"
    total_s=$(echo "$total_s + $s" | bc -l); total_kb=$((total_kb + kb))
  done
  printf "| %s | %.2f s | %d MB |\n" "$label" "$(echo "$total_s / $runs" | bc -l)" $((total_kb / runs / 1024))
}

echo "| $((n * n)) vertices, $((2 * (n - 1) * (n - 1))) triangles, $(nproc) cores, mean of $runs | wall | peak RSS |"
echo "|---|---|---|"
for ext in glb gltf; do
  measure "matbake export big.$ext -o out.glb" "$matbake" -q export "$work/big.$ext" -o "$work/out.glb"
  measure "gltfpack -noq -i big.$ext -o out.glb" gltfpack -noq -i "$work/big.$ext" -o "$work/gp.glb"
done
measure "matbake --version (process start alone)" "$matbake" --version
ls -l "$work/out.glb" "$work/gp.glb" | awk '{print "output size: " $5 " bytes, " $NF}'

/usr/bin/time -f "%e %M" -o "$work/time" "$matbake" --json bake-ao "$work/big.gltf" --samples 64 -o "$work/ao.gltf" >"$work/ao.json"
read -r wall kb <"$work/time"
rays=$(grep '"ray_seconds"' "$work/ao.json" | tr -dc '0-9.')
setup=$(grep '"setup_seconds"' "$work/ao.json" | tr -dc '0-9.')
printf "bake-ao 64 samples: %.2f s wall, %.2f s casting rays, %.2f s set-up (normals, BVH), %.1f%% of the wall time outside ray casting, %d MB peak\n" \
  "$wall" "$rays" "$setup" "$(echo "100 * ($wall - $rays) / $wall" | bc -l)" $((kb / 1024))
