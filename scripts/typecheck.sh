#!/usr/bin/env bash
# The type check: `python -m mypy` over synth/ (settings in pyproject.toml), failing when it
# reports more errors than .ci/mypy-baseline allows. The baseline only goes down: when the
# count falls below it, lower the number in the file in the same commit.
set -euo pipefail
cd "$(dirname "$0")/.."
allowed="$(tr -dc '0-9' < .ci/mypy-baseline)"
set +e
out="$(.venv/bin/python -m mypy 2>&1)"
set -e
found="$(printf '%s\n' "$out" | sed -n 's/^Found \([0-9][0-9]*\) errors\{0,1\} in .*/\1/p' | tail -n 1)"
if [ -z "$found" ]; then
  if printf '%s\n' "$out" | grep -q '^Success: no issues found'; then found=0; else
    printf '%s\n' "$out"; echo "== mypy did not run to the end" >&2; exit 1; fi
fi
if [ "$found" -gt "$allowed" ]; then
  printf '%s\n' "$out"
  echo "== mypy: $found errors, more than the $allowed of .ci/mypy-baseline" >&2
  exit 1
fi
echo "mypy: $found errors (baseline $allowed)"
if [ "$found" -lt "$allowed" ]; then echo "mypy: lower .ci/mypy-baseline to $found" >&2; fi
