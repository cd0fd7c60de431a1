# What the benchmarks that run `drape xr` on the mock runtime share (sourced by board.sh and
# garment.sh; ROOT is the source tree).

# bench_parse_frames NAME DEFAULT MIN MAX HELP_END ARGS...: sets FRAMES from --frames N (default
# DEFAULT, MIN to MAX frames); -h/--help prints the script's comment lines 2 to HELP_END. Exits
# 2 on an unknown flag or a count out of range, naming `bench NAME`.
bench_parse_frames() {
  local name="$1" min="$3" max="$4" help_end="$5"
  FRAMES="$2"
  shift 5
  while [ $# -gt 0 ]; do
    case "$1" in
      --frames) FRAMES="${2-}"; shift $(($# > 1 ? 2 : 1)) ;;
      -h | --help) sed -n "2,${help_end}p" "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
      *) echo "bench $name: unknown flag '$1' (--frames N)" >&2; exit 2 ;;
    esac
  done
  [[ "$FRAMES" =~ ^[0-9]+$ && "$FRAMES" -ge "$min" && "$FRAMES" -le "$max" ]] ||
    { echo "bench $name: --frames: $min to $max" >&2; exit 2; }
}

# bench_mock_setup NAME: in ROOT, BUILD (DRAPE_BUILD_DIR, default build) and EXE (its drape,
# which must be built), WORK = out/bench/NAME emptied, the mock runtime as the OpenXR runtime and
# its test-only variables unset.
bench_mock_setup() {
  cd "$ROOT"
  BUILD="${DRAPE_BUILD_DIR:-build}"
  EXE="$BUILD/bin/drape"
  [ -x "$EXE" ] || { echo "bench $1: $EXE not built" >&2; exit 2; }
  WORK="out/bench/$1"
  rm -rf "$WORK" && mkdir -p "$WORK"
  export XR_RUNTIME_JSON="$ROOT/$BUILD/bin/drape_mock_runtime.json"
  unset DRAPE_MOCK_WRITE_FRAMES DRAPE_MOCK_FAST DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_SCENARIO
}
