#!/usr/bin/env bash
# README's main job: set up, then validate the bundled box-sorting example.
set -uo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
synth plant plants/tri.rules
synth sup plants/tri.rules
