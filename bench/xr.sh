#!/usr/bin/env bash
# ./drape bench xr: the drape OpenXR app on the mock runtime (paced 90 Hz, lavapipe), 2 x 512^2
# eyes, a 128^2 cloth on the sim's own 90 Hz thread. Measures
#   latency_frames      hand pose-to-photon: frames between the scenario frame whose right-hand
#                       pose the drawn hand has and the frame that draws it (median; max too;
#                       the hand is drawn from the frame's own located pose; checked in pixels
#                       by xr_app_test HandMarkerIsDrawnAtTheFramesOwnPose)
#   cloth_latency_frames the same for the cloth's response: the frame whose hand pose the drawn
#                       sim snapshot holds (the sim consumed it), median and max
#   frame_ms_p50/p99    wall time per frame from xrWaitFrame's return to xrEndFrame's return
#   sim_tick_jitter_ms  standard deviation of the sim's tick-start intervals (nominal 11.11 ms)
# and, for comparison, the same with the sim in lock step (one tick per frame, 32^2 cloth).
# Writes out/bench/xr.json (+ xr_lockstep.json). Env: DRAPE_BUILD_DIR (default build).
set -euo pipefail
ROOT="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$ROOT"
BUILD="${DRAPE_BUILD_DIR:-build}"
EXE="$BUILD/bin/drape"
[ -x "$EXE" ] || { echo "bench xr: $EXE not built" >&2; exit 2; }
mkdir -p out/bench
export XR_RUNTIME_JSON="$ROOT/$BUILD/bin/drape_mock_runtime.json"
export DRAPE_MOCK_SCENARIO="$ROOT/assets/scenarios/bench_xr.json"
unset DRAPE_MOCK_WRITE_FRAMES DRAPE_MOCK_FAST DRAPE_MOCK_END_AFTER_FRAMES
echo "== free-running sim (90 Hz thread), 2 x 512^2, cloth 128^2, paced 90 Hz"
"$EXE" xr --eye-size 512 --cloth-res 128 --sim-free --json out/bench/xr.json 2>&1 |
  grep -E "^drape xr:" || true
echo "== lock-step sim (one tick per frame), 2 x 512^2, cloth 32^2, paced 90 Hz"
"$EXE" xr --eye-size 512 --cloth-res 32 --json out/bench/xr_lockstep.json 2>&1 |
  grep -E "^drape xr:" || true
/usr/bin/python3 - <<'PY'
import json
a = json.load(open("out/bench/xr.json")); b = json.load(open("out/bench/xr_lockstep.json"))
keys = ["latency_frames", "latency_frames_max", "cloth_latency_frames", "cloth_latency_frames_max",
        "frame_ms_p50", "frame_ms_p99", "sim_tick_jitter_ms", "frames"]
print(f"{'metric':24s} {'free 128^2':>12s} {'lockstep 32^2':>14s}")
for k in keys:
    print(f"{k:24s} {a.get(k, -1):12.3f} {b.get(k, -1):14.3f}")
print("wrote out/bench/xr.json, out/bench/xr_lockstep.json")
PY
