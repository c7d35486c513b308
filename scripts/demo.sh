#!/usr/bin/env bash
# README's main job: set up, then validate the bundled box-sorting example with the
# thesis's missing-order error (exit code 1: a blocking situation is found, diagnosed
# and drawn in the report).
set -uo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh || exit 2
.venv/bin/synth validate grafcets/tri_missing_order.g7 --plant plants/tri.rules --report reports/tri_missing_order
code=$?
echo
echo "synth exited with $code (0 pass, 1 problems found, 2 bad input or a limit, 3 a bug in synth)."
echo "Open reports/tri_missing_order/index.html for the trace, the element automata and SUP around the blocking state."
echo "The corrected program passes:  .venv/bin/synth validate grafcets/tri.g7 --plant plants/tri.rules"
echo "(put synth on your PATH with:  export PATH=\"$PWD/.venv/bin:\$PATH\")"
exit 0
