#!/usr/bin/env bash
# matbake against gltfpack with BasisU: the six Khronos models of the runtime test delivered by both
# at equal codec settings (ETC1S colour with UASTC data and normals; all UASTC; all ETC1S; matbake
# given the basisu settings gltfpack 0.17 passes: UASTC level 1, RDO 0.29 over 1024 bytes, zstd 9;
# ETC1S q 192) with quantized, meshopt-compressed geometry, rendered in three.js (headless Chromium)
# against the originals; bytes, wall time, peak memory and render PSNR per model, each tool timed
# MATBAKE_BENCH_RUNS times (default 5) interleaved with the other and the median kept, then run once
# more, watched, for its peak memory. Markdown on stdout.
# gltfpack: GLTFPACK=/path/to/gltfpack (a native build with BasisU), else npm's gltfpack 0.17.0
# (pinned in bench/gltfpack/), the last release that encodes KTX2 through an external basisu, run
# with the basisu matbake installs. Needs ../shared/testdata. Usage: scripts/bench-vs-gltfpack.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/install-basisu.sh" >/dev/null
bash "$root/scripts/install-runtime.sh" >/dev/null
bash "$root/scripts/build.sh" "$root/build" >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if [ -z "${GLTFPACK:-}" ]; then
  (cd "$root/bench/gltfpack" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
  GLTFPACK=$work/gltfpack
  printf '#!/bin/sh\nexec node %q "$@"\n' "$root/bench/gltfpack/node_modules/gltfpack/cli.js" >"$GLTFPACK"
  chmod +x "$GLTFPACK"
fi
export GLTFPACK
export BASISU_PATH=${BASISU_PATH:-$root/scripts/basisu/bin/basisu}
cd "$work"  # gltfpack writes its temporary images into the current folder
"$root/build/tests/matbake_tests" --gtest_also_run_disabled_tests --gtest_filter='Runtime.DISABLED_AgainstGltfpack' | grep '^|'
