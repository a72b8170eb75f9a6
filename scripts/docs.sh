#!/usr/bin/env bash
# Build the documentation site (mkdocs.yml) into site/, with every warning an error.
set -euo pipefail
cd "$(dirname "$0")/.."
export NO_MKDOCS_2_WARNING=1  # Material's notice of its successor, printed on every build
exec .venv/bin/mkdocs build --strict --quiet "$@"
