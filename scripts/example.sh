#!/usr/bin/env bash
# README command 1: installs what is missing, builds matbake, and runs it on the bundled example:
# the sRGB-authored textures in examples/textures/ become linear half-float EXRs in out/example/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/build.sh" "$root/build"
mkdir -p "$root/out/example"
"$root/build/cli/matbake" convert "$root"/examples/textures/*.png \
  --from srgb --to linear --bits half --out-dir "$root/out/example"
