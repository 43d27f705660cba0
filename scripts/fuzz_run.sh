#!/usr/bin/env bash
# Runs one libFuzzer target of tests/fuzz for a set time under ASan+UBSan (docs/fuzzing.md).
#   bash scripts/fuzz_run.sh FUZZER SECONDS [CORPUS_DIR] [ARTIFACT_DIR]
# FUZZER is the built target (its name says which: scene_loader_fuzz, csv_fuzz, rpc3_fuzz,
# mbs_model_fuzz, eqs_fuzz, cli_fuzz, scene_run_fuzz). The corpus starts from the seeds for that
# target (every scene in scenarios/, small CSV tables, RPC III files of both data types, the model
# files of generated_models/, the equation lists of tests/symbolic/data/, a few command lines) and
# the committed, minimised corpus tests/fuzz/corpus/TARGET (read only), and keeps what the run
# finds; an empty CORPUS_DIR means a temporary one, removed afterwards (ctest). Exits 1 on a crash, leak, timeout or undefined
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
# absolute: cli_fuzz runs the program in a folder of its own (its working directory)
corpus=$(cd "$corpus" && pwd)
artifacts=$(cd "$artifacts" && pwd)
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
  scene_run_fuzz)
    cp -r "$root/scenarios/." "$seeds/" ;;
  mbs_model_fuzz)
    cp "$root"/generated_models/*.mbs.yaml "$seeds/" ;;
  eqs_fuzz)
    cp "$root"/tests/symbolic/data/*.eqs "$seeds/"
    # parameters, functions, precedence, select (tests/symbolic/eqs_reader_test.cpp)
    printf 'input x 2\nparam k 1\nA = 1 + 2*x[0]^2 - -x[1]/4   # comment\nB = select(x[0], min(x[0], x[1]), max(x[0], x[1])) + atan2(x[1], x[0]) + pow(x[0]*x[0]+1, 0.5)*k[0]\noutput a = A\noutput b = B\ntangent x\n' >"$seeds/functions.eqs" ;;
  cli_fuzz)
    # one argument a line; s.yaml, r.yaml and b.csv are the target's own files (tests/fuzz/cli_fuzz.cpp)
    printf 'run\ns.yaml\n--no-estimate\n--set\nmass=2' >"$seeds/run"
    printf 'run\ns.yaml\n--solver\nrk4\n--step\n0.001\n--format\nmat\n--report' >"$seeds/run_rk4"
    printf 'sweep\ns.yaml\n--param\nstiffness\n--range\n30:50:3\n--fd\n0.1,0.01\n--delta\n1' >"$seeds/sweep"
    printf 'screen\ns.yaml\n--params\nmass,damping\n--samples\n2\n--threads\n1' >"$seeds/screen"
    printf 'accuracy\ns.yaml\n--methods\nbdf,rk4\n--target\n1e-3' >"$seeds/accuracy"
    printf 'replay\nr.yaml\n--input\nb.csv\n--no-sens\n--format\nrpc' >"$seeds/replay"
    printf 'equilibrium\ns.yaml\n--time\n0.01' >"$seeds/equilibrium"
    printf 'linearize\ns.yaml\n--input\nforce.y\n--output\nbody.x\n--at\n0.02' >"$seeds/linearize"
    printf 'modes\ns.yaml\n--max-frequency\n10' >"$seeds/modes"
    printf 'frf\ns.yaml\n--input\nforce.y\n--output\nbody.x\n--frequencies\n0.5:5:4\n--report' >"$seeds/frf"
    printf 'blocks' >"$seeds/blocks"
    printf 'run\n--help' >"$seeds/help" ;;
  *) echo "fuzz_run.sh: unknown target $target (scene_loader_fuzz csv_fuzz rpc3_fuzz mbs_model_fuzz eqs_fuzz cli_fuzz scene_run_fuzz)" >&2; exit 2 ;;
esac

# The committed corpus (scripts/fuzz_minimise.sh writes it), when there is one: read, never written.
committed=()
[ -d "$root/tests/fuzz/corpus/$target" ] && committed=("$root/tests/fuzz/corpus/$target")

echo "== $target: ${seconds} s, corpus $corpus"
# A leak is a finding, whatever the caller's ASAN_OPTIONS say (the last setting wins); halt_on_error:
# UBSan stops at the first report, so libFuzzer records the input and exits non-zero.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=1"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:+$UBSAN_OPTIONS:}print_stacktrace=1:halt_on_error=1"
status=0
# -timeout per input: 120 s. An input CI reported as a 16 s timeout under -timeout=10 replays in
# 0.2 s: the time was the loaded machine's (tests run two at a time), not the input's.
"$fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=120 -print_final_stats=1 \
  -artifact_prefix="$artifacts/$target-" "$corpus" "$seeds" "${committed[@]}" >"$log" 2>&1 || status=$?
cat "$log"
if [ $status -ne 0 ] || grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error' "$log"; then
  echo "$target: finding (exit $status), input in $artifacts/" >&2
  exit 1
fi
