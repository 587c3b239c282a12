#!/usr/bin/env bash
# Installs matbake's build and test dependencies from Debian (bookworm). Safe to re-run: when every
# package is already installed it does nothing, not even `apt-get update`.
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config git
  libopenimageio-dev openimageio-tools
  libopencolorio-dev opencolorio-tools
  libopenexr-dev libimath-dev libglm-dev libtinygltf-dev libembree-dev
  libcli11-dev nlohmann-json3-dev libtbb-dev libtomlplusplus-dev
  libgtest-dev libbenchmark-dev zlib1g-dev libdeflate-dev libspng-dev libxxhash-dev time
  libdraco-dev libmeshoptimizer-dev libwebp-dev libzstd-dev draco gltfpack
  clang-14 libclang-rt-14-dev llvm-14
)
# `deps.sh cluster`: also Slurm and munge, for scripts/test-cluster.sh.
[ "${1:-}" = cluster ] && packages+=(slurm-wlm munge)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
  echo "matbake: missing packages: ${missing[*]} (run this script as root, or install them)" >&2
  exit 1
fi
echo "matbake: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
