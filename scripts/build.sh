#!/usr/bin/env bash
# Configures and builds matbake in BUILD_DIR (default: build/, release with debug info).
# Usage: scripts/build.sh [--cli-only] [BUILD_DIR [extra cmake args...]]
# --cli-only builds the `matbake` executable and what it loads (library, OIIO module) and nothing
# else, and checks from Ninja's plan that no test or bench source is compiled (README command 1).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
target=all
if [ "${1:-}" = --cli-only ]; then target=matbake_cli; shift; fi
build=${1:-$root/build}
shift || true
bash "$root/scripts/deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
if [ "$target" != all ]; then
  # Every command the target needs, built or not: none may make a file of tests/ or bench/ (their
  # objects and programs go there; sources may be compiled through unity files of the build folder).
  if ninja -C "$build" -t commands "$target" | grep -E " -o (tests|bench)/" >/dev/null; then
    echo "matbake: scripts/build.sh --cli-only would compile a test or bench source (a dependency went wrong)" >&2
    exit 1
  fi
fi
cmake --build "$build" --target "$target"
