#!/usr/bin/env bash
# Write requirements/lock.txt: every package vcage, its extras and its development tools need, pinned
# to an exact version with the hashes of its files, for Python 3.11 on x86-64 Linux. setup.sh, .ci/run
# and the README's two commands install from it, so a release elsewhere cannot change what runs.
#
#   bash scripts/lock.sh                      # add or drop what pyproject.toml changed; keep every other pin
#   bash scripts/lock.sh --upgrade            # move every package to the newest version the ranges allow
#   bash scripts/lock.sh --upgrade-package mujoco --upgrade-package mujoco-core
#
# Moving a pin is a deliberate commit: run scripts/check-latest.sh first and put what it printed in
# the commit message. The compiler is uv, at a fixed version, in a throwaway environment.
set -euo pipefail
cd "$(dirname "$0")/.."
UV_VERSION=0.13.8
tool=$(mktemp -d)
trap 'rm -rf "$tool"' EXIT
python3 -m venv "$tool"
"$tool/bin/python" -m pip install -q "uv==$UV_VERSION"
# /opt/wheels holds the CPU build of torch on these machines (PyPI's torch pulls CUDA packages)
links=()
[ -d /opt/wheels ] && links=(--find-links /opt/wheels)
"$tool/bin/uv" pip compile pyproject.toml --all-extras --python-version 3.11 \
  --python-platform x86_64-manylinux_2_28 --generate-hashes "${links[@]}" \
  --custom-compile-command "bash scripts/lock.sh" \
  -o requirements/lock.txt "$@"
