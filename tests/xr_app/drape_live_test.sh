#!/usr/bin/env bash
# `drape run` at a desk: a display (Xvfb), no headset runtime configured, so the app runs live
# in the simulated runtime's window (DRAPE_MOCK_WINDOW, docs/mock-window.md) with no scenario.
# A person's input as real X events (xdotool, XTEST).
#   drape_live_test.sh DRAPE_EXE OUTDIR [free|golden|pin|save|scene] [--update-golden]
# free (default): the sim on its own 90 Hz thread, a 12² cloth; the mouse over the cloth, the
#   left button held (pinch), a drag, the release, Escape. Checks
#   * the runtime put the hand on the depth the app submitted (DRAPE_MOCK_WINDOW_LOG: z is the
#     depth under the cursor, at the cloth's distance, not the 0.45 m default without depth);
#   * the pinch took a cloth particle and the drag moved it (the app's xr_session.txt);
#   * the session ended by Escape with exit 0;
#   and keeps a screenshot (OUT/window.png) to look at.
# golden: the sim in lock step (--sim-lock-step, repeatable), a 16² cloth: press-drag-release
#   pinches and moves the cloth; in the oculus/touch profile (Tab) key 1 (A) starts a cut stroke,
#   the mouse crosses the cloth, 1 again ends it and the cut splits the cloth; key 2 (B) undoes
#   it. Each step is checked in the session's outputs (xr_session.txt with --state-hashes,
#   session_log.json) and in a screenshot compared with tests/xr_app/golden/live_*.png
#   (compare_golden in window_test_lib.sh).
# pin: hand tracking (the window's start profile when the app enables hand tracking), lock step:
#   with the hanging cloth at rest, Z (the thumb-middle pinch: the right hand's pin) pins the cloth
#   under the hand; checked in xr_session.txt (pinned vertices added), session_log.json (a pin
#   trigger) and the golden image live_pin.png; then the left button pinches, and P (the right
#   hand pointing) writes the pattern mid-session into out/pattern/session-1/ (the log line with
#   its tick; with --no-pattern no session-2 at the end).
# save: lock step, in the oculus/touch profile (Tab): F5 (a tap) holds the left controller's menu
#   button for 1.1 s (the window's frames); held 1 s, the app saves the session into
#   out/saved_session.drape (xr_session.txt: the controller's "menu held 1 s -> save", no menu
#   tap, and the save's line with its tick). `drape open` of that file in the window starts from its tick and
#   exits 0; the file's saved tick is the one the log names.
# scene: the scene's options (--fabric, --form, --mesh, --start, --resolution, --garment): bad
#   values exit 2 naming the option and file before a window opens; good ones (the sewn garment
#   too) run 20 live frames; a fakenect recording as the hands (--hands kinect --kinect-record)
#   runs live to its last frame.
# --update-golden: the screenshots become the golden images (look at them before committing).
set -uo pipefail
EXE="$1" OUT="$2" MODE="${3:-free}"
[ "${4:-}" = "--update-golden" ] && UPDATE_GOLDEN=1
GOLDEN="$(cd "$(dirname "$0")" && pwd)/golden"
REGION="300 380 520 600"  # the form and the cloth in the view: the image checks look there
case "$MODE" in
  free) ARGS=(--resolution 12 --eye-size 256) ;;
  # The cloth's image without the feedback panel and the pattern board (each has its own tests).
  golden | pin) ARGS=(--resolution 16 --eye-size 256 --sim-lock-step --state-hashes
    --no-feedback-panel --no-board) ;;
  save) ARGS=(--resolution 16 --eye-size 128 --sim-lock-step --no-board) ;;
  scene) ;;
  *) echo "usage: drape_live_test.sh DRAPE_EXE OUTDIR [free|golden|pin|save|scene] [--update-golden]"; exit 2 ;;
esac
rm -rf "$OUT" && mkdir -p "$OUT/home"
source "$(dirname "$0")/window_test_lib.sh"
start_xvfb

# No runtime configured: the launch falls back to the simulated runtime and, with a display,
# opens its window. The window's size and log are the runtime's own variables.
unset XR_RUNTIME_JSON XR_ENABLE_API_LAYERS DRAPE_MOCK_WINDOW DRAPE_MOCK_SCENARIO \
  DRAPE_MOCK_WRITE_FRAMES DRAPE_MOCK_END_AFTER_FRAMES
export HOME="$OUT/home" XDG_CONFIG_HOME="$OUT/home/.config" XDG_CONFIG_DIRS="$OUT/home/xdg"
export DRAPE_MOCK_WINDOW_SIZE=800x600 DRAPE_MOCK_WINDOW_LOG="$LOG"

# scene: the live scene's options. Bad values exit 2 with a message naming the option (and the
# file) before a window opens; each start state, a measurements file, a fabric and a mesh form
# run a short live session (--frames) to exit 0.
if [ "$MODE" = scene ]; then
  bad() {  # bad "MESSAGE" ARGS...: drape run ARGS exits 2, stderr holds MESSAGE, no window frame
    local want="$1"; shift
    rm -f "$LOG"
    "$EXE" run --out "$OUT/bad" --no-pattern "$@" >"$OUT/stdout" 2>"$OUT/stderr"; local rc=$?
    [ "$rc" -eq 2 ] || fail "drape run $* exited with $rc, not 2"
    grep -qF -- "$want" "$OUT/stderr" || fail "drape run $*: no '$want' in: $(cat "$OUT/stderr")"
    [ "$(lines)" -eq 0 ] || fail "drape run $*: a window opened"
    echo "ok: $* -> $(head -1 "$OUT/stderr")"
  }
  bad "--fabric silk: " --fabric silk
  bad "fabrics.json" --fabric silk
  bad "--form 99XX: 99XX: unknown form size" --form 99XX
  bad "--form: no such file: nowhere.json" --form nowhere.json
  bad "--mesh: no such file: nowhere.obj" --mesh nowhere.obj
  bad "--start: 'upside' is none of spread|rolled|pinned-top" --start upside
  bad "--resolution: Value 300 not in range 4 to 256" --resolution 300
  bad "--garment: no such design: nosuch" --garment nosuch
  echo '{"bust_girth": -1}' >"$OUT/bad_form.json"
  bad "--form $OUT/bad_form.json: $OUT/bad_form.json" --form "$OUT/bad_form.json"
  "$EXE" form --size 11AR --export "$OUT/form.obj" >/dev/null || fail "drape form --export"
  good() {  # good WHAT ARGS...: a 20-frame live session with ARGS exits 0 and says WHAT
    local want="$1"; shift
    rm -f "$LOG"
    "$EXE" run --out "$OUT/good" --no-pattern --resolution 16 --eye-size 128 --frames 20 "$@" \
      >"$OUT/stdout" 2>"$OUT/stderr" || fail "drape run $* failed: $(tail -3 "$OUT/stderr")"
    grep -qF -- "$want" "$OUT/stdout" || fail "drape run $*: no '$want' in: $(head -3 "$OUT/stdout")"
    [ "$(lines)" -ge 20 ] || fail "drape run $*: fewer than 20 window frames"
    echo "ok: $* -> $want"
  }
  good "16 x 16 muslin cloth, start pinned-top, form 9AR"
  good "start spread" --start spread
  good "start rolled" --start rolled
  good "denim cloth" --fabric denim --form 13AR
  good "form $(cd "$(dirname "$0")/../.." && pwd)/assets/forms/7AR.json" \
    --form "$(cd "$(dirname "$0")/../.." && pwd)/assets/forms/7AR.json"
  good "form $OUT/form.obj" --mesh "$OUT/form.obj" --start spread
  # The sewn garment instead of the panel (docs/xr.md, "The sewn garment in the app").
  good "live, the garment of" --garment tight-skirt
  grep -q "^garment: tick 0: 9516 vertices" "$OUT/good/xr_session.txt" || fail "--garment: not loaded"
  # --hands kinect --kinect-record: the program runs itself again under fakenect and still goes
  # live in the window; the recording's end is the session's status, and it runs to its last frame.
  python3 "$(dirname "$0")/kinect_record.py" "$OUT/rec" "$OUT/kinect.json" 0.11 1.15 0.115 \
    --until 0.6 || fail "the recording writer failed"
  rm -f "$LOG"
  "$EXE" run --out "$OUT/kinect" --no-pattern --resolution 12 --eye-size 128 --frames 200 \
    --hands kinect --kinect-record "$OUT/rec" --calibration "$OUT/kinect.json" \
    >"$OUT/stdout" 2>"$OUT/stderr" || fail "drape run --hands kinect failed: $(tail -3 "$OUT/stderr")"
  grep -q "live in the simulated runtime's window" "$OUT/stdout" || fail "--hands kinect: not live"
  [ "$(lines)" -ge 200 ] || fail "--hands kinect: fewer than 200 window frames"
  grep -q "hands: kinect: the recording $OUT/rec ended" "$OUT/kinect/xr_session.txt" ||
    fail "--hands kinect: no status for the recording's end"
  rm -rf "$OUT/rec"
  echo "ok: --hands kinect --kinect-record in the window"
  echo PASS
  exit 0
fi
"$EXE" run --out "$OUT/out" --no-pattern "${ARGS[@]}" >"$OUT/stdout" 2>"$OUT/stderr" &
CLIENT_PID=$!


for _ in $(seq 1200); do [ "$(lines)" -ge 5 ] && break; kill -0 $CLIENT_PID 2>/dev/null || break; sleep 0.05; done
[ "$(lines)" -ge 5 ] || fail "no window frames logged (did the window open?)"
grep -q "live in the simulated runtime's window" "$OUT/stdout" || fail "drape run did not go live"
WID=$(xdotool search --name "drape mock runtime" | head -1)
[ -n "$WID" ] || fail "no window named 'drape mock runtime'"

# The view: one 256 px eye scaled to 600x600 at x 100..700. The head at (0, 1.6, 1.0) looks
# down -z at the dress form; the cloth hangs on it around x 340..480, y 410..570.
# Lock step: the cloth comes to rest before the hand meets it, and after every step of the
# input below, so the frame an X event lands in does not change what follows.
[ "$MODE" = free ] || frames 240
# --- before the cloth: the background (far plane) under the cursor
xdotool mousemove 400 100
expect "nothing drawn under the cursor over the sky" "f('cursor') == 'in' and f('depth') == '-'"
# --- over the cloth: the hand goes onto the submitted depth
xdotool mousemove 410 500
expect "the hand sits on the cloth's depth (not the 0.45 m default)" \
  "f('depth') != '-' and 0.8 < v('depth') < 1.6 and abs(v('z') - v('depth')) < 1e-3"
frames 5
z_cloth=$(field z)
echo "hand at the cloth's depth: $z_cloth m"
# The hand's proxy (2 cm) pushes the cloth it rests on back a little and the hand follows the
# surface; drawn by the app into its depth it would instead walk toward the eye (~5 mm/frame).
frames 30
expect "the hand stays on the cloth (not pulled toward the eye by its own drawing)" \
  "f('depth') != '-' and $z_cloth - 0.01 < v('z') < $z_cloth + 0.05"

# --- pinch, drag up and to the left, release
# pinch_drag [NAME]: with NAME, the drag is one jump (the same hand poses every run, whatever
# frame the X events land in) and a screenshot OUT/NAME.png is taken while the cloth is held up.
pinch_drag() {
  xdotool mousedown 1
  expect "the left button pinches the right hand" "v('pinch', 2) == 1"
  frames 20
  if [ $# -gt 0 ]; then
    xdotool mousemove 370 420
    frames 150
    screenshot "$1"
  else
    for step in $(seq 8); do
      xdotool mousemove $(( 410 - 5 * step )) $(( 500 - 10 * step ))
      frames 3
    done
    frames 30
  fi
  xdotool mouseup 1
  expect "the release opens the hand" "v('pinch', 2) == 0"
  frames 20
}

# session_check NAME PYTHON: runs the Python code with `session` (xr_session.txt's text), `log`
# (session_log.json parsed) and `triggers` (its trigger events: (name, phase) pairs) defined.
session_check() {
  python3 - "$OUT/out/xr_session.txt" "$OUT/out/session_log.json" "$2" <<'PY' || fail "$1"
import json, re, sys
session = open(sys.argv[1]).read()
log = json.load(open(sys.argv[2]))
triggers = [(e.get("name"), e.get("phase")) for e in log.get("events", []) if e.get("name")]
exec(sys.argv[3])
PY
  echo "ok: $1"
}

# hashes OUTCOME: the "state hash A -> B: OUTCOME..." lines of xr_session.txt as "A B" pairs.
hashes() { sed -n "s/^sim: state hash \([0-9a-f]*\) -> \([0-9a-f]*\): $1.*/\1 \2/p" "$OUT/out/xr_session.txt"; }

# to_profile WORD: Tab until the window's profile (its log) contains WORD (at most 7 presses).
to_profile() {
  for _ in $(seq 7); do
    [[ "$(field profile)" == *"$1"* ]] && { echo "ok: profile $(field profile)"; return 0; }
    xdotool key Tab
    frames 5
  done
  fail "no profile containing '$1' after 7 Tab presses (last: $(field profile))"
}

case "$MODE" in
  free)
    pinch_drag
    frames 4  # the last image drawn in the window
    screenshot
    ;;
  golden)
    frames 120
    screenshot live_start
    # A cut across the cloth at rest: in the oculus/touch profile (Tab) A (key 1) starts the
    # stroke beside the cloth's left edge, the hand crosses it 4 cm in front of the cloth (two
    # wheel notches nearer: it does not push the cloth; the stroke counts within 5 cm), A again
    # beside its right edge ends it.
    to_profile oculus
    CUT_Y=520 CUT_X0=320 CUT_X1=500
    xdotool mousemove $CUT_X0 $CUT_Y
    frames 10
    xdotool click 5 click 5
    frames 120
    xdotool key 1
    frames 5
    for x in $(seq $CUT_X0 10 $CUT_X1); do xdotool mousemove "$x" $CUT_Y; frames 2; done
    xdotool key 1
    frames 180  # the cut-off piece falls to the floor and comes to rest
    screenshot live_cut
    compare_golden live_cut
    xdotool key 2  # B: undo
    frames 4       # the restored cloth (at rest before the cut), before it moves again
    screenshot live_undo
    compare_golden live_undo
    # The tolerance tells the states apart: the cut and the undone cloth differ by far more.
    apart=$(image_change live_cut live_undo)
    echo "the cut and the undone cloth differ in $apart % of the blocks"
    python3 -c "import sys; sys.exit(0 if $apart > 12.0 else 1)" ||
      fail "the undo did not visibly restore the cloth (or the golden tolerance cannot tell)"
    # Press-drag-release (the controller's trigger: the left button) on the restored cloth.
    xdotool click 4 click 4
    xdotool mousemove 410 500
    frames 180
    pinch_drag live_pinch  # the screenshot while the hand holds the cloth up (lock step)
    moved=$(image_change live_undo live_pinch)
    echo "the pinch and drag changed $moved % of the blocks"
    python3 -c "import sys; sys.exit(0 if $moved > 20.0 else 1)" || fail "the drag did not move the cloth"
    compare_golden live_pinch
    ;;
  pin)
    expect "the window starts in hand tracking (the app enabled it, no scenario)" \
      "f('profile') == 'hand_tracking'"
    frames 240  # the hanging cloth at rest, so the frame Z lands in does not change the outcome
    # Z: the thumb-middle pinch, held like a gesture (a recogniser debounces a one-frame tap):
    # the right hand's pin takes the cloth under the hand.
    xdotool keydown z
    frames 20
    xdotool keyup z
    frames 240
    screenshot live_pin
    xdotool mousedown 1
    expect "the left button pinches the right hand" "v('pinch', 2) == 1"
    frames 10
    xdotool mouseup 1
    # P: the right hand points (held like a gesture): the pattern of the cloth as it is now,
    # written off the sim thread into out/pattern/session-1/ while the session goes on.
    frames 20
    xdotool keydown p
    expect "P makes the right hand point" "f('gesture') == 'open,point'"
    frames 20
    xdotool keyup p
    frames 60
    ;;
  save)
    frames 60
    to_profile oculus
    [ -e "$OUT/out/saved_session.drape" ] && fail "a saved session before F5"
    xdotool key F5
    expect "F5 holds the menu button" "f('buttons')[4] == '1'"
    frames 60
    expect "the menu button is held for its 100 frames, then let go" "f('buttons')[4] == '0'"
    for _ in $(seq 100); do [ -s "$OUT/out/saved_session.drape" ] && break; sleep 0.1; done
    [ -s "$OUT/out/saved_session.drape" ] || fail "no out/saved_session.drape after F5"
    ;;
esac

# --- Escape ends the session; the app writes its outputs and exits 0
xdotool key Escape
for _ in $(seq 600); do kill -0 $CLIENT_PID 2>/dev/null || break; sleep 0.1; done
kill -0 $CLIENT_PID 2>/dev/null && fail "drape run did not exit within 60 s of Escape"
wait $CLIENT_PID; rc=$?; CLIENT_PID=""
[ "$rc" -eq 0 ] || fail "drape run exited with $rc"
grep -q "closed or Escape: ending the session" "$OUT/stderr" || fail "the runtime did not log the quit"
grep -q "^drape run: exiting" "$OUT/stdout" || fail "the session did not end in EXITING"
grep -q "depth: D32_SFLOAT swapchain per eye\|depth: D16_UNORM swapchain per eye" "$OUT/stdout" ||
  fail "the app submitted no depth swapchains"
SESSION="$OUT/out/xr_session.txt"
[ -s "$SESSION" ] && [ -s "$OUT/out/session_log.json" ] || fail "no xr_session.txt / session_log.json"

case "$MODE" in
  free)
    # The pinch took a particle at the hand, the drag moved it.
    python3 - "$SESSION" "$LOG" <<'PY' || fail "pinch outcome"
import math, re, sys
text = open(sys.argv[1]).read()
took = re.findall(r"pinch: right hand took particle (\d+) at \(([-\d.]+), ([-\d.]+), ([-\d.]+)\)", text)
went = re.findall(r"pinch: right hand let particle (\d+) go at \(([-\d.]+), ([-\d.]+), ([-\d.]+)\) \(moved ([\d.]+) mm\)", text)
assert len(took) == 1, f"expected one pinch, got {took}"
assert len(went) == 1 and went[0][0] == took[0][0], f"the particle was not let go: {went}"
moved = float(went[0][4])
print(f"particle {took[0][0]} taken at {took[0][1:]}, let go at {went[0][1:4]}, moved {moved} mm")
assert moved > 30, "the drag did not move the cloth"
# The particle was taken at the hand, which sat at the cloth's depth: its distance from the
# eye matches the hand's (the pinched frame's head and right hand of the window log).
p = [float(c) for c in took[0][1:]]
for line in open(sys.argv[2]):
    d = dict(kv.split("=", 1) for kv in line.split() if "=" in kv)
    if d.get("pinch", "0,0").split(",")[1] == "1":
        head = [float(c) for c in d["head"].split(",")]
        hand = [float(c) for c in d["right"].split(",")]
        break
else:
    sys.exit("no pinched frame in the window log")
dp, dh = math.dist(head, p), math.dist(head, hand)
print(f"eye to particle {dp:.3f} m, eye to hand {dh:.3f} m")
assert abs(dp - dh) < 0.06, "the particle is not where the hand was"
assert dh > 0.7, "the hand was not at the cloth's depth"
m = re.search(r"pinched_frames (\d+)", text)
assert m and int(m.group(1)) > 10, "too few frames with the particle held"
PY
    echo "ok: the pinch took a cloth particle at the hand and the drag moved it"
    grep "fps (frame work p50" "$OUT/stdout"
    ;;
  golden)
    session_check "the session log holds the pinch, the cut stroke (A twice) and the undo" '
names = [n for n, _ in triggers]
print("triggers:", triggers)
assert names.count("pinch") >= 2, "no pinch begin and end"
assert names.count("cut") == 2, "the cut stroke was not started and ended"
assert names.count("undo") == 1, "no undo"
m = re.search(r"pinched_frames (\d+)", session)
assert m and int(m.group(1)) > 10, "too few frames with the particle held"
assert re.search(r"^cut: ok, components 1 -> 2$", session, re.M), "the cut did not split the cloth"'
    read -r cut_before cut_after <<<"$(hashes "cut: [0-9]* edges")"
    read -r undo_before undo_after <<<"$(hashes "undo: cut")"
    echo "state hashes: cut $cut_before -> $cut_after, undo $undo_before -> $undo_after"
    [ -n "$cut_before" ] && [ -n "$undo_after" ] || fail "no state hash lines for the cut and the undo"
    [ "$cut_before" != "$cut_after" ] || fail "the cut did not change the state"
    [ "$undo_after" = "$cut_before" ] || fail "the undo did not restore the state before the cut"
    echo "ok: the undo restored the state hash from before the cut"
    ;;
  pin)
    session_check "the session log holds a pin, and vertices were pinned" '
print("triggers:", triggers)
assert "pin" in [n for n, _ in triggers], "no pin trigger"
m = re.search(r"pinned_added (-?\d+)", session)
assert m and int(m.group(1)) >= 1, "no vertex pinned"'
    session_check "P asked for the pattern mid-session; it was written into session-1 only" '
assert re.search(r"gesture point begin hand right -> pattern once", session), "no point -> pattern"
m = re.search(r"^pattern: (\d+) piece\(s\), .* -> .*/pattern/session-1 \(tick (\d+)\)$", session, re.M)
assert m and int(m.group(1)) >= 1, "no mid-session pattern line"
print("mid-session pattern:", m.group(0))
import os
d = os.path.dirname(sys.argv[1]) + "/pattern/"
assert os.path.getsize(d + "session-1/report.json") > 0 and os.path.getsize(d + "session-1/pattern.dxf") > 0
assert not os.path.exists(d + "session-2"), "--no-pattern: no pattern at the end"'
    compare_golden live_pin
    ;;
  save)
    session_check "F5 held the menu: a save from the controller, and no tap (no stop)" '
assert not re.search(r"controller button\.menu begin", session), "the held menu also fired its tap"
m = re.search(r"frame (\d+): controller button\.menu_hold begin hand left -> save once", session)
assert m, "no menu held -> save"
assert re.search(r"^save: frame " + m.group(1) + r": saving the session$", session, re.M), "no save"'
    saved=$OUT/out/saved_session.drape
    tick=$(sed -n "s|^save: the session at tick \([0-9]*\) saved to $saved .*|\1|p" "$SESSION")
    [ -n "$tick" ] || fail "no save line naming $saved in $SESSION"
    # The saved file opens: `drape open` in the window starts from its tick and runs 20 frames.
    "$EXE" open "$saved" --out "$OUT/opened" --no-record --no-pattern --voice off --frames 20 \
      --sim-lock-step --eye-size 128 >"$OUT/open.out" 2>&1 ||
      fail "drape open $saved exited with $?: $(tail -3 "$OUT/open.out")"
    grep -qE "^drape open: $saved: the session at tick $tick( |$)" "$OUT/open.out" ||
      fail "drape open did not start from the saved tick $tick: $(grep open: "$OUT/open.out")"
    echo "ok: F5 saved the session at tick $tick; drape open started from it"
    ;;
esac
echo PASS
