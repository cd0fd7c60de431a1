#!/usr/bin/env bash
# ./drape bench solvers: the solver study, quick version by default (a few minutes);
# SOLVERS_FULL=1 ./drape bench solvers runs the full grid up to 128^2 scored, 256^2 timed (about 45 min).
set -euo pipefail
ROOT="${1:-.}"; shift || true
cd "$ROOT"
BIN=build/bin/solvers_bench
[ -x "$BIN" ] || BIN=$(ls build*/bin/solvers_bench 2>/dev/null | head -1)
if [ "${SOLVERS_FULL:-0}" = 1 ]; then
  exec "$BIN" --max-res 256 "$@"
fi
exec "$BIN" --quick "$@"
