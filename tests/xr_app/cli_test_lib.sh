# Shared by the command-line tests (sourced): cli_test_setup NAME makes a scratch directory,
# removed on exit, and enters it; fail prints its message and the last command's output
# (out.txt) and exits 1; expect checks one `drape` run.
# Needs $exe (the drape executable).

cli_test_setup() {
  work=$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX") || exit 1
  trap 'rm -rf "$work"' EXIT
  cd "$work" || exit 1
}

fail() { echo "FAIL: $*"; cat out.txt; exit 1; }

# expect RC [TEXT...] -- ARGS...: drape ARGS exits RC and its output contains each TEXT.
expect() {
  local rc=$1 texts=()
  shift
  while [ "$1" != -- ]; do texts+=("$1"); shift; done
  shift
  "$exe" "$@" >out.txt 2>&1
  local got=$?
  [ $got -eq "$rc" ] || fail "drape $*: exit $got, expected $rc"
  for t in "${texts[@]}"; do grep -qF -- "$t" out.txt || fail "drape $*: no '$t' in the output"; done
  echo "ok: drape $* (exit $got)"
}
