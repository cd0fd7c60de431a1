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

# screenshot [NAME]: the 800x600 window at (0, 0) as OUT/NAME.png (default: window; from xwd,
# no other tool); fails when the view (x 100..700) is blank or the letterbox bars beside it are
# not plain.
screenshot() {
  local name="${1:-window}"
  xwd -root -silent >"$OUT/screen.xwd" || fail "xwd"
  python3 - "$OUT/screen.xwd" "$OUT/$name.png" <<'PY' || fail "screenshot check"
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
  echo "ok: screenshot $OUT/$name.png shows the submitted image"
}

# REGION: the part of the 800x600 window the image checks look at, "X0 Y0 X1 Y1" (default: the
# view, x 100..700); a caller narrows it to where the action is.
REGION="${REGION:-100 0 700 600}"
# compare_golden NAME: OUT/NAME.png against GOLDEN/NAME.png (GOLDEN: the caller's folder of
# golden images) over REGION, both averaged over 4x4 blocks: a block differs when a channel is
# off by more than 24/255; at most 3 % of the blocks may differ and the RMS over all blocks must
# be below 8/255 (a live session's input lands in frames a little apart from run to run: the held
# or cut cloth ends a few pixels apart). Prints the measured difference; writes OUT/NAME_diff.png (the difference, x4)
# on failure. With UPDATE_GOLDEN=1 the screenshot becomes the golden image instead (look at it
# before committing it).
compare_golden() {
  local name="$1"
  if [ "${UPDATE_GOLDEN:-0}" = 1 ]; then
    cp "$OUT/$name.png" "$GOLDEN/$name.png" || fail "cannot write $GOLDEN/$name.png"
    echo "updated: $GOLDEN/$name.png"
    return 0
  fi
  [ -f "$GOLDEN/$name.png" ] || fail "no golden image $GOLDEN/$name.png (make it with --update-golden)"
  python3 - "$OUT/$name.png" "$GOLDEN/$name.png" "$OUT/${name}_diff.png" "$name" $REGION <<'PY' ||
import math, struct, sys, zlib
def read_png(path):
    d = open(path, "rb").read()
    assert d[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    pos, idat, w = 8, b"", 0
    while pos < len(d):
        n, t = struct.unpack(">I4s", d[pos:pos + 8])
        body = d[pos + 8:pos + 8 + n]
        if t == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and ctype == 2, f"{path}: not 8-bit RGB"
        elif t == b"IDAT":
            idat += body
        pos += 12 + n
    raw, stride, rows, prev = zlib.decompress(idat), 3 * w, [], bytearray(3 * w)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            b, c = prev[i], prev[i - 3] if i >= 3 else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return w, h, rows
def blocks(rows, x0, y0, x1, y1):
    return [[tuple(sum(rows[by + k][3 * (bx + i) + c] for k in range(4) for i in range(4)) / 16
                   for c in range(3)) for bx in range(x0, x1 - 3, 4)] for by in range(y0, y1 - 3, 4)]
shot, gold, diff_path, name = sys.argv[1:5]
x0, y0, x1, y1 = (int(v) for v in sys.argv[5:9])
(w1, h1, a), (w2, h2, b) = read_png(shot), read_png(gold)
assert (w1, h1) == (w2, h2) == (800, 600), f"sizes {w1}x{h1} and {w2}x{h2}, expected 800x600"
A, B = blocks(a, x0, y0, x1, y1), blocks(b, x0, y0, x1, y1)
off, sq, n = 0, 0.0, len(A) * len(A[0])
for ra, rb in zip(A, B):
    for pa, pb in zip(ra, rb):
        d = [abs(pa[c] - pb[c]) for c in range(3)]
        off += max(d) > 24
        sq += sum(v * v for v in d) / 3
frac, rms = off / n, math.sqrt(sq / n)
print(f"{name}: {100 * frac:.2f} % of the {n} 4x4 blocks of x {x0}..{x1}, y {y0}..{y1} differ by > 24/255 (max 3 %), RMS {rms:.2f}/255 (max 8)")
if frac <= 0.03 and rms < 8:
    sys.exit(0)
raw = b"".join(b"\0" + bytes(min(255, 4 * abs(a[y][i] - b[y][i])) for i in range(2400)) for y in range(600))
def chunk(t, body): return struct.pack(">I", len(body)) + t + body + struct.pack(">I", zlib.crc32(t + body))
open(diff_path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 800, 600, 8, 2, 0, 0, 0))
                          + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
print(f"the difference (x4): {diff_path}")
sys.exit(1)
PY
    fail "$name.png does not match its golden image"
  echo "ok: $name.png matches $GOLDEN/$name.png"
}

# image_change A B: the fraction of REGION's 4x4 blocks (as compare_golden) that differ by more
# than 24/255 between OUT/A.png and OUT/B.png, printed as a percentage.
image_change() {
  python3 - "$OUT/$1.png" "$OUT/$2.png" $REGION <<'PY' || fail "image_change $1 $2"
import struct, sys, zlib
x0, y0, x1, y1 = (int(v) for v in sys.argv[3:7])
def view(path):
    d = open(path, "rb").read()
    pos, idat = 8, b""
    while pos < len(d):
        n, t = struct.unpack(">I4s", d[pos:pos + 8])
        if t == b"IDAT": idat += d[pos + 8:pos + 8 + n]
        pos += 12 + n
    raw = zlib.decompress(idat)  # written by screenshot(): filter 0 on every row
    rows = [raw[y * 2401 + 1:(y + 1) * 2401] for y in range(600)]
    return [[tuple(sum(rows[by + k][3 * (bx + i) + c] for k in range(4) for i in range(4)) / 16
                   for c in range(3)) for bx in range(x0, x1 - 3, 4)] for by in range(y0, y1 - 3, 4)]
A, B = view(sys.argv[1]), view(sys.argv[2])
n = len(A) * len(A[0])
off = sum(max(abs(pa[c] - pb[c]) for c in range(3)) > 24 for ra, rb in zip(A, B) for pa, pb in zip(ra, rb))
print(f"{100 * off / n:.2f}")
PY
}
