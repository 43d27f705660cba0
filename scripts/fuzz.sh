#!/usr/bin/env bash
# Fuzzes the input readers, the command line and a bounded run of a scene with libFuzzer under ASan+UBSan (docs/fuzzing.md).
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     default: 60 s, every target
# Builds the targets in the sanitize preset's build (build/sanitize, clang-14; scripts/setup.sh
# installs clang-14 and libclang-rt-14-dev) and runs each with scripts/fuzz_run.sh, keeping its
# corpus in build/sanitize/corpus/TARGET and what it finds in build/sanitize/artifacts.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scene_loader_fuzz csv_fuzz rpc3_fuzz mbs_model_fuzz eqs_fuzz cli_fuzz scene_run_fuzz)

build=build/sanitize
cmake --preset sanitize >/dev/null
ninja -C "$build" -j "${DYDP_FUZZ_JOBS:-1}" "${targets[@]}"

status=0
for target in "${targets[@]}"; do
  bash scripts/fuzz_run.sh "$build/tests/fuzz/$target" "$seconds" "$build/corpus/$target" "$build/artifacts" \
    >"$build/$target.log" 2>&1 || status=1
  grep -E '^== |^#[0-9]+[[:space:]]+(DONE|INITED)|stat::|ERROR|SUMMARY|finding' "$build/$target.log" || true
done
exit $status
