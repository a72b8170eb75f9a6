#!/usr/bin/env bash
# Set up and run the main job on the offline defaults (no API key, no GPU): generate a small
# verified dataset for a long-horizon instruction, then audit it. Each run writes a new directory.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
out="out/demo/dataset-$(date +%Y%m%d-%H%M%S)"
.venv/bin/vcage generate "get ready for work" --episodes 2 --out "$out" "$@"
.venv/bin/vcage audit "$out"
