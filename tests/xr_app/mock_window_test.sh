#!/usr/bin/env bash
# Window mode of the mock runtime (DRAPE_MOCK_WINDOW=1) driven like a person would: a real X
# server (Xvfb), real X input events (xdotool, through XTEST), a real OpenXR client.
#   mock_window_test.sh MANIFEST OUTDIR hello HELLO_XR    Khronos hello_xr (no depth submitted)
#   mock_window_test.sh MANIFEST OUTDIR depth CLIENT      mock_window_client (submits depth and
#                                                         reads hand joints and actions back)
# The runtime writes one line per frame to DRAPE_MOCK_WINDOW_LOG (head, hands, pinch, fist,
# wheel, depth under the cursor, profile); the checks read it. The window is 800x600 at (0, 0)
# (no window manager) and shows one 1024x1024 eye scaled to 600x600 at x 100..700.
set -uo pipefail
MANIFEST="$1" OUT="$2" MODE="$3" CLIENT="$4"
rm -rf "$OUT" && mkdir -p "$OUT"
source "$(dirname "$0")/window_test_lib.sh"
start_xvfb

export XR_RUNTIME_JSON="$MANIFEST" DRAPE_MOCK_WINDOW=1 DRAPE_MOCK_WINDOW_SIZE=800x600 \
  DRAPE_MOCK_WINDOW_LOG="$LOG"
unset DRAPE_MOCK_SCENARIO DRAPE_MOCK_WRITE_FRAMES XR_ENABLE_API_LAYERS DRAPE_MOCK_END_AFTER_FRAMES
if [ "$MODE" = hello ]; then
  # hello_xr quits on a key on stdin: hold stdin open.
  bash -c "exec '$CLIENT' -g Vulkan2 < <(sleep 300)" >"$OUT/stdout" 2>"$OUT/stderr" &
else
  "$CLIENT" >"$OUT/stdout" 2>"$OUT/stderr" &
fi
CLIENT_PID=$!


for _ in $(seq 600); do [ "$(lines)" -ge 5 ] && break; kill -0 $CLIENT_PID 2>/dev/null || break; sleep 0.05; done
[ "$(lines)" -ge 5 ] || fail "no window frames logged (did the window open?)"
WID=$(xdotool search --name "drape mock runtime" | head -1)
[ -n "$WID" ] || fail "no window named 'drape mock runtime'"
xdotool getwindowgeometry "$WID" | tee "$OUT/geometry" | grep -q "Geometry: 800x600" || fail "window geometry"

# client_expect "description" EXPR: polls the client's last line of hand joints (up to 20 s)
# until EXPR holds; f(NAME) is a field as text, v(NAME, I) the I-th number of it.
client_expect() {
  python3 - "$OUT/stdout" "$2" <<'PY' || fail "$1 ($2)"
import sys, time
out, expr = sys.argv[1], sys.argv[2]
deadline = time.time() + 20
while True:
    rows = [l for l in open(out).read().splitlines() if " gaps=" in l]
    if rows:
        kv = dict(p.split("=", 1) for p in rows[-1].split() if "=" in p)
        f = lambda k: kv.get(k, "")
        v = lambda k, i=1: float(kv[k].split(",")[i - 1])
        if eval(expr):
            break
    if time.time() > deadline:
        print("last client line:", rows[-1] if rows else "(none)")
        sys.exit(1)
    time.sleep(0.05)
PY
  echo "ok: $1"
}

if [ "$MODE" = depth ]; then
  # --- the client enables XR_EXT_hand_tracking and no scenario names a profile: the window
  # starts with the hands alone, and Z X C G U T P make the gestures of the hand under the mouse:
  # the thumb tip 5 mm from the middle, ring, little tip; the fingers together palm down; the
  # palm up; the open palm facing forward, thrust 20 cm forward; pointing (the middle, ring and
  # little fingers curled: the thumb far from their tips, the index's gap open).
  expect "the window starts in hand tracking" "f('profile') == 'hand_tracking'"
  xdotool mousemove 400 300
  client_expect "the client reads the open hand" "v('gaps', 1) > 0.02 and v('spread') > 0.065 and v('palm_normal', 2) < -0.9"
  pz=$(tail -1 "$OUT/stdout" | tr ' ' '\n' | sed -n 's/^palm=//p' | cut -d, -f3)
  for k in z x c g u t p; do
    case $k in
      z) want=pinch_middle; reads="v('gaps', 1) < 0.007 and v('gaps', 2) > 0.015 and v('pinch_gap') > 0.02" ;;
      x) want=pinch_ring; reads="v('gaps', 2) < 0.007 and v('gaps', 1) > 0.015 and v('gaps', 3) > 0.015" ;;
      c) want=pinch_little; reads="v('gaps', 3) < 0.007 and v('gaps', 2) > 0.015" ;;
      g) want=flat; reads="v('spread') < 0.055 and v('palm_normal', 2) < -0.9" ;;
      u) want=palm_up; reads="v('palm_normal', 2) > 0.9 and v('spread') > 0.065" ;;
      t) want=push; reads="v('palm_normal', 3) < -0.9 and v('palm', 3) < $pz - 0.15" ;;
      p) want=point; reads="v('pinch_gap') > 0.02 and v('palm_normal', 2) < -0.9" ;;
    esac
    xdotool keydown $k
    expect "key $k makes the right hand's $want" "f('gesture') == 'open,$want'"
    client_expect "the client reads the $want from the joints" "$reads"
    xdotool keyup $k
    expect "releasing $k opens the hand" "f('gesture') == 'open,open'"
  done
  client_expect "the client reads the open hand again" "v('gaps', 1) > 0.02 and v('spread') > 0.065 and v('palm_normal', 2) < -0.9"
  xdotool key Tab
  expect "Tab: from hand tracking to the first profile" "f('profile').endswith('khr/simple_controller')"
fi

# --- the right hand follows the cursor
xdotool mousemove 150 300
expect "the cursor is over the view, on the left" "f('cursor') == 'in' and v('right', 1) < -0.3"
x1=$(field right 1)
xdotool mousemove 650 300
expect "the right hand follows the cursor to the right" "v('right', 1) - $x1 > 0.5"
xdotool mousemove 400 120
expect "the right hand follows the cursor up" "v('right', 2) > 1.8"
ya=$(field right 2)
xdotool mousemove 400 480
expect "the right hand follows the cursor down" "$ya - v('right', 2) > 0.4"

# --- head: W moves forward (-z), R resets, right-drag looks
z0=$(field head 3)
xdotool keydown w; sleep 0.5; xdotool keyup w
expect "W moves the head forward" "$z0 - v('head', 3) > 0.1"
frames 3; z1=$(field head 3)
frames 5
expect "releasing W stops the head" "v('head', 3) == $z1"
y0=$(field head 2)
xdotool keydown e; sleep 0.3; xdotool keyup e
expect "E moves the head up" "v('head', 2) - $y0 > 0.05"
xdotool key r
expect "R resets the head" "abs(v('head', 3) - $z0) < 1e-3 and abs(v('head', 2) - $y0) < 1e-3"
xdotool mousedown 3; xdotool mousemove_relative -- 150 0; xdotool mouseup 3
expect "right-drag to the right turns the head right" "abs(v('yaw') + 150 * 0.004) < 1e-3"
xdotool key r
expect "R resets the look" "v('yaw') == 0 and v('pitch') == 0"

# --- pinch on the left button (held, or a quick click), fist on F
xdotool mousemove 400 300
expect "no pinch before the button" "f('pinch') == '0,0'"
xdotool mousedown 1
expect "left button pinches the right hand" "f('pinch') == '0,1'"
xdotool search --name "drape mock runtime" getwindowname | grep -q "right hand pinch" ||
  fail "the window title does not show the pinch: $(xdotool search --name 'drape mock runtime' getwindowname)"
echo "ok: the window title shows it"
frames 3
[ "$MODE" = depth ] && cp "$OUT/stdout" "$OUT/stdout_pinched"
xdotool mouseup 1
expect "releasing the button opens the pinch" "f('pinch') == '0,0'"
n=$(lines); xdotool click 1
expect "a quick click pinches for a frame, then opens" "f('pinch') == '0,0' and any(' pinch=0,1 ' in l for l in open('$LOG').read().splitlines()[$n:])"
xdotool keydown f
expect "F makes a fist" "f('fist') == '0,1'"
xdotool keyup f
expect "releasing F opens the fist" "f('fist') == '0,0'"

# --- the controllers' buttons: 1 2 3 4 M = A B X Y menu (hello_xr quits on menu: its M is
# the last step)
keys="1 2 3 4"
[ "$MODE" = depth ] && keys="1 2 3 4 m"
for k in $keys; do
  xdotool keydown $k
  want=$(case $k in 1) echo 10000;; 2) echo 01000;; 3) echo 00100;; 4) echo 00010;; m) echo 00001;; esac)
  expect "key $k presses button $want" "f('buttons') == '$want'"
  xdotool keyup $k
done
expect "buttons released" "f('buttons') == '00000'"

# --- the left hand with Shift; the right hand stays
rx=$(field right 1); lx0=$(field left 1)
xdotool keydown shift; xdotool mousemove 200 300
expect "Shift makes the left hand follow the cursor" "f('active') == 'left' and abs(v('left', 1) - $lx0) > 0.05"
expect "the right hand stays" "v('right', 1) == $rx"
xdotool keyup shift
expect "without Shift the right hand is active again" "f('active') == 'right'"

# --- wheel: the hand farther (up) and nearer (down)
xdotool mousemove 400 300
xdotool click --repeat 3 --delay 30 4
expect "wheel up: the right hand 3 notches (6 cm) farther" "abs(v('wheel', 2) - 0.06) < 1e-6"
xdotool click --repeat 3 --delay 30 5
expect "wheel down brings it back" "abs(v('wheel', 2)) < 1e-6"

# --- Tab switches the interaction profile
p0=$(field profile)
xdotool key Tab
expect "Tab switches the profile (from $p0)" "f('profile') != '$p0'"
echo "   profile now $(field profile)"

if [ "$MODE" = depth ]; then
  # --- the arrows and Enter: the thumbstick and its click of the hand under the mouse (the
  # client binds the right Touch controller's)
  expect "the profile is oculus/touch_controller" "f('profile').endswith('oculus/touch_controller')"
  for k in Up Down Left Right; do
    case $k in Up) xy="0,1";; Down) xy="0,-1";; Left) xy="-1,0";; Right) xy="1,0";; esac
    xdotool keydown $k
    expect "$k pushes the stick $xy" "f('stick') == '$xy,0'"
    client_expect "the client reads the thumbstick at $xy" "(v('stick', 1), v('stick', 2)) == tuple(float(c) for c in '$xy'.split(','))"
    xdotool keyup $k
    expect "releasing $k centres the stick" "f('stick') == '0,0,0'"
  done
  xdotool keydown Return
  expect "Enter clicks the stick" "f('stick') == '0,0,1'"
  client_expect "the client reads the thumbstick click" "v('stick', 3) == 1"
  xdotool keyup Return
  client_expect "the click is let go" "v('stick', 3) == 0"
fi

# --- V: both eyes side by side
xdotool key v
expect "V shows both eyes" "f('view') == 'both'"
xdotool key v
expect "V again: the left eye" "f('view') == 'left'"

if [ "$MODE" = depth ]; then
  # The client draws a plane at 0.8 m over the left half of each eye and the hand's joints
  # (with depth); hits on the joints are not the surface.
  xdotool mousemove 250 300
  expect "the hand's depth is the submitted plane's" "abs(v('z') - 0.8) < 0.005"
  # The hand sits on the plane: at view depth 0.8 m (head z 1.0, looking down -z).
  expect "the right hand sits on the surface" "abs(v('right', 3) - (1.0 - 0.8)) < 0.01"
  frames 10
  expect "and stays there (the drawn hand does not pull it)" "abs(v('right', 3) - 0.2) < 0.01"
  xdotool mousemove 600 300
  expect "over nothing but the drawn hand: no surface hit" "f('depth') == '-' or f('depth').endswith('(hand)')"
  frames 10
  expect "over nothing the hand keeps the last surface depth" "abs(v('right', 3) - 0.2) < 0.01 and abs(v('right', 1)) > 0.1"
  xdotool click --repeat 5 --delay 30 5
  expect "the wheel brings the hand 10 cm nearer than the surface" "abs(v('right', 3) - 0.3) < 0.01"
  xdotool mousemove 250 300
  frames 10
  expect "and it hovers 10 cm in front of the plane" "abs(v('right', 3) - 0.3) < 0.01 and abs(v('z') - 0.8) < 0.005"
  xdotool key r
  expect "R resets the wheel" "v('wheel', 2) == 0"
fi

frames 6  # the last image drawn in the window
# --- a screenshot of the window: the submitted image is shown
screenshot

# --- Escape ends the session the way a headset's quit does: STOPPING, IDLE, EXITING. hello_xr
# binds its quit action to the menu button: there M ends it through the action path.
if [ "$MODE" = hello ]; then
  xdotool keydown m; sleep 0.3; xdotool keyup m
else
  xdotool key Escape
fi
for _ in $(seq 300); do kill -0 $CLIENT_PID 2>/dev/null || break; sleep 0.1; done
kill -0 $CLIENT_PID 2>/dev/null && fail "the client did not exit within 30 s"
wait $CLIENT_PID; rc=$?; CLIENT_PID=""
[ "$rc" -eq 0 ] || fail "the client exited with $rc"
if [ "$MODE" = hello ]; then
  grep -q "closed or Escape" "$OUT/stderr" && fail "the session ended by Escape, not by the menu button"
  grep -q "buttons=00001" "$LOG" || fail "M did not press the menu button"
  echo "ok: M (menu) made hello_xr request the exit"
  grep -q "XR_SESSION_STATE_STOPPING->XR_SESSION_STATE_IDLE" "$OUT/stdout" || fail "no STOPPING->IDLE"
  grep -q "XR_SESSION_STATE_IDLE->XR_SESSION_STATE_EXITING" "$OUT/stdout" || fail "no IDLE->EXITING"
  grep -q "XR_ERROR" "$OUT/stdout" "$OUT/stderr" && fail "an XR_ERROR result was logged"
else
  grep -q "closed or Escape: ending the session" "$OUT/stderr" || fail "the runtime did not log the quit"
  grep -q "^state EXITING" "$OUT/stdout" || fail "the client saw no EXITING"
  # What the app sees: hand joints with thumb and index tips together while pinched, the
  # select action pressed, the profile change event.
  grep -q "pinch_gap=0.005" "$OUT/stdout_pinched" || fail "the client never saw the thumb and index tips together"
  grep -q "select=1" "$OUT/stdout_pinched" || fail "the client never saw select pressed"
  grep -q "^profile changed: /interaction_profiles/khr/simple_controller" "$OUT/stdout" ||
    fail "the client never saw khr/simple_controller"
  grep -q "^profile changed: none" "$OUT/stdout" || fail "the client never saw the change to hand tracking alone"
  awk '/^state/ && seen { exit } /pinch_gap/ { seen = 1 } seen && /hand not tracked/ { bad = 1 }
       END { exit bad }' "$OUT/stdout" || fail "the client saw the hand untracked while focused"
  echo "ok: the client saw the pinch as hand joints and as select, and the profile change"
fi
echo "ok: the session ended (STOPPING, IDLE, EXITING), exit 0"
echo PASS
