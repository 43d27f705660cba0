#!/usr/bin/env bash
# Quick-start command 1: installs what is missing, builds dydp, runs the default scene
# and writes its results and report to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release --target dydp
scene=${1:-scenarios/fourposter_comfort.yaml}
./build/release/apps/dydp/dydp run "$scene" --out out --report
