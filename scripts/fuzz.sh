#!/usr/bin/env bash
# Fuzzes the scene loader, the CSV reader and the RPC III reader with libFuzzer under ASan+UBSan (docs/fuzzing.md).
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     default: 60 s, every target
# Builds in build/fuzz with clang-14 (Debian: clang-14, libclang-rt-14-dev), seeds the corpora
# from scenarios/ and a few CSV tables, and keeps corpora and crash files in build/fuzz/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scene_loader_fuzz csv_fuzz rpc3_fuzz)

build=build/fuzz
CC=clang-14 CXX=clang++-14 cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DDYDP_BUILD_FUZZ=ON -DDYDP_BUILD_BENCH=OFF -DDYDP_BUILD_GUI=OFF >/dev/null
ninja -C "$build" -j "${DYDP_FUZZ_JOBS:-1}" "${targets[@]}"

# Seeds: every shipped scene; CSV tables shaped like recorded bench input.
mkdir -p "$build/corpus/scene_loader_fuzz" "$build/corpus/csv_fuzz" "$build/artifacts"
find scenarios -name '*.yaml' -exec cp {} "$build/corpus/scene_loader_fuzz/" \;
printf 't,fl,fr,rl,rr\n0,0,0,0,0\n0.5,0.01,0,0,0\n1.0,0.0,0.002,-0.001,0\n' >"$build/corpus/csv_fuzz/bench.csv"
printf 't,z\n0.0,0.0\n0.5, 1e-3\n\n1.0,2.5e-2\r\n' >"$build/corpus/csv_fuzz/table.csv"
# RPC III seeds of both data types, written by the tests' numpy writer (python/tests/rpc3_file.py).
mkdir -p "$build/corpus/rpc3_fuzz"
/usr/bin/python3 - "$build/corpus/rpc3_fuzz" <<'PY'
import sys
import numpy as np
sys.path.insert(0, "python/tests")
import rpc3_file
t = np.arange(40) * 0.01
channels = [("fl", "m", 0.01 * np.sin(t)), ("fr", "m", 0.02 * np.cos(3 * t))]
for data_type in ("SHORT_INTEGER", "FLOATING_POINT"):
    rpc3_file.write(f"{sys.argv[1]}/{data_type.lower()}.rsp", channels, 0.01, data_type, pts_per_frame=16, frames_per_group=2)
PY

status=0
for target in "${targets[@]}"; do
  echo "== $target: ${seconds} s"
  # detect_leaks stays on: a leak is a finding. The scene dictionary is the YAML keys of the format.
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build/tests/fuzz/$target" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$build/artifacts/$target-" -print_final_stats=1 \
    "$build/corpus/$target" 2>&1 | tee "$build/$target.log" | grep -E '^#[0-9]+[[:space:]]+(DONE|INITED)|stat::|ERROR|SUMMARY' || true
  if grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error' "$build/$target.log"; then
    echo "$target: finding, see $build/$target.log and $build/artifacts/" >&2
    status=1
  fi
done
exit $status
