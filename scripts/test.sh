#!/usr/bin/env bash
# README command 2: installs what is missing, builds matbake and runs the whole test suite twice:
# a release build (build/) and an AddressSanitizer + UndefinedBehaviorSanitizer build
# (build-asan/), where any sanitizer report fails the run.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=$(nproc)

# The Khronos glTF-Validator (npm, pinned) for the tests of written glTF; without it they skip.
bash "$root/scripts/install-gltf-validator.sh" || echo "matbake: glTF-Validator tests will skip" >&2

bash "$root/scripts/build.sh" "$root/build" -DMATBAKE_WERROR=ON
ctest --test-dir "$root/build" --output-on-failure -j "$jobs"

bash "$root/scripts/build.sh" "$root/build-asan" -DMATBAKE_WERROR=ON -DMATBAKE_SANITIZE=ON
# Full unwinding on malloc so leak suppressions can name the third-party frame.
export ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:strict_string_checks=1:fast_unwind_on_malloc=0
export LSAN_OPTIONS=suppressions=$root/tests/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
ctest --test-dir "$root/build-asan" --output-on-failure -j "$jobs"
