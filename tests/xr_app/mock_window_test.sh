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
LOG="$OUT/window.log"
XVFB_PID="" CLIENT_PID=""
cleanup() {
  [ -n "$CLIENT_PID" ] && kill "$CLIENT_PID" 2>/dev/null
  [ -n "$XVFB_PID" ] && kill "$XVFB_PID" 2>/dev/null
  wait 2>/dev/null
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  echo "--- window log (tail)"; tail -3 "$LOG" 2>/dev/null
  echo "--- client stdout (tail)"; tail -15 "$OUT/stdout" 2>/dev/null
  echo "--- client stderr (tail)"; tail -15 "$OUT/stderr" 2>/dev/null
  exit 1
}
for tool in Xvfb xdotool xwd; do command -v $tool >/dev/null || fail "$tool is not installed (./drape setup)"; done

# A free display: Xvfb picks it and writes its number to fd 3.
Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp 3>"$OUT/display" 2>"$OUT/xvfb.log" &
XVFB_PID=$!
for _ in $(seq 100); do [ -s "$OUT/display" ] && break; sleep 0.1; done
[ -s "$OUT/display" ] || fail "Xvfb did not start"
export DISPLAY=":$(head -1 "$OUT/display")"
echo "Xvfb on $DISPLAY"

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

lines() { [ -f "$LOG" ] && wc -l <"$LOG" || echo 0; }
# Waits until the runtime has logged N more frames (the input of the action is then taken).
frames() {
  local want=$(( $(lines) + $1 ))
  for _ in $(seq 600); do [ "$(lines)" -ge "$want" ] && return 0; sleep 0.05; done
  fail "the runtime logged no frames for 30 s"
}
# field NAME [INDEX]: the value of NAME= in the last log line (INDEX: 1-based part of x,y,z).
field() {
  local v
  v=$(tail -1 "$LOG" | tr ' ' '\n' | sed -n "s/^$1=//p")
  if [ $# -ge 2 ]; then echo "$v" | cut -d, -f"$2"; else echo "$v"; fi
}
check() {  # check "description" python-expression
  python3 -c "import sys; sys.exit(0 if ($2) else 1)" || fail "$1 ($2)"
  echo "ok: $1"
}

for _ in $(seq 600); do [ "$(lines)" -ge 5 ] && break; kill -0 $CLIENT_PID 2>/dev/null || break; sleep 0.05; done
[ "$(lines)" -ge 5 ] || fail "no window frames logged (did the window open?)"
WID=$(xdotool search --name "drape mock runtime" | head -1)
[ -n "$WID" ] || fail "no window named 'drape mock runtime'"
xdotool getwindowgeometry "$WID" | tee "$OUT/geometry" | grep -q "Geometry: 800x600" || fail "window geometry"

# --- the right hand follows the cursor
xdotool mousemove 150 300; frames 4
x1=$(field right 1); y1=$(field right 2)
xdotool mousemove 650 300; frames 4
x2=$(field right 1)
check "right hand follows the cursor to the right ($x1 -> $x2)" "$x2 - $x1 > 0.3"
xdotool mousemove 400 120; frames 4
ya=$(field right 2)
xdotool mousemove 400 480; frames 4
yb=$(field right 2)
check "right hand follows the cursor down ($ya -> $yb)" "$ya - $yb > 0.2"
check "the cursor is over the view" "'$(field cursor)' == 'in'"

# --- head: W moves forward (-z), R resets, right-drag looks
z0=$(field head 3)
xdotool keydown w; sleep 0.5; xdotool keyup w; frames 4
z1=$(field head 3)
check "W moves the head forward ($z0 -> $z1)" "$z0 - $z1 > 0.1"
xdotool key r; frames 4
check "R resets the head" "abs($(field head 3) - $z0) < 1e-3"
xdotool mousedown 3; xdotool mousemove_relative -- 150 0; frames 3; xdotool mouseup 3; frames 4
yaw=$(field yaw)
check "right-drag to the right turns the head right (yaw $yaw)" "$yaw < -0.3"
xdotool key r; frames 4
check "R resets the look" "abs($(field yaw)) < 1e-6"

# --- pinch on the left button, fist on F
xdotool mousemove 400 300; frames 3
check "no pinch before the button" "'$(field pinch)' == '0,0'"
xdotool mousedown 1; frames 4
check "left button pinches the right hand" "'$(field pinch)' == '0,1'"
[ "$MODE" = depth ] && cp "$OUT/stdout" "$OUT/stdout_pinched"
xdotool mouseup 1; frames 4
check "releasing the button opens the pinch" "'$(field pinch)' == '0,0'"
n=$(lines); xdotool click 1; frames 4
tail -n +$((n + 1)) "$LOG" | grep -q " pinch=0,1 " || fail "a quick click pinches for at least one frame"
check "a quick click pinches, then opens" "'$(field pinch)' == '0,0'"
xdotool keydown f; frames 4
check "F makes a fist" "'$(field fist)' == '0,1'"
xdotool keyup f; frames 4
check "releasing F opens the fist" "'$(field fist)' == '0,0'"

# --- the left hand with Shift; the right hand stays
rx=$(field right 1); lx0=$(field left 1)
xdotool keydown shift; xdotool mousemove 200 300; frames 4
check "Shift makes the left hand the active one" "'$(field active)' == 'left'"
lx1=$(field left 1)
check "the left hand follows the cursor ($lx0 -> $lx1)" "abs($lx1 - $lx0) > 0.05"
check "the right hand stays" "abs($(field right 1) - $rx) < 1e-4"
xdotool keyup shift; frames 3

# --- wheel: the hand farther (up) and nearer (down)
xdotool mousemove 400 300; frames 3
xdotool click --repeat 3 --delay 30 4; frames 4
check "wheel up moves the right hand 3 notches farther" "abs($(field wheel 2) - 0.06) < 1e-6"
xdotool click --repeat 3 --delay 30 5; frames 4
check "wheel down brings it back" "abs($(field wheel 2)) < 1e-6"

# --- Tab switches the interaction profile
p0=$(field profile)
xdotool key Tab; frames 4
p1=$(field profile)
check "Tab switches the profile ($p0 -> $p1)" "'$p0' != '$p1'"

# --- V: both eyes side by side
xdotool key v; frames 4
check "V shows both eyes" "'$(field view)' == 'both'"
xdotool key v; frames 4

if [ "$MODE" = depth ]; then
  # The client draws a plane at 0.8 m over the left half of each eye image, nothing on the
  # right half; the runtime reads the depth under the cursor.
  xdotool mousemove 250 300; frames 6
  d=$(field depth)
  check "depth under the cursor is the submitted plane ($d)" "'$d' != '-' and abs(float('$d') - 0.8) < 0.01"
  # The hand sits on the plane: at view depth 0.8 m (head z 1.0, looking down -z).
  check "the right hand sits on the surface (z $(field right 3))" "abs($(field right 3) - (1.0 - 0.8)) < 0.02"
  xdotool mousemove 600 300; frames 6
  check "nothing drawn under the cursor: no depth hit" "'$(field depth)' == '-'"
  check "over nothing the hand keeps the last surface depth" "abs($(field right 3) - 0.2) < 0.02"
fi

# --- a screenshot of the window: the submitted image is shown
xwd -root -silent >"$OUT/screen.xwd" || fail "xwd"
python3 - "$OUT/screen.xwd" "$OUT/window.png" <<'PY' || fail "screenshot check"
import struct, sys, zlib
d = open(sys.argv[1], "rb").read()
f = struct.unpack(">25I", d[:100])
hsize, fmt, depth, w, h, byte_order, bpp, bpl, ncolors = f[0], f[2], f[3], f[4], f[5], f[7], f[11], f[12], f[19]
assert fmt == 2 and bpp in (24, 32), (fmt, bpp)
px, n = d[hsize + 12 * ncolors:], bpp // 8
order = "little" if byte_order == 0 else "big"
rows = []
for y in range(600):  # the window: 800x600 at (0, 0)
    row = bytearray()
    for x in range(800):
        v = int.from_bytes(px[y * bpl + n * x:y * bpl + n * x + n], order)
        row += bytes(((v >> 16) & 255, (v >> 8) & 255, v & 255))
    rows.append(bytes(row))
raw = b"".join(b"\0" + r for r in rows)
def chunk(t, b): return struct.pack(">I", len(b)) + t + b + struct.pack(">I", zlib.crc32(t + b))
open(sys.argv[2], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 800, 600, 8, 2, 0, 0, 0))
                              + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
view = {rows[y][3 * x:3 * x + 3] for y in range(0, 600, 4) for x in range(100, 700, 4)}
bars = {rows[y][3 * x:3 * x + 3] for y in range(0, 600, 4) for x in list(range(0, 96, 4)) + list(range(704, 800, 4))}
print(f"screenshot: {len(view)} distinct colours in the view, {len(bars)} in the side bars")
assert len(view) >= 3, "the view is blank: the submitted image is not shown"
assert len(bars) == 1, "the letterbox bars are not plain"
PY
echo "ok: screenshot $OUT/window.png shows the submitted image"

# --- Escape ends the session the way a headset's quit does: STOPPING, IDLE, EXITING
xdotool key Escape
for _ in $(seq 300); do kill -0 $CLIENT_PID 2>/dev/null || break; sleep 0.1; done
kill -0 $CLIENT_PID 2>/dev/null && fail "the client did not exit within 30 s of Escape"
wait $CLIENT_PID; rc=$?; CLIENT_PID=""
[ "$rc" -eq 0 ] || fail "the client exited with $rc"
grep -q "closed or Escape: ending the session" "$OUT/stderr" || fail "the runtime did not log the quit"
if [ "$MODE" = hello ]; then
  grep -q "XR_SESSION_STATE_STOPPING->XR_SESSION_STATE_IDLE" "$OUT/stdout" || fail "no STOPPING->IDLE"
  grep -q "XR_SESSION_STATE_IDLE->XR_SESSION_STATE_EXITING" "$OUT/stdout" || fail "no IDLE->EXITING"
  grep -q "XR_ERROR" "$OUT/stdout" "$OUT/stderr" && fail "an XR_ERROR result was logged"
else
  grep -q "^state EXITING" "$OUT/stdout" || fail "the client saw no EXITING"
  # What the app sees: hand joints with thumb and index tips together while pinched, the
  # select action pressed, the profile change event.
  grep -q "pinch_gap=0.005" "$OUT/stdout_pinched" || fail "the client never saw the thumb and index tips together"
  grep -q "select=1" "$OUT/stdout_pinched" || fail "the client never saw select pressed"
  grep -q "^profile changed" "$OUT/stdout" || fail "the client saw no interaction profile change"
  echo "ok: the client saw the pinch as hand joints and as select, and the profile change"
fi
echo "ok: Escape ended the session, exit 0"
echo PASS
