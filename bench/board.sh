#!/usr/bin/env bash
# ./drape bench board [--frames N]: the live pattern board's cost and latency in the drape OpenXR
# app on the mock runtime (paced 90 Hz, lavapipe, 2 x 512^2 eyes), the sim on its own 90 Hz
# thread, playing the default scenario (pinch, carry, cut: one piece, then two), with a 64^2 and
# a 128^2 cloth, each with the board and without it (--no-board). Measures
#   board_latency_ms   from the fill of the sim tick's snapshot a board is built from to the end
#                      of the frame that first draws it (p50, p90, max)
#   board_build_ms     the pattern extraction and board on the worker thread (p50, max)
#   board_interval_ms  between new boards drawn (p50, max): the board's update rate
#   step_wall_ms       the sim's solver step per tick (p50, p99) with and without the board, and
#   tick_interval_ms   the sim's tick-start intervals (p50, p99): the board must not stall it
# Writes out/bench/board.json and out/bench/board.csv and prints a table with the machine's
# load (everything here is CPU work on shared cores). Env: DRAPE_BUILD_DIR (default build).
set -euo pipefail
ROOT="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
shift || true
. "$ROOT/bench/lib.sh"
bench_parse_frames board 300 120 100000 15 "$@"
bench_mock_setup board
for res in 64 128; do
  for board in on off; do
    flag=()
    [ $board = off ] && flag=(--no-board)
    echo "== cloth ${res}^2, board $board ($(uptime | sed 's/.*load/load/'))"
    "$EXE" xr --scenario assets/scenarios/default.json --eye-size 512 --cloth-res $res --sim-free \
      --frames "$FRAMES" "${flag[@]}" --out "$WORK/${res}_$board" \
      --json "$WORK/${res}_$board.json" >"$WORK/${res}_$board.txt" 2>&1 ||
      { echo "bench board: drape xr failed (cloth $res, board $board):" >&2; tail "$WORK/${res}_$board.txt" >&2; exit 1; }
  done
done
echo "== done ($(uptime | sed 's/.*load/load/'))"
/usr/bin/python3 - "$WORK" <<'PY'
import csv, json, sys
work = sys.argv[1]

def q(v, p):
    return v.get(p, float("nan")) if v else float("nan")

rows = []
for res in (64, 128):
    on = json.load(open(f"{work}/{res}_on.json"))["profile_ms"]
    off = json.load(open(f"{work}/{res}_off.json"))["profile_ms"]
    lat = on.get("board.latency", {})
    r = {
        "cloth": res,
        "boards_drawn": lat.get("n", 0),
        "board_latency_ms_p50": q(lat, "p50"),
        "board_latency_ms_p99": q(lat, "p99"),
        "board_build_ms_p50": q(on.get("board.build"), "p50"),
        "board_build_ms_p99": q(on.get("board.build"), "p99"),
        "board_interval_ms_p50": q(on.get("board.interval"), "p50"),
        "board_interval_ms_p99": q(on.get("board.interval"), "p99"),
        "step_wall_ms_p50_board": q(on.get("sim.step_wall"), "p50"),
        "step_wall_ms_p50_no_board": q(off.get("sim.step_wall"), "p50"),
        "tick_interval_ms_p50_board": q(on.get("sim.tick_interval"), "p50"),
        "tick_interval_ms_p50_no_board": q(off.get("sim.tick_interval"), "p50"),
        "tick_interval_ms_p99_board": q(on.get("sim.tick_interval"), "p99"),
        "tick_interval_ms_p99_no_board": q(off.get("sim.tick_interval"), "p99"),
    }
    r["step_ratio_board_vs_none"] = r["step_wall_ms_p50_board"] / r["step_wall_ms_p50_no_board"]
    r["updates_at_least_2_hz"] = bool(r["board_interval_ms_p50"] <= 500)
    rows.append(r)
print(f"{'cloth':>6} {'boards':>6} {'latency p50/p99 ms':>19} {'build p50/p99 ms':>17} "
      f"{'interval p50/p99 ms':>20} {'step p50 ms board/none (ratio)':>31} {'tick p99 ms board/none':>23}")
for r in rows:
    print(f"{r['cloth']:>4}^2 {r['boards_drawn']:>6} "
          f"{r['board_latency_ms_p50']:>9.1f}/{r['board_latency_ms_p99']:<9.1f}"
          f"{r['board_build_ms_p50']:>8.1f}/{r['board_build_ms_p99']:<8.1f}"
          f"{r['board_interval_ms_p50']:>10.0f}/{r['board_interval_ms_p99']:<9.0f}"
          f"{r['step_wall_ms_p50_board']:>13.2f}/{r['step_wall_ms_p50_no_board']:<6.2f} ({r['step_ratio_board_vs_none']:.2f})"
          f"{r['tick_interval_ms_p99_board']:>12.1f}/{r['tick_interval_ms_p99_no_board']:<8.1f}")
json.dump({"rows": rows}, open("out/bench/board.json", "w"), indent=1)
with open("out/bench/board.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
print("wrote out/bench/board.json, out/bench/board.csv")
PY
