#!/usr/bin/env bash
# Builds matbake's libFuzzer targets (build-fuzz/: clang 14, ASan + UBSan) and runs them.
#   scripts/fuzz.sh TARGET SECONDS [libFuzzer flags...]   one target for SECONDS
#   scripts/fuzz.sh --smoke SECONDS                        every target for SECONDS each (the test
#                                                          command's smoke run)
# Targets: image (our reader over OIIO), gltf and glb (document + flattened scene), manifest,
# layout, materials, ktx2, state (stamps and made.json through the output gate), cache (the encode
# cache's entries and the bake's kept-map index), scripts (hostile
# words through the Ninja and Slurm writers). Seeds: the repository's presets and examples, plus ../shared/testdata when it
# is there (pngsuite, libpng-testpngs, openexr, the Khronos models), and tests/fuzz/regressions/ (inputs
# that once failed, and seeds made by other tools; replayed first by every run). The growing corpus stays in
# build-fuzz/corpus/TARGET; a crash is written to build-fuzz/artifacts/TARGET/ and fails the run.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
testdata=$root/../shared/testdata
build=$root/build-fuzz
targets=(image gltf glb manifest layout materials ktx2 state cache scripts json)

if [ $# -lt 2 ]; then
  echo "usage: scripts/fuzz.sh TARGET|--smoke SECONDS [libFuzzer flags...]  (targets: ${targets[*]})" >&2
  exit 2
fi
bash "$root/scripts/deps.sh"
CXX=clang++-14 cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMATBAKE_FUZZ=ON \
  -DMATBAKE_BUILD_TESTS=OFF -DMATBAKE_BUILD_BENCH=OFF >/dev/null
# The targets only (the command-line program is not fuzzed through its binary).
# Quiet when it builds; the compiler's errors (the end of its output) when it does not.
if ! build_log=$(cmake --build "$build" --target "${targets[@]/#/fuzz_}" 2>&1); then
  printf '%s\n' "$build_log" | tail -n 60 >&2
  echo "scripts/fuzz.sh: the fuzz build failed (above)" >&2
  exit 1
fi

# Seeds: copies of the matching files, flat (libFuzzer reads every file of a folder it is given).
seed() {  # target, then find arguments
  local target=$1; shift
  local dir=$build/seeds/$target
  rm -rf "$dir" && mkdir -p "$dir"
  # tests/fuzz/regressions/TARGET: inputs that once failed and seeds made by other tools (Draco,
  # meshopt); each run starts by replaying them.
  for place in "$root/presets" "$root/examples" "$testdata" "$root/tests/fuzz/regressions/$target"; do
    [ -d "$place" ] || continue
    find "$place" -type f "$@" -size -2M -print0 | while IFS= read -r -d '' f; do
      cp "$f" "$dir/$(echo "$f" | md5sum | cut -c1-12)-$(basename "$f")"
    done
  done
  echo "$dir"
}

run() {  # target, seconds, extra flags
  local target=$1 seconds=$2; shift 2
  local seeds
  case $target in
    # Leak checks off for images: OIIO 2.4's PNG reader leaks a string when libpng longjmps out of
    # its read callback (tests/lsan.supp), and naming that frame needs full unwinding on every
    # malloc, which slows the run a hundredfold. The sanitizer test build checks leaks with it.
    # Allocations above 256 MB fail (malloc returns null, as under a memory limit; a throwing new
    # above it is reported): a small input cannot spend the run clearing gigabytes, and the
    # readers' out-of-memory paths are exercised (that is how exit 136 was found).
    image) seeds=$(seed image \( -name '*.png' -o -name '*.exr' -o -name '*.jpg' -o -name '*.tif' \))
      export ASAN_OPTIONS=detect_leaks=0:max_allocation_size_mb=256:allocator_may_return_null=1
      set -- -detect_leaks=0 "$@" ;;
    gltf) seeds=$(seed gltf -name '*.gltf') ;;
    # GLBs up to 64 KB: a 290 KB seed (and mutants of it) held the run at 100 exec/s, and the
    # container and accessor paths do not need large buffers to be reached.
    # No Draco-compressed GLBs: libdraco 1.5.5 trusts a count inside the stream (one changed byte
    # makes it decode for 5 s and 200 MB before refusing: docs/reliability.md), and those mutants
    # held this target near 100 runs/s. Draco streams are fuzzed through the gltf target.
    glb) seeds=$(seed glb -name '*.glb')
      mkdir -p "$build/corpus/glb"
      { find "$seeds" "$build/corpus/glb" -type f -exec grep -lZ KHR_draco_mesh_compression {} + || true; } | xargs -0r rm -f
      set -- -max_len=65536 "$@" ;;
    manifest) seeds=$(seed manifest -name '*.toml' ! -name 'materials.toml') ;;
    layout) seeds=$(seed layout -path '*layouts*' -name '*.json') ;;
    materials) seeds=$(seed materials -name 'materials*.toml') ;;
    ktx2) seeds=$(seed ktx2 -name '*.ktx2') ;;
    # State files as a build writes them (tests/fuzz/regressions/state: a stamp and a made.json).
    state) seeds=$(seed state -name '*.json' -path '*regressions*') ;;
    # The caches' files (tests/fuzz/regressions/cache: an entry's header, a kept-map index).
    cache) seeds=$(seed cache -path '*regressions/cache*') ;;
    scripts) seeds=$(seed scripts -name '*.txt' -path '*regressions*') ;;
    # The bounded JSON reader (tests/fuzz/regressions/json: nestings past its limit and within it,
    # brackets in strings and escapes).
    json) seeds=$(seed json -path '*regressions/json*') ;;
    *) echo "scripts/fuzz.sh: unknown target '$target' (${targets[*]})" >&2; exit 2 ;;
  esac
  mkdir -p "$build/corpus/$target" "$build/artifacts/$target"
  local log=$build/fuzz-$target.log started=$SECONDS
  rm -f "$build"/fuzz-[0-9]*.log  # the jobs' logs of an earlier run
  # -rss_limit_mb: a decoder's legitimate peak stays far below; -max_len: large seeds are kept whole
  # (a -max_len among the target's flags, later on the line, overrides it). Run from the build
  # folder: with -jobs, libFuzzer writes each job's fuzz-N.log in the current one.
  if ! (cd "$build" && exec "$build/tests/fuzz/fuzz_$target" "$build/corpus/$target" "$seeds" -max_total_time="$seconds" \
      -rss_limit_mb=4096 -max_len=1048576 -print_final_stats=1 -artifact_prefix="$build/artifacts/$target/" \
      "$@") >"$log" 2>&1; then
    tail -n 60 "$log" >&2
    echo "matbake: fuzz target $target failed; the input is in $build/artifacts/$target/" >&2
    return 1
  fi
  # Runs: the one process's, or with -jobs the sum of its jobs'.
  printf "fuzz %-9s %10s runs in %4s s, corpus %s files\n" "$target" \
    "$(cat "$log" "$build"/fuzz-[0-9]*.log 2>/dev/null | grep -o 'stat::number_of_executed_units: *[0-9]*' |
      awk '{ runs += $NF } END { print runs + 0 }')" "$((SECONDS - started))" \
    "$(find "$build/corpus/$target" -type f | wc -l)"
}

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export LSAN_OPTIONS=suppressions=$root/tests/lsan.supp:print_suppressions=0
if [ "$1" = --smoke ]; then
  for t in "${targets[@]}"; do run "$t" "$2"; done
else
  target=$1 seconds=$2; shift 2
  run "$target" "$seconds" "$@"
fi
