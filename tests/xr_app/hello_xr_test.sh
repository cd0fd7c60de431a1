#!/usr/bin/env bash
# Runs the Khronos hello_xr (Debian libopenxr-utils) against the mock runtime and checks it.
#   hello_xr_test.sh HELLO_XR MANIFEST FRAMES MODE OUTDIR
# MODE: plain       fast pacing, N frames, exit 0, the runtime reports exactly N frames composed
#       validation  the same under XR_APILAYER_LUNARG_core_validation: zero validation messages
#       paced_png   real 90 Hz pacing (wall time >= N/90 s) and every 15th frame written to PNG
# hello_xr quits on a key press on stdin (with stdin at /dev/null it exits at once without
# rendering), so stdin is held open by a process substitution.
set -uo pipefail
HELLO="$1" MANIFEST="$2" FRAMES="$3" MODE="$4" OUT="$5"
rm -rf "$OUT" && mkdir -p "$OUT"
export XR_RUNTIME_JSON="$MANIFEST"
export DRAPE_MOCK_END_AFTER_FRAMES="$FRAMES"
unset DRAPE_MOCK_SCENARIO DRAPE_MOCK_WRITE_FRAMES XR_ENABLE_API_LAYERS
export DRAPE_MOCK_FAST=1
case "$MODE" in
  validation) export XR_ENABLE_API_LAYERS=XR_APILAYER_LUNARG_core_validation ;;
  paced_png) export DRAPE_MOCK_FAST=0 DRAPE_MOCK_WRITE_FRAMES="$OUT/frames" DRAPE_MOCK_WRITE_EVERY=15 ;;
esac
fail() { echo "FAIL: $*"; echo "--- stdout (tail)"; tail -20 "$OUT/stdout"; echo "--- stderr (tail)"; tail -20 "$OUT/stderr"; exit 1; }

start=$(date +%s.%N)
timeout 90 bash -c "'$HELLO' -g Vulkan2 < <(sleep 120)" >"$OUT/stdout" 2>"$OUT/stderr"
rc=$?
end=$(date +%s.%N)
elapsed=$(echo "$end - $start" | bc)
[ "$rc" -eq 0 ] || fail "hello_xr exited with $rc"
composed=$(grep -oP '^frames composed: \K[0-9]+' "$OUT/stderr" | tail -1)
[ -n "$composed" ] || fail "the runtime did not report 'frames composed'"
echo "hello_xr exit 0, frames composed: $composed (expected $FRAMES), wall time ${elapsed}s"
[ "$composed" -eq "$FRAMES" ] || fail "frames composed $composed != $FRAMES"
grep -q "XR_SESSION_STATE_STOPPING->XR_SESSION_STATE_IDLE" "$OUT/stdout" || fail "no STOPPING->IDLE"
grep -q "XR_SESSION_STATE_IDLE->XR_SESSION_STATE_EXITING" "$OUT/stdout" || fail "no IDLE->EXITING"
grep -q "XR_ERROR" "$OUT/stdout" "$OUT/stderr" && fail "an XR_ERROR result was logged"

if [ "$MODE" = validation ]; then
  grep -q "Core Validation" "$OUT/stdout" "$OUT/stderr" || fail "the core validation layer was not loaded"
  n=$(awk '/VALID_ERROR|VALID_WARNING|VUID-/ { n++ } END { print n + 0 }' "$OUT/stdout" "$OUT/stderr")
  echo "core validation messages: $n"
  [ "$n" -eq 0 ] || fail "$n validation messages"
fi

if [ "$MODE" = paced_png ]; then
  min=$(echo "($FRAMES - 2) / 90" | bc -l)
  echo "paced: ${elapsed}s for $FRAMES frames (>= ${min}s at 90 Hz)"
  [ "$(echo "$elapsed >= $min" | bc)" -eq 1 ] || fail "frames not paced at 90 Hz"
  n=$(ls "$OUT/frames"/frame_*.png 2>/dev/null | wc -l)
  want=$(( (FRAMES + 14) / 15 ))
  [ "$n" -eq "$want" ] || fail "$n PNG files, expected $want"
  /usr/bin/python3 - "$OUT/frames" <<'PY' || fail "PNG check"
import sys, zlib, struct, glob
for f in sorted(glob.glob(sys.argv[1] + "/frame_*.png")):
    d = open(f, "rb").read()
    assert d[:8] == b"\x89PNG\r\n\x1a\n", f
    w, h = struct.unpack(">II", d[16:24])
    assert (w, h) == (1024, 1024), (f, w, h)
    pos, idat = 8, b""
    while pos < len(d):
        n, t = struct.unpack(">I4s", d[pos:pos + 8])
        body = d[pos + 8:pos + 8 + n]
        assert zlib.crc32(t + body) == struct.unpack(">I", d[pos + 8 + n:pos + 12 + n])[0], "crc"
        if t == b"IDAT": idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    assert len(raw) == h * (w * 4 + 1)
    colors = {raw[i:i + 3] for y in range(0, h, 8) for i in range(y * (w * 4 + 1) + 1, (y + 1) * (w * 4 + 1), 32)}
    print(f"{f}: {w}x{h}, {len(colors)} distinct sampled colours")
    assert len(colors) >= 3, "the frame is blank: hello_xr's cubes are missing"
PY
fi
echo PASS
