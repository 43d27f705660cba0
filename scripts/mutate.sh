#!/usr/bin/env bash
# Mutation score of the tangent and derivative code (docs/testing.md, "Mutation score").
#   bash scripts/mutate.sh [N] [SEED] [mutate.py options]     default: 100 mutants, seed 44
# Applies single-token mutations (a sign flipped, a term times 2, a subscript off by one, a term
# dropped) to the functions that compute tangents, Jacobians and derivatives in blocks/, engine/
# and the generator (symbolic/differentiate.cpp, grouped_tangent.cpp, the tangent emission of
# emit_cpp_tangent.cpp), one mutant at a time: the file edited, the test executables that cover it rebuilt
# in the release build (ninja, only what changed), run with a time limit (120 s an executable),
# the mutant recorded killed, survived or stillborn (does not compile), the file restored. The
# sample is drawn with the seed from all the mutants (scripts/mutate.py --list prints it).
# Results: build/mutate/results.jsonl (one line a mutant), the build and test output in
# build/mutate/mutate.log; the score and the survivors are printed at the end.
# From a clean checkout it configures and builds the release preset first. The tree is left as it
# was: the original of the file under mutation is restored on exit, on an error and on Ctrl-C (and,
# after a hard kill, from build/mutate/backup at the next start).
#   bash scripts/mutate.sh 100 44 --only ID[,ID...]   re-run some mutants (ids from the results)
#   bash scripts/mutate.sh 100 44 --skip K            resume a sample after its first K mutants
#   bash scripts/mutate.sh 100 44 --summary           the score of what has been run
set -euo pipefail
cd "$(dirname "$0")/.."
count=${1:-100}
seed=${2:-44}
shift $(( $# < 2 ? $# : 2 ))
out=build/mutate
mkdir -p "$out/backup"

restore_backup() {
  if [ -f "$out/backup/original" ]; then
    path=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["path"])' "$out/backup/original")
    cp "$out/backup/original.src" "$path"
    rm -f "$out/backup/original"
    echo "mutate.sh: restored $path" >&2
  fi
}
restore_backup  # a run killed before it could restore its file
trap restore_backup EXIT

for a in "$@"; do
  case "$a" in --summary|--list) exec python3 scripts/mutate.py --count "$count" --seed "$seed" "$@" ;; esac
done

before=$(git status --porcelain -- blocks engine symbolic; git diff -- blocks engine symbolic | sha1sum)
[ -f build/release/build.ninja ] || cmake --preset release
cmake --build --preset release  # the unmutated build, so that a mutant rebuilds only its own file
python3 scripts/mutate.py --count "$count" --seed "$seed" --jobs "${DYDP_MUTATE_JOBS:-2}" "$@"
after=$(git status --porcelain -- blocks engine symbolic; git diff -- blocks engine symbolic | sha1sum)
if [ "$before" != "$after" ]; then
  echo "mutate.sh: blocks/, engine/ or symbolic/ differ from before the run" >&2
  exit 1
fi
