#!/usr/bin/env bash
# Installs Debian packages for deps.sh and the install-*.sh scripts: `apt-install.sh WHAT PACKAGE...`
# installs those of PACKAGE... that are missing (as root), or says so with WHAT (what follows) and
# exits 1.
# A PACKAGE is there when dpkg says it is installed; one given as COMMAND:PACKAGE, when COMMAND is
# on PATH (however it came). Does nothing, not even `apt-get update`, when all are there.
set -euo pipefail
what=$1
shift
missing=()
for p in "$@"; do
  if [[ $p == *:* ]]; then
    command -v "${p%%:*}" >/dev/null || missing+=("${p#*:}")
  else
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0
if [ "$(id -u)" -ne 0 ]; then
  echo "matbake: missing ${missing[*]} (run as root, or install them) — $what" >&2
  exit 1
fi
echo "matbake: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
