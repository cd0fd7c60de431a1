#!/usr/bin/env bash
# ./drape bench desk [--frames N] [--repeat R] [--eye-size PX]: `drape run` at a desk as a person
# gets it: the simulated runtime's window (1280x720, under Xvfb; real X input from xdotool), its
# default eye size (--eye-size: another),
# lavapipe, the sim on its own 90 Hz thread, no scenario. Measures
#   fps_64, fps_128        frames per second (frames over the frame loop's time after the first
#                          30) with a 64² and a 128² cloth while the mouse's hand pinches the
#                          cloth and drags it up and down (the app's --json; median of R runs)
#   mouse_latency_frames   mouse-to-photon: xdotool jumps the cursor between two places on the
#                          cloth; from the frame whose window-log line first shows the right hand
#                          at the new place (the frame the runtime took the motion in) to the
#                          first frame whose submitted left-eye image (the runtime's screenshots,
#                          every frame) shows the hand's pointer marker nearer the new place than
#                          the old one (median of the jumps; max too); 64² cloth
#   cloth_latency_frames   the cloth's response: frames between the frame whose right-hand pose
#                          the drawn sim snapshot holds and the frame drawing it (the app's
#                          probes during the pinch and drag; median, p90 and max at 64²)
# Goals: fps_64 >= 30, cloth_latency_frames <= 2 (the median); whether met is written too.
# Writes out/bench/desk.json, out/bench/desk.csv and prints a table with the machine's load.
set -euo pipefail
ROOT="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
shift || true
FRAMES=540 REPEAT=1 EYE=()
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) FRAMES="$2"; shift 2 ;;
    --repeat) REPEAT="$2"; shift 2 ;;
    --eye-size) EYE=(--eye-size "$2"); shift 2 ;;
    -h | --help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench desk: unknown flag '$1' (--frames N, --repeat R, --eye-size PX)" >&2; exit 2 ;;
  esac
done
[[ "$FRAMES" =~ ^[0-9]+$ && "$FRAMES" -ge 120 ]] || { echo "bench desk: --frames: at least 120" >&2; exit 2; }
[[ "$REPEAT" =~ ^[0-9]+$ && "$REPEAT" -ge 1 ]] || { echo "bench desk: --repeat: at least 1" >&2; exit 2; }
cd "$ROOT"
EXE="$ROOT/${DRAPE_BUILD_DIR:-build}/bin/drape"
[ -x "$EXE" ] || { echo "bench desk: $EXE not built" >&2; exit 2; }
for tool in Xvfb xdotool python3; do
  command -v $tool >/dev/null || { echo "bench desk: $tool is not installed (./drape setup)" >&2; exit 2; }
done
WORK="$ROOT/out/bench/desk"
rm -rf "$WORK" && mkdir -p "$WORK/home"
XVFB_PID="" APP_PID=""
cleanup() {
  [ -n "$APP_PID" ] && kill "$APP_PID" 2>/dev/null
  [ -n "$XVFB_PID" ] && kill "$XVFB_PID" 2>/dev/null
  wait 2>/dev/null || true
}
trap cleanup EXIT
Xvfb -displayfd 3 -screen 0 1280x720x24 -nolisten tcp 3>"$WORK/display" 2>"$WORK/xvfb.log" &
XVFB_PID=$!
for _ in $(seq 100); do [ -s "$WORK/display" ] && break; sleep 0.1; done
[ -s "$WORK/display" ] || { echo "bench desk: Xvfb did not start" >&2; exit 1; }
export DISPLAY=":$(head -1 "$WORK/display")"
# No runtime configured: drape run takes the simulated runtime and, with a display, its window.
unset WAYLAND_DISPLAY XR_RUNTIME_JSON XR_ENABLE_API_LAYERS DRAPE_MOCK_WINDOW DRAPE_MOCK_SCENARIO \
  DRAPE_MOCK_WRITE_FRAMES DRAPE_MOCK_END_AFTER_FRAMES
export HOME="$WORK/home" XDG_CONFIG_HOME="$WORK/home/.config" XDG_CONFIG_DIRS="$WORK/home/xdg"
export DRAPE_MOCK_WINDOW_SIZE=1280x720

# The view: the left eye letterboxed at x 280..1000 (720 px high); the cloth hangs on the form around
# x 570..730, y 490..680.
lines() { [ -f "$LOG" ] && wc -l <"$LOG" || echo 0; }
frames() {  # frames N: waits for N more frames in the window log (false when the app ended)
  local want=$(( $(lines) + $1 ))
  while [ "$(lines)" -lt "$want" ]; do kill -0 "$APP_PID" 2>/dev/null || return 1; sleep 0.02; done
}
# start_app NAME ARGS...: drape run live into WORK/NAME; waits for its first 5 frames.
start_app() {
  local name="$1"; shift
  LOG="$WORK/$name.log"
  export DRAPE_MOCK_WINDOW_LOG="$LOG"
  "$EXE" run --no-pattern --out "$WORK/$name" "${EYE[@]}" "$@" >"$WORK/$name.stdout" 2>"$WORK/$name.stderr" &
  APP_PID=$!
  frames 5 || { echo "bench desk: $name: the app ended early:" >&2; tail -5 "$WORK/$name.stderr" >&2; exit 1; }
}
finish_app() {
  wait "$APP_PID" || { echo "bench desk: drape run failed:" >&2; tail -5 "$WORK/$1.stderr" >&2; exit 1; }
  APP_PID=""
}

# A pinch and drag until the frame budget ends the run: the hand onto the cloth, the button
# held, the cloth pulled up 160 px and back down, again and again.
pinch_and_drag() {
  xdotool mousemove 650 600
  frames 20 || return 0
  xdotool mousedown 1
  while true; do
    for s in $(seq 0 10) $(seq 10 -1 0); do
      xdotool mousemove $((650 - 4 * s)) $((600 - 16 * s))
      frames 2 || { xdotool mouseup 1; return 0; }
    done
  done
}

load() { uptime | sed 's/.*load average: //'; }
echo "== bench desk: drape run live, window 1280x720, ${EYE[*]:-default eye size}, lavapipe, sim thread 90 Hz, $FRAMES frames"
echo "   load before: $(load) ($(nproc) cores)"
for r in $(seq "$REPEAT"); do
  for res in 64 128; do
    start_app "fps_${res}_$r" --resolution "$res" --frames "$FRAMES" --json "$WORK/fps_${res}_$r.json"
    pinch_and_drag
    finish_app "fps_${res}_$r"
    echo "   run $r, ${res}²: $(grep -o '[0-9.]* fps (frame work p50 [0-9.]* ms)' "$WORK/fps_${res}_$r.stdout"), load $(load)"
  done
done

# Mouse-to-photon: every frame's left eye written by the runtime; the cursor jumps between two
# places on the cloth every 15 frames.
start_app latency --resolution 64 --frames 200 --every 1
LAT_LOG="$LOG"
xdotool mousemove 600 600
frames 30 || true
for _ in $(seq 10); do
  xdotool mousemove 710 600; frames 15 || break
  xdotool mousemove 600 600; frames 15 || break
done
finish_app latency

echo "   load after: $(load)"
python3 - "$WORK" "$LAT_LOG" "$REPEAT" "$(load)" "$(nproc)" <<'PY'
import csv, json, math, os, statistics, struct, sys, zlib
work, lat_log, repeat, load, cores = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
runs = {res: [json.load(open(f"{work}/fps_{res}_{r}.json")) for r in range(1, repeat + 1)] for res in (64, 128)}
med = lambda xs: statistics.median(xs) if xs else -1

# The window log: the right hand per frame; a jump of more than 5 cm is the frame the runtime
# took the cursor's motion in.
hands = {}
for line in open(lat_log):
    d = dict(kv.split("=", 1) for kv in line.split() if "=" in kv)
    hands[int(d["frame"])] = [float(c) for c in d["right"].split(",")]
jumps = [f for f in sorted(hands) if f - 1 in hands and math.dist(hands[f], hands[f - 1]) > 0.05]

def marker(frame, x0, x1, cy):
    """The median of the pointer marker's pixels in window x0..x1, cy +- 30 (the left eye fills
    the window's height at x 280..1000), in window pixels."""
    path = f"{work}/latency/frames/frame_{frame:06d}.png"
    if not os.path.exists(path):
        return None
    d = open(path, "rb").read()
    w, h = struct.unpack(">II", d[16:24])
    k = w / 720  # eye pixels per window pixel
    pos, idat = 8, b""
    while pos < len(d):
        n, t = struct.unpack(">I4s", d[pos:pos + 8])
        if t == b"IDAT":
            idat += d[pos + 8:pos + 8 + n]
        pos += 12 + n
    raw = zlib.decompress(idat)  # the runtime's PNG: RGBA, filter 0 on every row
    xs, ys = [], []
    for y in range(max(0, int(k * (cy - 30))), min(h, int(k * (cy + 30)))):
        row = raw[y * (4 * w + 1) + 1:(y + 1) * (4 * w + 1)]
        for x in range(max(0, int(k * (x0 - 280))), min(w, int(k * (x1 - 280)))):
            r, g, b = row[4 * x], row[4 * x + 1], row[4 * x + 2]
            if r > 235 and 215 < g < 252 and 80 < b < 170:
                xs.append(x)
                ys.append(y)
    if len(xs) < 3:
        return None
    return statistics.median(xs) / k + 280, statistics.median(ys) / k

A, B = (600, 600), (710, 600)  # the cursor's two places (window pixels)
lat = []
for f0 in jumps:
    new = B if hands[f0][0] > hands[f0 - 1][0] else A
    old = A if new is B else B
    for f in range(f0 - 2, f0 + 8):
        m = marker(f, A[0] - 30, B[0] + 30, A[1])
        if m and math.dist(m, new) < math.dist(m, old):
            lat.append(f - f0)
            break
mouse = med(lat)
fps64 = med([j["fps"] for j in runs[64]])
fps128 = med([j["fps"] for j in runs[128]])
cl = runs[64][len(runs[64]) // 2]["cloth_latency_frames"]
out = {
    "machine": {"load_after": load, "cores": int(cores), "gpu": "lavapipe (CPU)"},
    "setup": "drape run live, mock runtime window 1280x720 under Xvfb, sim thread 90 Hz",
    "eye_size": runs[64][0].get("eye_size", 0),
    "repeat": repeat,
    "fps_64": fps64, "fps_128": fps128,
    "fps_64_runs": [j["fps"] for j in runs[64]], "fps_128_runs": [j["fps"] for j in runs[128]],
    "frame_work_p50_ms_64": med([j["frame_work_p50_ms"] for j in runs[64]]),
    "frame_work_p50_ms_128": med([j["frame_work_p50_ms"] for j in runs[128]]),
    "sim_step_p50_ms_64": med([j["sim_step_p50_ms"] for j in runs[64]]),
    "sim_step_p50_ms_128": med([j["sim_step_p50_ms"] for j in runs[128]]),
    "mouse_latency_frames": mouse, "mouse_latency_frames_max": max(lat) if lat else -1,
    "mouse_latency_jumps": len(lat), "mouse_latency_jumps_seen": len(jumps),
    "cloth_latency_frames": cl["p50"], "cloth_latency_frames_p90": cl["p90"],
    "cloth_latency_frames_max": cl["max"], "cloth_latency_samples": cl["n"],
    "cloth_latency_frames_128": runs[128][len(runs[128]) // 2]["cloth_latency_frames"]["p50"],
    "goals": {"fps_64": ">= 30", "cloth_latency_frames": "<= 2 (median)"},
}
out["goals_met"] = {"fps_64": fps64 >= 30,
                    "cloth_latency_frames": cl["n"] > 0 and cl["p50"] <= 2}
os.makedirs("out/bench", exist_ok=True)
json.dump(out, open("out/bench/desk.json", "w"), indent=2)
rows = [("fps_64", fps64, ">= 30", out["goals_met"]["fps_64"]),
        ("fps_128", fps128, "", ""),
        ("mouse_latency_frames", mouse, f"max {out['mouse_latency_frames_max']}, {len(lat)} of {len(jumps)} jumps", ""),
        ("cloth_latency_frames", cl["p50"], "<= 2", out["goals_met"]["cloth_latency_frames"]),
        ("cloth_latency_frames_p90", cl["p90"], "", ""),
        ("cloth_latency_frames_max", cl["max"], "", ""),
        ("frame_work_p50_ms_64", out["frame_work_p50_ms_64"], "", ""),
        ("frame_work_p50_ms_128", out["frame_work_p50_ms_128"], "", ""),
        ("sim_step_p50_ms_64", out["sim_step_p50_ms_64"], "", ""),
        ("sim_step_p50_ms_128", out["sim_step_p50_ms_128"], "", "")]
with open("out/bench/desk.csv", "w", newline="") as f:
    w = csv.writer(f)  # quotes a note that holds a comma
    w.writerow(["metric", "value", "goal", "met"])
    for k, v, g, m in rows:
        w.writerow([k, f"{v:.3f}", g, m])
print(f"{'metric':28s} {'value':>9s}  goal / note")
for k, v, g, m in rows:
    print(f"{k:28s} {v:9.2f}  {g}{'' if m == '' else ('  met' if m else '  NOT met')}")
print(f"load after: {load} ({cores} cores)")
print("wrote out/bench/desk.json, out/bench/desk.csv")
PY
rm -rf "$WORK/latency/frames"
