#!/usr/bin/env bash
# Installs Debian packages for one of the install-*.sh scripts: `apt-install.sh WHAT PACKAGE...`
# installs those of PACKAGE... that are missing (as root), or says that WHAT will skip and exits 1.
# A PACKAGE given as COMMAND:PACKAGE counts as there when COMMAND is on PATH.
set -euo pipefail
what=$1
shift
missing=()
for p in "$@"; do
  command -v "${p%%:*}" >/dev/null || missing+=("${p#*:}")
done
[ ${#missing[@]} -eq 0 ] && exit 0
if [ "$(id -u)" -ne 0 ]; then
  echo "matbake: missing ${missing[*]} (run as root, or install them) — $what will skip" >&2
  exit 1
fi
echo "matbake: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
