#!/usr/bin/env bash
# ./drape bench solvers: the solver study (pass --quick for the short version).
set -euo pipefail
ROOT="${1:-.}"; shift || true
cd "$ROOT"
BIN=build/bin/solvers_bench
[ -x "$BIN" ] || BIN=$(ls build*/bin/solvers_bench 2>/dev/null | head -1)
exec "$BIN" --max-res 128 "$@"
