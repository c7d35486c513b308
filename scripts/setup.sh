#!/usr/bin/env bash
# Installs what synth needs on a fresh machine: Graphviz's dot (Debian) and the
# package with its test dependencies (pip). Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v dot >/dev/null 2>&1; then
  echo "== installing Graphviz (dot)" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq >&2
  apt-get install -y -qq graphviz >/dev/null
fi
echo "== installing synth" >&2
python3 -m pip install --quiet --disable-pip-version-check ".[test]" >&2
