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
  python3-jsonschema
)
# `deps.sh cluster`: also Slurm and munge, for scripts/test-cluster.sh.
[ "${1:-}" = cluster ] && packages+=(slurm-wlm munge)

bash "$(dirname "${BASH_SOURCE[0]}")/apt-install.sh" "matbake cannot be built" "${packages[@]}"
