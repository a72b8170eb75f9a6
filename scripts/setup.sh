#!/usr/bin/env bash
# Set up vcage on a fresh Debian machine: GL libraries for offscreen rendering, chromium for the
# report's browser test, a virtualenv, and the package with its development tools, all from
# requirements/lock.txt (scripts/lock.sh writes it). Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."
if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  need=()
  gl=(libegl1 libegl-mesa0 libgl1-mesa-dri libopengl0 libosmesa6)
  dpkg -s "${gl[@]}" >/dev/null 2>&1 || need+=("${gl[@]}")
  # Debian's browser, which Playwright drives in the report's browser test (no browser download)
  dpkg -s chromium >/dev/null 2>&1 || need+=(chromium)
  if [ "${#need[@]}" -gt 0 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null
  fi
fi
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
# Everything from the lock file (exact versions, checked against their hashes), so that a release
# elsewhere cannot change what runs here; then vcage itself, with nothing else resolved.
.venv/bin/python -m pip install -q pip==26.3
.venv/bin/python -m pip install -q --require-hashes -r requirements/lock.txt
.venv/bin/python -m pip install -q --no-deps --no-build-isolation -e .
