#!/usr/bin/env bash
# ./drape bench garment [--frames N]: the sewn garment's sim tick in the drape OpenXR app
# (`drape xr --garment tight-skirt`: the tight skirt at its design's resolution, 12 mm remesh,
# XPBD with 20 substeps and its seam ties, 2 threads) on the mock runtime (paced 90 Hz, lavapipe,
# 2 x 256^2 eyes), playing tests/xr_app/scenarios/garment_pinch.json (a pinch pulls the skirt,
# the colour maps are toggled), side by side with the live panel (64^2, the app's solver) under
# the same scenario:
#   garment_lock   the sim in lock step (one tick per frame, on the frame loop's thread)
#   garment_free   the sim on its own thread at 90 Hz (the live default of `drape run`)
#   panel64_free   the 64^2 panel of the default scene on its own thread
#   garment_rest   garment_lock played for 1200 ticks: the garment settles and falls asleep
#   dress_lock     the dress (`--garment dress`: bodice and tight skirt sewn at the waist) in lock
#                  step under the same scenario
#   dress_rest     dress_lock played for 1200 ticks
# Per run: step_wall_ms and step_cpu_ms (the solver's step per tick, p50 / p99), tick_interval_ms
# (free sim: the tick-start intervals, p50 / p99, i.e. the rate it reaches), frame_ms p50, the
# ratio of the step's p50 to the panel's and the garment's vertices asleep at the end. Writes
# out/bench/garment.json and out/bench/garment.csv and prints a table with the machine's load
# (CPU work on shared cores). Env: DRAPE_BUILD_DIR (default build).
set -euo pipefail
ROOT="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
shift || true
. "$ROOT/bench/lib.sh"
bench_parse_frames garment 400 120 400 18 "$@"
bench_mock_setup garment
SCENARIO=tests/xr_app/scenarios/garment_pinch.json
run() {  # run NAME ARGS...
  local name="$1"; shift
  echo "== $name ($(uptime | sed 's/.*load/load/'))"
  "$EXE" xr --scenario "$SCENARIO" --eye-size 256 --frames "$FRAMES" --no-feedback-panel \
    --out "$WORK/$name" --json "$WORK/$name.json" "$@" >"$WORK/$name.txt" 2>&1 ||
    { echo "bench garment: drape xr failed ($name):" >&2; tail "$WORK/$name.txt" >&2; exit 1; }
}
run garment_lock --garment tight-skirt
run garment_free --garment tight-skirt --sim-free
run panel64_free --cloth-res 64 --sim-free
# The same pinch played for 1200 ticks in lock step: the garment settles and falls asleep.
sed 's/"end_after_frames": [0-9]*/"end_after_frames": 1200/' "$SCENARIO" >"$WORK/scenario_rest.json"
SCENARIO="$WORK/scenario_rest.json" FRAMES=1200 run garment_rest --garment tight-skirt
run dress_lock --garment dress
SCENARIO="$WORK/scenario_rest.json" FRAMES=1200 run dress_rest --garment dress
echo "== done ($(uptime | sed 's/.*load/load/'))"
/usr/bin/python3 - "$WORK" <<'PY'
import csv, json, re, sys
work = sys.argv[1]
nan = float("nan")

def q(prof, stage, p):
    return prof.get(stage, {}).get(p, nan)

rows = []
for name in ("garment_lock", "garment_free", "panel64_free", "garment_rest", "dress_lock",
             "dress_rest"):
    j = json.load(open(f"{work}/{name}.json"))
    prof = j["profile_ms"]
    log = open(f"{work}/{name}/xr_session.txt").read()
    m = re.search(r"garment: tick \d+: (\d+) vertices, (\d+) triangles, (\d+) seam ties, "
                  r"seam gap max ([0-9.]+) mm, [0-9.]+ mm in the form, (\d+) vertices asleep",
                  log.split("garment: tick 0:")[-1])
    rows.append({
        "run": name,
        "vertices": int(m.group(1)) if m else 64 * 64,
        "ties": int(m.group(3)) if m else 0,
        "ticks": prof.get("sim.step_wall", {}).get("n", 0),
        "step_wall_ms_p50": q(prof, "sim.step_wall", "p50"),
        "step_wall_ms_p99": q(prof, "sim.step_wall", "p99"),
        "step_cpu_ms_p50": q(prof, "sim.step_cpu", "p50"),
        "step_cpu_ms_p99": q(prof, "sim.step_cpu", "p99"),
        "tick_interval_ms_p50": q(prof, "sim.tick_interval", "p50"),
        "tick_interval_ms_p99": q(prof, "sim.tick_interval", "p99"),
        "frame_ms_p50": j["frame_ms_p50"],
        "seam_gap_end_mm": float(m.group(4)) if m else nan,
        "asleep_end": int(m.group(5)) if m else 0,
    })
panel = next(r for r in rows if r["run"] == "panel64_free")["step_wall_ms_p50"]
for r in rows:
    r["step_p50_vs_panel64"] = r["step_wall_ms_p50"] / panel
print(f"{'run':<13} {'verts':>6} {'ties':>5} {'ticks':>5} {'step wall p50/p99 ms':>21} "
      f"{'step cpu p50/p99 ms':>20} {'tick interval p50/p99':>22} {'frame p50':>9} "
      f"{'gap mm':>7} {'vs panel':>8} {'asleep':>6}")
for r in rows:
    print(f"{r['run']:<13} {r['vertices']:>6} {r['ties']:>5} {r['ticks']:>5} "
          f"{r['step_wall_ms_p50']:>10.2f}/{r['step_wall_ms_p99']:<10.2f}"
          f"{r['step_cpu_ms_p50']:>9.2f}/{r['step_cpu_ms_p99']:<10.2f}"
          f"{r['tick_interval_ms_p50']:>10.2f}/{r['tick_interval_ms_p99']:<11.2f}"
          f"{r['frame_ms_p50']:>9.2f} {r['seam_gap_end_mm']:>7.3f} {r['step_p50_vs_panel64']:>8.2f}"
          f" {r['asleep_end']:>6}")
json.dump({"rows": rows}, open("out/bench/garment.json", "w"), indent=1)
with open("out/bench/garment.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
print("wrote out/bench/garment.json, out/bench/garment.csv")
PY
