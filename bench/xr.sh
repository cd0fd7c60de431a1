#!/usr/bin/env bash
# ./drape bench xr: the drape OpenXR app on the mock runtime (paced 90 Hz, lavapipe), 2 x 512^2
# eyes, a 128^2 cloth on the sim's own 90 Hz thread. Measures
#   latency_frames      hand pose-to-photon: frames between the scenario frame whose right-hand
#                       pose the drawn hand has and the frame that draws it (median; max too;
#                       the hand is drawn from the frame's own located pose; checked in pixels
#                       by xr_app_test HandMarkerIsDrawnAtTheFramesOwnPose)
#   cloth_latency_frames the same for the cloth's response: the frame whose hand pose the drawn
#                       sim snapshot holds (the sim consumed it), median and max
#   cloth_latency_ms    the same in time: posting that pose to the sim -> end of the frame that
#                       draws the snapshot holding it (median, p99)
#   frame_ms_p50/p99    wall time per frame from xrWaitFrame's return to xrEndFrame's return
#   sim_tick_jitter_ms  standard deviation of the sim's tick-start intervals (nominal 11.11 ms)
#   profile_ms          per-stage wall ms per frame (render.gpu_wait = lavapipe's rasterisation,
#                       render.build/upload, xr.*, pose_wait, ...) and per sim tick (sim.step_wall,
#                       sim.step_cpu = the sim thread's CPU in the solver step); thread_cpu_s: CPU
#                       seconds per thread group (frame loop, lavapipe, sim thread, solver workers)
# and, for comparison, the same with the sim in lock step (one tick per frame, 32^2 cloth).
# Writes out/bench/xr.json (+ xr_lockstep.json). Env: DRAPE_BUILD_DIR (default build).
# The machine's load is printed with the figures: everything here is CPU work on shared cores.
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
echo "== free-running sim (90 Hz thread), 2 x 512^2, cloth 128^2, paced 90 Hz ($(uptime | sed 's/.*load/load/'))"
"$EXE" xr --eye-size 512 --cloth-res 128 --sim-free --json out/bench/xr.json 2>&1 |
  grep -E "^drape xr:" || true
echo "== lock-step sim (one tick per frame), 2 x 512^2, cloth 32^2, paced 90 Hz ($(uptime | sed 's/.*load/load/'))"
"$EXE" xr --eye-size 512 --cloth-res 32 --json out/bench/xr_lockstep.json 2>&1 |
  grep -E "^drape xr:" || true
echo "== done ($(uptime | sed 's/.*load/load/'))"
/usr/bin/python3 - <<'PY'
import json
a = json.load(open("out/bench/xr.json")); b = json.load(open("out/bench/xr_lockstep.json"))
keys = ["latency_frames", "latency_frames_max", "cloth_latency_frames", "cloth_latency_frames_max",
        "cloth_latency_ms", "frame_ms_p50", "frame_ms_p99", "sim_tick_jitter_ms", "frames"]
print(f"{'metric':28s} {'free 128^2':>12s} {'lockstep 32^2':>14s}")
for k in keys:
    print(f"{k:28s} {a.get(k, -1):12.3f} {b.get(k, -1):14.3f}")
pa, pb = a.get("profile_ms", {}), b.get("profile_ms", {})
for st in ["frame.process_cpu", "render.gpu_wait", "render.build", "render.upload",
           "render.record_submit", "pose_wait", "xr.end_frame", "sim.step_wall", "sim.step_cpu"]:
    print(f"{'p50 ' + st:28s} {pa.get(st, {}).get('p50', -1):12.3f} {pb.get(st, {}).get('p50', -1):14.3f}")
ta, tb = a.get("thread_cpu_s", {}), b.get("thread_cpu_s", {})
for g in sorted(set(ta) | set(tb)):
    print(f"{'cpu s ' + g[:22]:28s} {ta.get(g, 0):12.2f} {tb.get(g, 0):14.2f}")
print("wrote out/bench/xr.json, out/bench/xr_lockstep.json")
PY
