#!/usr/bin/env bash
# Set up and run the main job on the offline defaults (no API key, no GPU).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec .venv/bin/vcage demo --out out/demo "$@"
