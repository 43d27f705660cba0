#!/usr/bin/env bash
# Runs one libFuzzer target of tests/fuzz for a set time under ASan+UBSan (docs/fuzzing.md).
#   bash scripts/fuzz_run.sh FUZZER SECONDS [CORPUS_DIR] [ARTIFACT_DIR]
# FUZZER is the built target (its name says which reader: scene_loader_fuzz, csv_fuzz, rpc3_fuzz).
# The corpus starts from the seeds for that reader (every scene in scenarios/, small CSV tables,
# RPC III files of both data types) and keeps what the run finds; an empty CORPUS_DIR means a
# temporary one, removed afterwards (ctest). Exits 1 on a crash, leak, timeout or undefined
# behaviour, with the input that caused it in ARTIFACT_DIR and libFuzzer's log on stdout.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
fuzzer=$1
seconds=$2
corpus=${3:-}
artifacts=${4:-$PWD/artifacts}
target=$(basename "$fuzzer")

temporary_corpus=false
if [ -z "$corpus" ]; then
  corpus=$(mktemp -d)
  temporary_corpus=true
fi
mkdir -p "$corpus" "$artifacts"
seeds=$(mktemp -d)
log=$(mktemp)
trap 'rm -rf "$seeds" "$log"; if $temporary_corpus; then rm -rf "$corpus"; fi' EXIT

case "$target" in
  scene_loader_fuzz)
    # every shipped scene and subsystem file; libFuzzer reads the folders recursively
    cp -r "$root/scenarios/." "$seeds/" ;;
  csv_fuzz)
    # tables shaped like recorded bench input: a header, blanks, CRLF, exponents
    printf 't,fl,fr,rl,rr\n0,0,0,0,0\n0.5,0.01,0,0,0\n1.0,0.0,0.002,-0.001,0\n' >"$seeds/bench.csv"
    printf 't,z\n0.0,0.0\n0.5, 1e-3\n\n1.0,2.5e-2\r\n' >"$seeds/table.csv" ;;
  rpc3_fuzz)
    # both data types, written by the tests' numpy writer (python/tests/rpc3_file.py)
    /usr/bin/python3 - "$seeds" "$root/python/tests" <<'PY'
import sys
import numpy as np
sys.path.insert(0, sys.argv[2])
import rpc3_file
t = np.arange(40) * 0.01
channels = [("fl", "m", 0.01 * np.sin(t)), ("fr", "m", 0.02 * np.cos(3 * t))]
for data_type in ("SHORT_INTEGER", "FLOATING_POINT"):
    rpc3_file.write(f"{sys.argv[1]}/{data_type.lower()}.rsp", channels, 0.01, data_type, pts_per_frame=16, frames_per_group=2)
PY
    ;;
  *) echo "fuzz_run.sh: unknown target $target (scene_loader_fuzz, csv_fuzz, rpc3_fuzz)" >&2; exit 2 ;;
esac

echo "== $target: ${seconds} s, corpus $corpus"
# A leak is a finding, whatever the caller's ASAN_OPTIONS say (the last setting wins); halt_on_error:
# UBSan stops at the first report, so libFuzzer records the input and exits non-zero.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=1"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:+$UBSAN_OPTIONS:}print_stacktrace=1:halt_on_error=1"
status=0
# -timeout per input: 120 s. An input CI reported as a 16 s timeout under -timeout=10 replays in
# 0.2 s: the time was the loaded machine's (tests run two at a time), not the input's.
"$fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=120 -print_final_stats=1 \
  -artifact_prefix="$artifacts/$target-" "$corpus" "$seeds" >"$log" 2>&1 || status=$?
cat "$log"
if [ $status -ne 0 ] || grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error' "$log"; then
  echo "$target: finding (exit $status), input in $artifacts/" >&2
  exit 1
fi
