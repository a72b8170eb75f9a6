#!/usr/bin/env bash
# The drift check (not run by CI): build a second environment, .venv-latest, with the newest versions
# that pyproject.toml's ranges allow, and print what moved against requirements/lock.txt, which tests
# move with it, and whether the same seeds still give the same datasets.
#
#   bash scripts/check-latest.sh            # everything (the suite takes ~15 min on 2 cores)
#   bash scripts/check-latest.sh -m "not slow"   # arguments go to pytest
#
# Exits 0 whatever it finds: it reports. Updating the lock is a deliberate commit afterwards
# (bash scripts/lock.sh --upgrade, or --upgrade-package NAME) with this output in its message.
set -uo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null  # the locked environment, for the datasets' comparison
rm -rf .venv-latest
python3 -m venv .venv-latest
.venv-latest/bin/python -m pip install -q --upgrade pip
.venv-latest/bin/python -m pip install -q torch==2.13.0  # the CPU build here, before what depends on it
.venv-latest/bin/python -m pip install -q --upgrade --upgrade-strategy eager -e ".[dev]" 2>&1 \
  | grep -v "^WARNING: Location" || true

echo "== packages that moved against requirements/lock.txt"
.venv-latest/bin/python - <<'PY'
import re
from importlib.metadata import distributions

def norm(name): return re.sub(r"[-_.]+", "-", name).lower()

pins = re.findall(r"^([A-Za-z0-9_.\-]+)==([^ \\\n]+)", open("requirements/lock.txt").read(), re.M)
locked = {norm(name): pinned for name, pinned in pins}
latest = {norm(d.metadata["Name"]): d.version for d in distributions()}
moved = [(n, locked[n], latest[n]) for n in sorted(locked) if n in latest and locked[n] != latest[n]]
for name, a, b in moved:
    print(f"  {name}: {a} -> {b}")
for name in sorted(set(locked) - set(latest)):
    print(f"  {name}: {locked[name]} -> not installed")
for name in sorted(set(latest) - set(locked) - {"pip", "vcage"}):
    print(f"  {name}: not locked -> {latest[name]}")
print(f"  {len(moved)} of {len(locked)} locked packages moved")
PY

echo "== the test suite under the newest versions"
LP_NUM_THREADS=1 .venv-latest/bin/pytest -p no:cacheprovider -rfE "$@" 2>&1 | tail -n 60

echo "== the same seeds under the locked and the newest versions (benchmarks/same_data.py)"
.venv/bin/python benchmarks/same_data.py --before HEAD --after HEAD --before-python .venv/bin/python \
  --after-python .venv-latest/bin/python 2>&1 | grep -v "^same " | tail -n 40
exit 0
