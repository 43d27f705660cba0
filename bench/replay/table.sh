#!/usr/bin/env bash
# The replay accuracy table of docs/accuracy.md: every benchmark recording replayed with the
# default (error-controlled rosw), with a fixed 2.5 ms rosw step, and with BDF at rtol 2e-5
# (order 3), each against a BDF reference at rtol = atol = 1e-9, with the valve-current
# sensitivity. Errors by compare.py; the estimate from each run's run.json.
#
#   bench/replay/table.sh DYDP DIR [BASELINE_DYDP]
#
# DIR: made by make_recordings.py (and shaker.csv from make_shaker.py 20). References are
# computed once (DIR/ref_NAME) and kept. BASELINE_DYDP: another binary whose default replay is
# measured beside (a row "baseline default").
set -euo pipefail
dydp=$1; dir=$2; base=${3:-}
here=$(cd "$(dirname "$0")" && pwd)
scene=$dir/sedan20.yaml
for rec in road_A road_B road_C road_D cleat chirp noise shaker; do
  [ -f "$dir/$rec.csv" ] || continue
  if [ ! -f "$dir/ref_$rec/run.json" ]; then
    "$dydp" replay "$scene" --input "$dir/$rec.csv" --solver bdf --rtol 1e-9 --atol 1e-9 --no-estimate --out "$dir/ref_$rec" >/dev/null 2>&1
  fi
  runs=()
  "$dydp" replay "$scene" --input "$dir/$rec.csv" --out "$dir/default_$rec" >/dev/null 2>"$dir/default_$rec.err" || true
  runs+=("$dir/default_$rec")
  "$dydp" replay "$scene" --input "$dir/$rec.csv" --step 0.0025 --out "$dir/fixed_$rec" >/dev/null 2>"$dir/fixed_$rec.err" || true
  runs+=("$dir/fixed_$rec")
  "$dydp" replay "$scene" --input "$dir/$rec.csv" --solver bdf --rtol 2e-5 --atol 2e-5 --max-order 3 --out "$dir/bdf_$rec" >/dev/null 2>"$dir/bdf_$rec.err" || true
  runs+=("$dir/bdf_$rec")
  if [ -n "$base" ]; then
    "$base" replay "$scene" --input "$dir/$rec.csv" --out "$dir/base_$rec" >/dev/null 2>"$dir/base_$rec.err" || true
    runs+=("$dir/base_$rec")
  fi
  echo "## $rec"
  python3 "$here/compare.py" "$dir/ref_$rec" "${runs[@]}"
done
