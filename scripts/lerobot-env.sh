#!/usr/bin/env bash
# Build .venv-lerobot/: a separate Python 3.12 environment with LeRobot 0.6.1, for the reference
# learner benchmark (benchmarks/lerobot_reference.py trains LeRobot's own diffusion policy on a vcage
# dataset with it, and benchmarks/lerobot_bridge.py serves that policy's actions from it). vcage
# itself, its tests and .ci/run never need it. Safe to run again: it does nothing once built.
#
# torch: LeRobot 0.6.1 declares torch>=2.7,<2.12 (and torchvision<0.27), so vcage's torch==2.13.0
# cannot be used here; the newest pair inside that range is pinned and installed first, so that
# installing lerobot resolves nothing about torch. PyPI has no CPU-only torch wheel for Linux and
# Python 3.12: this is the ordinary (CUDA-enabled) build, which runs on the CPU as well (about 6 GB
# installed). torchcodec finds no system FFmpeg here; LeRobot then decodes with PyAV (bundled).
set -euo pipefail
cd "$(dirname "$0")/.."
venv=.venv-lerobot
torch_pins=(torch==2.11.0 torchvision==0.26.0)
lerobot_pin='lerobot[training,diffusion]==0.6.1'
if [ -x "$venv/bin/lerobot-train" ] && "$venv/bin/python" -c \
  'import importlib.metadata as m, sys; sys.exit(m.version("lerobot") != "0.6.1")' 2>/dev/null; then
  echo "$venv: already built (lerobot 0.6.1)"
  exit 0
fi
py=/root/.pyenv/versions/3.12.1/bin/python3.12
if [ ! -x "$py" ]; then
  if command -v pyenv >/dev/null 2>&1; then
    version=$(pyenv versions --bare | grep -E '^3\.12(\.[0-9]+)?$' | sort -V | tail -n 1 || true)
    [ -n "$version" ] && py="$(pyenv root)/versions/$version/bin/python3.12"
  fi
fi
if [ ! -x "$py" ]; then
  py=$(command -v python3.12 || true)
fi
if [ -z "$py" ] || [ ! -x "$py" ]; then
  echo "lerobot-env.sh: no Python 3.12 found (pyenv install 3.12, or put python3.12 on PATH)" >&2
  exit 1
fi
[ -x "$venv/bin/python" ] || "$py" -m venv "$venv"
"$venv/bin/python" -m pip install -q pip==26.3
"$venv/bin/python" -m pip install -q "${torch_pins[@]}"
"$venv/bin/python" -m pip install -q "$lerobot_pin" "${torch_pins[@]}"
"$venv/bin/python" -c 'import lerobot, torch; print("lerobot", lerobot.__version__, "torch", torch.__version__)'
