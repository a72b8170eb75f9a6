#!/usr/bin/env bash
# Set up vcage on a fresh Debian machine: GL libraries for offscreen rendering, chromium for the
# report's browser test, a virtualenv, and the package with its development tools. Safe to run again.
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
.venv/bin/python -m pip install -q --upgrade pip
# the CPU build of torch (a local wheel here) before anything that depends on it: vcage.policy
.venv/bin/python -m pip install -q torch==2.13.0
.venv/bin/python -m pip install -q -e ".[dev]"
