#!/usr/bin/env bash
# KTX2 delivery, speed against error (docs/delivery.md): matbake's mip chains and container against
# basisu's own -mipmap at equal codec settings, on the Khronos WaterBottle textures (colour, ORM,
# normal map) at 2048² and at 1024² (resized by oiiotool first), and on a synthetic alpha-tested
# foliage texture (MASK, cutoff 0.5); then the bytes texel-density sizing saves on the example scene
# and two Khronos models. Markdown on stdout. Needs ../shared/testdata for the Khronos part.
# Usage: scripts/bench-delivery.sh     (about 5 minutes on 2 cores)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
testdata=$root/../shared/testdata/gltf
bash "$root/scripts/build.sh" "$root/build" >/dev/null
bash "$root/scripts/install-basisu.sh"
export MATBAKE_BASISU=$root/scripts/basisu/bin/basisu
bench=$root/build/bench/bench_delivery
matbake=$root/build/cli/matbake
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

bottle=$testdata/SpecGlossVsMetalRough/glTF
echo "## Mip chains: matbake against basisu -mipmap (basisu $("$MATBAKE_BASISU" -version | sed -n 's/.*Compressor v//p'))"
echo
if [ -d "$bottle" ]; then
  for size in 2048 1024; do
    for t in baseColor:colour:etc1s baseColor:colour:uastc roughnessMetallic:data:uastc normal:normal:uastc; do
      IFS=: read -r name class codec <<<"$t"
      file=$bottle/WaterBottle_$name.png
      if [ "$size" != 2048 ]; then
        oiiotool "$file" --resize "${size}x${size}" -o "$work/WaterBottle_${name}_$size.png"
        file=$work/WaterBottle_${name}_$size.png
      fi
      "$bench" "$work/bench" "$class" "$codec" "$file"
    done
  done
else
  echo "(../shared/testdata is not there: the Khronos textures are skipped)"
  echo
fi

# Foliage: leaf-shaped blobs of alpha 1 on alpha 0, soft-edged, about a third of the texels covered.
python3 - "$work/foliage.png" <<'PY'
import math, random, struct, sys, zlib
random.seed(1)
n = 1024
alpha = [[0.0] * n for _ in range(n)]
for _ in range(900):
    cx, cy, r, a = random.uniform(0, n), random.uniform(0, n), random.uniform(6, 22), random.uniform(0, math.pi)
    for y in range(int(cy - 2 * r), int(cy + 2 * r)):
        for x in range(int(cx - 2 * r), int(cx + 2 * r)):
            dx, dy = x - cx, y - cy
            u, v = dx * math.cos(a) + dy * math.sin(a), -dx * math.sin(a) + dy * math.cos(a)
            d = (u / r) ** 2 + (v / (0.35 * r)) ** 2
            if d < 1.4:
                alpha[y % n][x % n] = max(alpha[y % n][x % n], min(1.0, (1.4 - d) / 0.4))
rows = b"".join(b"\0" + bytes(c for x in range(n) for c in (60, 110 + (x * 7 + y) % 60, 40, int(255 * alpha[y][x] + 0.5)))
                for y in range(n))
chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 6, 0, 0, 0)) +
                              chunk(b"IDAT", zlib.compress(rows, 6)) + chunk(b"IEND", b""))
PY
"$bench" "$work/bench" colour uastc "$work/foliage.png" 0.5

echo "## Texel density: bytes saved"
echo
echo "| scene | texels per unit | texture | needed side | source | delivered | bytes before | bytes after |"
echo "|---|---|---|---|---|---|---|---|"
scenes=()
[ -f "$root/examples/out/showroom.glb" ] || "$matbake" build "$root/examples/showroom.toml" --quiet
scenes+=("$root/examples/out/showroom.glb:64")
[ -d "$bottle" ] && scenes+=("$bottle/SpecGlossVsMetalRough.gltf:1024")
[ -f "$testdata/Cube/glTF/Cube.gltf" ] && scenes+=("$testdata/Cube/glTF/Cube.gltf:128")
cat >"$work/summary.py" <<'PY'
import json, sys
r = json.load(sys.stdin)
name, density = sys.argv[1], sys.argv[2]
before = after = 0
for t in r["textures"]:
    before += t["source_bytes"]
    after += t["bytes"]
    src, size = t["source_size"], t["size"]
    print(f"| {name} | {density} | {t['texture']} ({t['class']}) | {t.get('needed_side', '-')} | "
          f"{src[0]}x{src[1]} | {size[0]}x{size[1]} | {t['source_bytes']} | {t['bytes']} |")
print(f"| **{name}** | {density} | all | | | | **{before}** | **{after}** ({100 * (1 - after / before):.0f}% saved) |")
PY
for s in "${scenes[@]}"; do
  scene=${s%:*}
  density=${s##*:}
  "$matbake" --json export "$scene" -o "$work/density/$(basename "${scene%.*}").glb" --texel-density "$density" |
    python3 "$work/summary.py" "$(basename "$scene")" "$density"
done

# A whole scene: wall time and peak RSS of one KTX2 export (ten 2048² textures, all UASTC at level 0,
# the fastest encode, so that decoding and holding images weigh most), and the bytes once more with
# --jobs 1 (they must be the same).
if [ -d "$bottle" ]; then
  echo
  echo "### A whole scene: time and peak memory (SpecGlossVsMetalRough, all UASTC level 0)"
  echo
  echo "| --jobs | wall s | peak RSS MB | bytes |"
  echo "|---|---|---|---|"
  for jobs in $(nproc) 1; do
    out=$work/scene-$jobs/out.glb
    /usr/bin/time -f "%e %M" -o "$work/time-$jobs" "$matbake" --jobs "$jobs" export "$bottle/SpecGlossVsMetalRough.gltf" -o "$out" \
      --texture-format ktx2 --colour-codec uastc --colour-uastc-level 0 --data-uastc-level 0 --normal-uastc-level 0 >/dev/null
    read -r wall rss <"$work/time-$jobs"
    echo "| $jobs | $wall | $((rss / 1024)) | $(stat -c %s "$out") |"
  done
  cmp -s "$work/scene-$(nproc)/out.glb" "$work/scene-1/out.glb" || { echo "matbake: bytes differ between --jobs" >&2; exit 1; }
fi
