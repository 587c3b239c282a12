#!/usr/bin/env bash
# Compressed and quantized glTF in: each model made into its Draco and meshopt variants by the tools
# users make them with (Debian's draco_transcoder and gltfpack), then read by matbake beside its
# plain twin. Per variant: the farthest any decoded vertex lies from the plain scene's (as a
# fraction of the scene's diagonal), mean AO per vertex and per texel against the plain scene's
# (same seed and samples), the glTF-Validator's errors on export's and bake-ao's outputs, and the
# wall time and peak memory of reading (bake-ao at 1 ray per vertex). Markdown on stdout.
# Usage: scripts/bench-gltf-input.sh   (the Khronos models when ../shared/testdata is there)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
testdata=$root/../shared/testdata/gltf
bash "$root/scripts/build.sh" "$root/build" >/dev/null
bash "$root/scripts/install-gltf-validator.sh" >/dev/null
missing=()
command -v python3 >/dev/null || missing+=(python3)
[ -x /usr/bin/time ] || missing+=(time)
if [ ${#missing[@]} -gt 0 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
matbake=$root/build/cli/matbake
validate="node $root/scripts/gltf-validator/validate.js"
samples=${SAMPLES:-256}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

models=("$root/examples/showroom.gltf")
for m in Box/glTF-Embedded/Box.gltf BoxTextured/glTF-Embedded/BoxTextured.gltf Cube/glTF/Cube.gltf \
         MultiUVTest/glTF-Embedded/MultiUVTest.gltf MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb; do
  [ -f "$testdata/$m" ] && models+=("$testdata/$m")
done
variants=("draco|draco_transcoder|" "draco lossless|draco_transcoder|-qp 0 -qn 0 -qt 0" "meshopt -c|gltfpack|-c"
          "meshopt -cc|gltfpack|-cc" "meshopt -c -noq|gltfpack|-c -noq")

# The farthest vertex of dump B from the vertices of dump A and back, over A's diagonal (bake-ao --dump CSVs).
farthest() {
  python3 - "$1" "$2" <<'PY'
import csv, math, sys
def points(path):
    with open(path) as f:
        return [tuple(float(r[k]) for k in "xyz") for r in csv.DictReader(f)]
a, b = points(sys.argv[1]), points(sys.argv[2])
lo = [min(p[i] for p in a) for i in range(3)]; hi = [max(p[i] for p in a) for i in range(3)]
diag = math.dist(lo, hi) or 1.0
cell = diag / 256
def far(src, dst):
    grid = {}
    for q in dst: grid.setdefault(tuple(int(math.floor(q[i] / cell)) for i in range(3)), []).append(q)
    worst = 0.0
    for p in src:
        c = [int(math.floor(p[i] / cell)) for i in range(3)]
        near = [math.dist(p, q) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
                for q in grid.get((c[0] + dx, c[1] + dy, c[2] + dz), [])]
        worst = max(worst, min(near) if near else cell)
    return worst
print("%.1e" % (max(far(a, b), far(b, a)) / diag))
PY
}
mean_ao() { "$matbake" --json bake-ao "$@" --samples "$samples" --seed 0 | python3 -c 'import json,sys; print("%.5f" % json.load(sys.stdin)["mean_ao"])'; }
errors() { $validate "$1" | sed -n 's/.*: \([0-9]*\) errors.*/\1/p'; }
read_cost() { /usr/bin/time -f "%e %M" -o "$work/time" "$matbake" -q bake-ao "$1" --dump "$work/read.csv" --samples 1 >/dev/null; awk '{printf "%.2f s, %d MB", $1, $2 / 1024}' "$work/time"; }

echo "| model | variant | size | farthest vertex / diagonal | mean AO per vertex (plain) | per texel (plain) | validator errors (export, bake-ao) | read: wall, peak RSS (plain) |"
echo "|---|---|---|---|---|---|---|---|"
for model in "${models[@]}"; do
  name=$(basename "${model%.*}")
  "$matbake" -q bake-ao "$model" --dump "$work/plain.csv" --samples 1 >/dev/null
  plain_vertex=$(mean_ao "$model" --dump "$work/unused.csv")
  plain_texel=$(mean_ao "$model" -o "$work/plain_tex.glb" --texture 128 2>/dev/null || echo "n/a")
  plain_read=$(read_cost "$model")
  for v in "${variants[@]}"; do
    IFS='|' read -r label tool flags <<<"$v"
    out=$work/$name-${label// /_}.glb
    # shellcheck disable=SC2086
    "$tool" -i "$model" -o "$out" $flags >/dev/null 2>&1 || { echo "| $name | $label | $tool failed | | | | | |"; continue; }
    "$matbake" -q bake-ao "$out" --dump "$work/variant.csv" --samples 1 >/dev/null
    vertex=$(mean_ao "$out" --dump "$work/unused.csv")
    texel=$(mean_ao "$out" -o "$work/tex.glb" --texture 128 2>/dev/null || echo "n/a")
    "$matbake" -q export "$out" -o "$work/export.glb" --ao-samples 16 >/dev/null
    "$matbake" -q bake-ao "$out" -o "$work/ao.glb" --samples 16 >/dev/null
    echo "| $name | $label | $(stat -c %s "$out") B | $(farthest "$work/plain.csv" "$work/variant.csv") | $vertex ($plain_vertex) |" \
         "$texel ($plain_texel) | $(errors "$work/export.glb"), $(errors "$work/ao.glb") | $(read_cost "$out") ($plain_read) |"
  done
done
