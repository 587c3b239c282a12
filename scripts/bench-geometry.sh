#!/usr/bin/env bash
# Geometry for delivery against gltfpack: each model written by matbake export (--join-meshes --mesh-quantization
# --mesh-compression meshopt, textures as they are) and by Debian's gltfpack -c (the same
# quantization: 14-bit positions, 12-bit UVs, 8-bit normals and colours), and, for scale, both
# without compression. Per model and tool: the geometry's bytes (the GLB's binary chunk without its
# images), the wall time and the glTF-Validator's errors. Markdown on stdout.
# Usage: scripts/bench-geometry.sh   (the Khronos models when ../shared/testdata is there)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
testdata=$root/../shared/testdata/gltf
bash "$root/scripts/build.sh" "$root/build" >/dev/null
bash "$root/scripts/install-gltf-validator.sh" >/dev/null
matbake=$root/build/cli/matbake
validate="node $root/scripts/gltf-validator/validate.js"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

models=("$root/examples/showroom.gltf")
for m in MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb OrientationTest/glTF-Embedded/OrientationTest.gltf \
         VertexColorTest/glTF-Embedded/VertexColorTest.gltf MultiUVTest/glTF-Embedded/MultiUVTest.gltf \
         NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb TextureCoordinateTest/glTF-Embedded/TextureCoordinateTest.gltf; do
  [ -f "$testdata/$m" ] && models+=("$testdata/$m")
done

# The bytes of a GLB's binary chunk that are not images: its geometry (compressed or not).
geometry_bytes() {
  python3 - "$1" <<'PY'
import json, struct, sys
data = open(sys.argv[1], "rb").read()
length = struct.unpack_from("<I", data, 12)[0]
doc = json.loads(data[20:20 + length])
bin_length = struct.unpack_from("<I", data, 20 + length)[0] if len(data) > 20 + length else 0
images = sum(doc["bufferViews"][i["bufferView"]]["byteLength"] for i in doc.get("images", []) if "bufferView" in i)
print(bin_length - images)
PY
}
# "bytes | seconds | errors" of one run writing $2.
measure() {
  local out=$1; shift
  local start end
  start=$(date +%s.%N)
  "$@" >/dev/null 2>"$work/err" || { echo "failed: $(head -c 200 "$work/err") | | "; return; }
  end=$(date +%s.%N)
  printf '%s | %.2f | %s' "$(geometry_bytes "$out")" "$(echo "$end - $start" | bc)" "$($validate "$out" | sed -n 's/.*: \([0-9]*\) errors.*/\1/p')"
}

echo "| model | as read (B) | matbake quantized (B) | gltfpack quantized, uncompressed (B) | matbake quantized + meshopt (B, s, errors) | gltfpack -c (B, s, errors) | matbake / gltfpack |"
echo "|---|---:|---:|---:|---|---|---:|"
for model in "${models[@]}"; do
  name=$(basename "${model%.*}")
  "$matbake" -q export "$model" -o "$work/$name-plain.glb"
  plain=$(geometry_bytes "$work/$name-plain.glb")
  "$matbake" -q export "$model" -o "$work/$name-q.glb" --join-meshes --mesh-quantization
  gltfpack -i "$model" -o "$work/$name-gq.glb" >/dev/null
  ours=$(measure "$work/$name-mq.glb" "$matbake" -q export "$model" -o "$work/$name-mq.glb" --join-meshes --mesh-quantization --mesh-compression meshopt)
  theirs=$(measure "$work/$name-gp.glb" gltfpack -i "$model" -o "$work/$name-gp.glb" -c)
  ratio=$(echo "scale=3; ${ours%% *} / ${theirs%% *}" | bc)
  echo "| $name | $plain | $(geometry_bytes "$work/$name-q.glb") | $(geometry_bytes "$work/$name-gq.glb") | $ours | $theirs | $ratio |"
done
