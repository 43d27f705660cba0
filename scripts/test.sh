#!/usr/bin/env bash
# Quick-start command 2: installs what is missing, builds, and runs every test.
# With --preset sanitize it does the same in an ASan+UBSan build.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=release
if [ "${1:-}" = "--preset" ]; then preset=$2; fi
bash scripts/setup.sh
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset"
ctest --preset "$preset"
