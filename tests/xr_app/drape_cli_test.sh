#!/usr/bin/env bash
# The `drape` executable on the mock runtime, as a user runs it:
#   xr         `drape xr --frames N` with XR_RUNTIME_JSON unset falls back to the mock runtime
#              next to the executable, renders, exits 0; the runtime's frame count matches.
#   validation the same under the OpenXR core validation layer: zero validation messages.
#   run        `drape run` (the default draping scenario) writes frames, the session log, the
#              cloth glTF and the pattern to its out dir, exits 0, well under 2 minutes.
#   args       out-of-range and misplaced arguments of `drape xr` and `drape run` exit 2 with a
#              message naming the option; --help exits 0 and lists every option (drape run's
#              also the command map's bindings).
# usage: drape_cli_test.sh DRAPE_EXE MODE WORKDIR
set -u
exe=$1 mode=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
log=$work/log.txt
fail() { echo "FAIL: $*"; echo "--- log:"; cat "$log"; exit 1; }
# No configured runtime: no XR_RUNTIME_JSON, an empty config home.
unset XR_RUNTIME_JSON DRAPE_MOCK_SCENARIO DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_WRITE_FRAMES
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_CONFIG_DIRS=$work/none
export DRAPE_MOCK_FAST=1
case $mode in
  xr|validation)
    [ "$mode" = validation ] && export XR_ENABLE_API_LAYERS=XR_APILAYER_LUNARG_core_validation
    "$exe" xr --frames 20 --eye-size 64 --cloth-res 12 >"$log" 2>&1
    rc=$?
    [ $rc -eq 0 ] || fail "exit code $rc"
    grep -q "runtime manifest: .*/drape_mock_runtime.json" "$log" || fail "did not fall back to the mock runtime"
    line=$(grep "^drape xr: exiting" "$log") || fail "no 'exiting' summary"
    echo "$line"
    app=$(sed -n "s/.*frames \([0-9]*\) (rendered \([0-9]*\)).*/\1 \2/p" <<<"$line")
    read -r frames rendered <<<"$app"
    composed=$(sed -n 's/^frames composed: \([0-9]*\)/\1/p' "$log")
    echo "app frames $frames, rendered $rendered, runtime composed $composed"
    [ "$frames" -ge 20 ] || fail "fewer than 20 frames"
    [ "$rendered" = "$frames" ] || fail "not every frame rendered"
    [ "$composed" = "$frames" ] || fail "runtime composed $composed != app frames $frames"
    grep -q "validation messages 0" "$line" 2>/dev/null || grep -q "validation messages 0" <<<"$line" || fail "validation messages"
    if [ "$mode" = validation ]; then
      grep -qi "VALID_ERROR\|VUID-" "$log" && fail "validation errors in the log"
    fi
    ;;
  run)
    cd "$work" || exit 1
    start=$(date +%s.%N)
    "$exe" run --out "$work/out" --eye-size 128 >"$log" 2>&1
    rc=$?
    end=$(date +%s.%N)
    secs=$(echo "$end - $start" | bc)
    echo "drape run: exit $rc in $secs s"
    [ $rc -eq 0 ] || fail "exit code $rc"
    (( $(echo "$secs < 100" | bc) )) || fail "took $secs s"
    for f in session_log.json drape_cloth.gltf xr_session.txt scenario.json voice/cue0.wav; do
      [ -s "$work/out/$f" ] || fail "missing out/$f"
    done
    n=$(ls "$work/out/frames"/frame_*.png 2>/dev/null | wc -l)
    echo "$n screenshots"
    [ "$n" -ge 5 ] || fail "only $n screenshots"
    # The pattern of the cloth as draped (pinned and cut): every file it names, the cut's two
    # pieces.
    grep -q "pattern: 2 piece(s), 1 cut edge(s)" "$log" || fail "the session pattern: $(grep pattern: "$log")"
    for f in pattern.svg pattern.dxf pattern_a4.pdf report.json; do
      grep -q "wrote .*/pattern/session-1/$f" "$log" && [ -s "$work/out/pattern/session-1/$f" ] ||
        fail "no pattern/session-1/$f"
    done
    # Read back: the PDF by poppler, the SVG by librsvg, the DXF's two piece blocks.
    pat="$work/out/pattern/session-1"
    pages=$(pdfinfo "$pat/pattern_a4.pdf" | awk '/^Pages:/ {print $2}')
    [ "${pages:-0}" -ge 2 ] || fail "pattern_a4.pdf does not read (pages: ${pages:-none})"
    rsvg-convert "$pat/pattern.svg" -o "$work/pattern.png" && [ -s "$work/pattern.png" ] ||
      fail "pattern.svg does not render"
    [ "$(grep -c "^Piece Name: Piece" "$pat/pattern.dxf")" -eq 2 ] || fail "pattern.dxf: not 2 pieces"
    # ezdxf (Debian's python3-ezdxf, hence the system interpreter): two piece blocks inserted, each
    # with one closed boundary polyline on layer 1.
    /usr/bin/python3 - "$pat/pattern.dxf" <<'PY' || fail "pattern.dxf does not read back with ezdxf"
import sys, ezdxf
doc = ezdxf.readfile(sys.argv[1])
inserts = [e for e in doc.modelspace() if e.dxftype() == "INSERT"]
assert len(inserts) == 2, len(inserts)
for ins in inserts:
    bounds = [e for e in doc.blocks[ins.dxf.name] if e.dxftype() == "POLYLINE" and e.dxf.layer == "1"]
    assert len(bounds) == 1 and bounds[0].is_closed, ins.dxf.name
print("ezdxf: 2 pieces, each with a closed boundary")
PY
    summary=$(grep "^drape run: exiting" "$log") || fail "no summary"
    echo "$summary"
    grep -q "voice commands 1" <<<"$summary" || fail "voice pin not heard"
    grep -q "pinched in [1-9][0-9]* frames" <<<"$summary" || fail "the pinch took nothing"
    grep -q " [1-9][0-9]* vertices pinned" <<<"$summary" || fail "nothing pinned"
    grep -q " 1 cut(s)" <<<"$summary" || fail "the cut stroke was not applied"
    grep -q "; 1 -> 2 parts" <<<"$summary" || fail "the cut did not split the cloth in two"
    grep -q "command map: .*commands.json" "$work/out/xr_session.txt" || fail "command map not loaded"
    ;;
  args)
    : >"$log"
    reject() {  # reject OPTION ARGS...: exit 2, the message names OPTION
      local opt=$1; shift
      "$exe" "$@" >"$work/out.txt" 2>&1
      local rc=$?
      cat "$work/out.txt" >>"$log"
      echo "drape $*: exit $rc: $(head -n 1 "$work/out.txt")"
      [ $rc -eq 2 ] || fail "drape $* exited $rc, not 2"
      grep -q -- "$opt" "$work/out.txt" || fail "drape $*: the message does not name $opt"
    }
    reject --cloth-res xr --cloth-res 0
    reject --cloth-res xr --cloth-res -3
    reject --cloth-res xr --cloth-res=-3
    reject --cloth-res xr --cloth-res twelve
    reject --eye-size xr --eye-size 0
    reject --frames xr --frames 0
    reject --pose-wait-ms xr --pose-wait-ms -1
    reject --scenario xr --scenario "$work/none.json"
    reject --commands xr --commands "$work/none.json"
    reject --eye-size run --eye-size 0
    reject --cloth-res run --cloth-res 300
    reject --every run --every 0
    reject --seconds run --headless --seconds 0
    reject --resolution run --headless --resolution 2
    reject --stiffness-scale run --headless --stiffness-scale 11
    reject --seconds run --seconds 2
    reject --eye-size run --headless --eye-size 64
    reject --bogus xr --bogus
    for cmd in xr run; do
      "$exe" $cmd --help >"$work/help.txt" 2>&1 || fail "drape $cmd --help exited $?"
      opts=(--frames --eye-size --cloth-res --verbose --assets)
      [ $cmd = xr ] && opts+=(--scenario --no-render --sim-free --pose-wait-ms --commands --no-ops
        --out --json --full-form --no-malloc-tuning)
      [ $cmd = run ] && opts+=(--scenario --out --no-voice --no-pattern --every --headless
        --seconds --resolution --fabric --size --realtime --stiffness-scale)
      for o in "${opts[@]}"; do
        grep -q -- "$o" "$work/help.txt" || fail "drape $cmd --help does not list $o"
      done
      echo "drape $cmd --help lists ${#opts[@]} options"
    done
    # drape run --help ends with the command map's bindings (the bundled assets/commands.json).
    grep -q "^Bindings (.*commands.json" "$work/help.txt" || fail "drape run --help lists no bindings"
    for b in "gesture +pinch +begin -> pinch begin" "voice +pin +any +-> pin once" \
             "controller button.trigger +begin -> pinch begin" "controller button.a +begin -> cut toggle"; do
      grep -Eq "^  $b" "$work/help.txt" || fail "drape run --help does not list the binding '$b'"
    done
    echo "drape run --help lists $(grep -c ' -> ' "$work/help.txt") bindings"
    ;;
  *) echo "unknown mode $mode"; exit 2 ;;
esac
echo PASS
