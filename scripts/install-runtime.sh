#!/usr/bin/env bash
# Installs the runtime the runtime tests render in (tests/runtime, docs/delivery.md#in-a-runtime):
# Debian's Chromium, and three.js with puppeteer-core from npm, pinned in tests/runtime/package-lock.json
# (puppeteer-core drives the Chromium installed here; it downloads no browser). Installs Debian's
# nodejs and npm first when they are missing. Safe to re-run: does nothing when all is there.
# Exit 1 when it cannot install; the runtime tests then skip and say why.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../tests/runtime" && pwd)

bash "$(dirname "${BASH_SOURCE[0]}")/apt-install.sh" "runtime tests will skip" chromium:chromium node:nodejs npm:npm

installed() {
  node -p "require('$here/node_modules/$1/package.json').version" 2>/dev/null || true
}
wanted() {
  node -p "require('$here/package.json').dependencies['$1']" 2>/dev/null || true
}
if [ "$(installed three)" = "$(wanted three)" ] && [ "$(installed puppeteer-core)" = "$(wanted puppeteer-core)" ]; then exit 0; fi
echo "matbake: installing three $(wanted three) and puppeteer-core $(wanted puppeteer-core) (npm)" >&2
# PUPPETEER_SKIP_DOWNLOAD: puppeteer-core fetches no browser; set all the same, for safety.
if ! (cd "$here" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error >/dev/null); then
  echo "matbake: could not install the runtime harness from npm — runtime tests will skip" >&2
  exit 1
fi
