#!/usr/bin/env bash
# Minimises a target's corpus into the committed one (docs/fuzzing.md).
#   bash scripts/fuzz_minimise.sh TARGET...
# Merges build/sanitize/corpus/TARGET (what scripts/fuzz.sh kept) and tests/fuzz/corpus/TARGET
# (committed) with libFuzzer's -merge=1: the smallest set of inputs that reaches every feature
# (edge and counter) either reaches, written to tests/fuzz/corpus/TARGET. The seeds of
# scripts/fuzz_run.sh are not in it (fuzz_run.sh writes them at every run). Inputs over 8 kB are
# left out (variants of the large seeds, the sedan and the 200-body chain, which the seeds bring
# back at every run), to keep the committed corpus small. Files are named by their SHA-1, as
# libFuzzer names them.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/sanitize
[ $# -gt 0 ] || { echo "usage: bash scripts/fuzz_minimise.sh TARGET..." >&2; exit 2; }
for target in "$@"; do
  fuzzer=$build/tests/fuzz/$target
  committed=tests/fuzz/corpus/$target
  merged=$(mktemp -d)
  mkdir -p "$committed" "$build/corpus/$target"
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
  "$fuzzer" -merge=1 -rss_limit_mb=2048 -timeout=120 "$merged" "$committed" "$build/corpus/$target" \
    >"$build/$target.merge.log" 2>&1
  find "$merged" -type f -size +8k -delete
  rm -rf "$committed"
  mv "$merged" "$committed"
  chmod 755 "$committed"
  echo "$target: $(ls "$committed" | wc -l) inputs, $(du -sk "$committed" | cut -f1) kB in $committed"
done
