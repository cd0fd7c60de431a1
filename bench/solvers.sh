#!/usr/bin/env bash
# ./drape bench solvers: the solver benchmark, quick version by default (a few minutes);
# ./drape bench solvers --full runs the full grid up to 128^2 scored, 256^2 timed (about 45 min).
# Other flags go to solvers_bench (`build/bin/solvers_bench --help`).
set -euo pipefail
ROOT="${1:-.}"; shift || true
cd "$ROOT"
BIN=build/bin/solvers_bench
[ -x "$BIN" ] || BIN=$(ls build*/bin/solvers_bench 2>/dev/null | head -1)
MODE=(--quick)
ARGS=()
for a in "$@"; do
  if [ "$a" = --full ]; then MODE=(--max-res 256); else ARGS+=("$a"); fi
done
exec "$BIN" "${MODE[@]}" "${ARGS[@]}"
