#!/usr/bin/env bash
# Takes a screenshot of dydp-gui with a scene opened and run, under a virtual X server (Xvfb).
#   bash scripts/gui_screenshot.sh SCENE [OUT.png]     (default OUT: docs/gui.png)
# Builds dydp-gui if needed (Qt 6 required) and installs xvfb with apt-get if it is missing.
set -euo pipefail

if [ $# -lt 1 ]; then
  echo "usage: $0 SCENE [OUT.png]" >&2
  exit 2
fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scene="$(realpath "$1")"
out="$(realpath -m "${2:-$root/docs/gui.png}")"

if ! command -v xvfb-run >/dev/null; then
  echo "gui_screenshot: installing xvfb"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends xvfb xauth >/dev/null
fi

cd "$root"
if [ ! -f build/release/CMakeCache.txt ]; then cmake --preset release >/dev/null; fi
cmake --build build/release --target dydp_gui -j 2 >/dev/null
gui=build/release/gui/dydp-gui
if [ ! -x "$gui" ]; then
  echo "gui_screenshot: $gui was not built (is Qt 6 installed? see scripts/setup.sh)" >&2
  exit 1
fi

mkdir -p "$(dirname "$out")"
# 2000x1250: the whole sedan (car, four corner subsystems, rig, objectives) fitted with its port
# names legible, and the objectives table wide enough for every digit.
QT_QPA_PLATFORM=xcb xvfb-run -a -s "-screen 0 2000x1250x24" \
  "$gui" "$scene" --run --screenshot "$out" --size 2000x1250
echo "gui_screenshot: wrote $out"
