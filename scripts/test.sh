#!/usr/bin/env bash
# Set up (if needed) and run the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Two worker processes (pytest-xdist; VCAGE_TEST_WORKERS sets another number, 0 runs in this process),
# each taking whole test files, so that a module's fixtures (a trained policy, a generated dataset) are
# built once; the session's fixtures are built once per worker.
exec .venv/bin/pytest -n "${VCAGE_TEST_WORKERS:-2}" --dist loadfile "$@"
