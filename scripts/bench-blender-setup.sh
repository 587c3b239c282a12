# Sourced by the benches against Blender's bake (bench-bake-blender.sh, bench-ao-blender.sh) after
# they set `bench` (their name, for messages), `work_variable` and `repeats_variable` (the
# environment variables that keep their work folder and set their repeat count): installs Blender
# and numpy, builds matbake; sets root, matbake, pairs_tool, threads (2, each tool's), repeats (3
# unless set), work (the variable's folder when it is set, else a temporary folder removed on exit)
# and the helpers below.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/apt-install.sh" "$bench needs Blender" blender:blender python3-numpy
bash "$root/scripts/build.sh" "$root/build" >/dev/null
matbake=$root/build/cli/matbake
pairs_tool=$root/build/bench/bake_pairs
threads=2
repeats=${!repeats_variable:-3}
work=${!work_variable:-}
if [ -z "$work" ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work"

now() { date +%s.%N; }
elapsed() { echo "$1 $(now)" | awk '{printf "%.2f", $2 - $1}'; }
ratio() { echo "$1 $2" | awk '{printf "%.1f×", $1 / ($2 > 0 ? $2 : 0.005)}'; }

# keep_fastest BAKE RUN: one matbake run's bake and whole-run seconds, kept in $seconds and
# $run_seconds when its bake is the fastest so far (empty $seconds: none yet).
keep_fastest() {
  if [ -z "$seconds" ] || awk -v a="$1" -v b="$seconds" 'BEGIN { exit !(a < b) }'; then seconds=$1 run_seconds=$2; fi
}

# blender_run ARGS...: scripts/bench-bake-blender.py with ARGS (its usage), the fastest bake call's
# time in $seconds; Blender's last lines and an error when it printed none.
blender_run() {
  local log
  log=$(timeout 3600 blender -b --factory-startup --python "$root/scripts/bench-bake-blender.py" -- "$@" 2>&1)
  seconds=$(printf '%s\n' "$log" | sed -n 's/^seconds=//p')
  [ -n "$seconds" ] || { printf '%s\n' "$log" | tail -20 >&2; echo "$bench: Blender's bake failed" >&2; exit 1; }
  seconds=$(printf '%.2f' "$seconds")
}
