# Shared by the tests that drive the simulated runtime's window under Xvfb
# (mock_window_test.sh, drape_live_test.sh). The sourcing script sets OUT (its output folder,
# made empty) first; the runtime's DRAPE_MOCK_WINDOW_LOG is LOG, the client's output
# OUT/stdout and OUT/stderr, its process CLIENT_PID.

# After OUT is set: the runtime's log, the clean-up of Xvfb and the client (CLIENT_PID) on exit,
# fail() that shows the tails of the logs, and the tools the tests need.
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
for tool in Xvfb xdotool xwd python3; do
  command -v $tool >/dev/null || fail "$tool is not installed (./drape setup)"
done

# start_xvfb: a free display (Xvfb picks it and writes its number to fd 3); sets XVFB_PID and
# DISPLAY.
start_xvfb() {
  Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp 3>"$OUT/display" 2>"$OUT/xvfb.log" &
  XVFB_PID=$!
  for _ in $(seq 100); do [ -s "$OUT/display" ] && break; sleep 0.1; done
  [ -s "$OUT/display" ] || fail "Xvfb did not start"
  export DISPLAY=":$(head -1 "$OUT/display")"
  unset WAYLAND_DISPLAY
  echo "Xvfb on $DISPLAY"
}

lines() { [ -f "$LOG" ] && wc -l <"$LOG" || echo 0; }
# frames N: waits until the runtime has logged N more frames (the input of the action is then
# taken).
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
# expect "description" EXPR: polls the last log line (up to 20 s) until the Python expression
# EXPR holds; in it f(NAME) is a field as text and v(NAME, I) the I-th (1-based) number of it.
expect() {
  python3 - "$LOG" "$2" <<'PY' || fail "$1 ($2)"
import sys, time
log, expr = sys.argv[1], sys.argv[2]
deadline = time.time() + 20
while True:
    with open(log) as fh:
        lines = fh.read().splitlines()
    d = dict(kv.split("=", 1) for kv in lines[-1].split() if "=" in kv) if lines else {}
    f = lambda name: d[name]
    v = lambda name, i=1: float(d[name].split(",")[i - 1])
    try:
        if eval(expr):
            sys.exit(0)
    except (KeyError, ValueError, IndexError):
        pass
    if time.time() > deadline:
        print("last line:", lines[-1] if lines else "(none)")
        sys.exit(1)
    time.sleep(0.02)
PY
  echo "ok: $1"
}

# screenshot: the 800x600 window at (0, 0) as OUT/window.png (from xwd, no other tool); fails
# when the view (x 100..700) is blank or the letterbox bars beside it are not plain.
screenshot() {
  xwd -root -silent >"$OUT/screen.xwd" || fail "xwd"
  python3 - "$OUT/screen.xwd" "$OUT/window.png" <<'PY' || fail "screenshot check"
import struct, sys, zlib
d = open(sys.argv[1], "rb").read()
f = struct.unpack(">25I", d[:100])
hsize, fmt, byte_order, bpp, bpl, ncolors = f[0], f[2], f[7], f[11], f[12], f[19]
assert fmt == 2 and bpp in (24, 32), (fmt, bpp)
px, n = d[hsize + 12 * ncolors:], bpp // 8
order = "little" if byte_order == 0 else "big"
rows = []
for y in range(600):
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
}
