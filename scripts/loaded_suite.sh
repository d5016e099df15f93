#!/usr/bin/env bash
# Run the whole test suite N times in a row (default 5) with a busy-loop process beside it, the
# way a loaded CI machine runs it, and stop at the first failing run. Prints one line per run
# (passed or failed, wall seconds, pytest's summary) and writes build/loaded_suite/run-K.log.
# Usage: scripts/loaded_suite.sh [N]
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
runs="${1:-5}"
python="${PYTHON:-$root/.venv/bin/python}"
export SAILOR_DARKNET_DATA="${SAILOR_DARKNET_DATA:-$(scripts/fetch_test_data.sh)}"
mkdir -p build/loaded_suite

"$python" -c "while True: pass" &
busy=$!
trap 'kill "$busy" 2>/dev/null || true' EXIT

for run in $(seq 1 "$runs"); do
  log="build/loaded_suite/run-$run.log"
  started=$(date +%s)
  if "$python" -m pytest -q >"$log" 2>&1; then outcome=passed; else outcome=FAILED; fi
  seconds=$(( $(date +%s) - started ))
  echo "run $run/$runs: $outcome in ${seconds} s ($(tail -n 1 "$log"))"
  if [ "$outcome" = FAILED ]; then
    echo "see $log"
    exit 1
  fi
done
