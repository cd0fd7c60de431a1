#!/usr/bin/env bash
# Runs a benchmark by name: bench/run.sh <root> <name|all> [flags...]. Each bench/<name>.sh (or
# the executable <name>_bench) writes its results under out/bench/; the flags go to it (e.g.
# `./drape bench solvers --full`, `./drape bench stress --scale 2`; `<name> --help` lists them).
set -euo pipefail
ROOT="$1"; NAME="${2:-all}"
shift $(($# < 2 ? $# : 2))
cd "$ROOT"
mkdir -p out/bench
run_one() {
  local n="$1"; shift
  if [ -x "bench/$n.sh" ]; then
    "bench/$n.sh" "$ROOT" "$@"
  elif [ -x "build/bin/${n}_bench" ]; then
    "build/bin/${n}_bench" "$@"
  else
    echo "unknown benchmark '$n'; available:" >&2
    ls build/bin/*_bench 2>/dev/null | sed 's|.*/||; s|_bench$||' >&2
    return 2
  fi
}
if [ "$NAME" = all ]; then
  [ $# -eq 0 ] || { echo "bench all takes no flags (they differ per benchmark)" >&2; exit 2; }
  for b in build/bin/*_bench; do run_one "$(basename "$b" _bench)"; done
else
  run_one "$NAME" "$@"
fi
