#!/usr/bin/env bash
# Installs the Khronos glTF-Validator that the glTF tests run (npm package pinned in
# scripts/gltf-validator/package-lock.json) into scripts/gltf-validator/node_modules. Installs
# Debian's nodejs and npm first when they are missing. Safe to re-run: does nothing when the pinned
# version is already there. Exit 1 when it cannot install; the glTF tests then skip and say why.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/gltf-validator" && pwd)

installed=$(node -p "require('$here/node_modules/gltf-validator/package.json').version" 2>/dev/null || true)
wanted=$(node -p "require('$here/package.json').dependencies['gltf-validator']" 2>/dev/null || true)
if [ -n "$installed" ] && [ "$installed" = "$wanted" ]; then exit 0; fi

bash "$(dirname "${BASH_SOURCE[0]}")/apt-install.sh" "glTF validator tests will skip" node:nodejs npm:npm
echo "matbake: installing the glTF-Validator (npm gltf-validator $(node -p "require('$here/package.json').dependencies['gltf-validator']"))" >&2
if ! (cd "$here" && npm ci --no-audit --no-fund --loglevel=error >/dev/null); then
  echo "matbake: could not install gltf-validator from npm — glTF validator tests will skip" >&2
  exit 1
fi
