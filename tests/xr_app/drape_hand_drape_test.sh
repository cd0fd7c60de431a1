#!/usr/bin/env bash
# The tight skirt draped by hand (docs/draping.md, "A hand-draped tight skirt"): the scenarios
# assets/scenarios/hand_drape_{front,back}.json (written by hand_drape_scenario, which this test
# runs again and compares) are played on the simulated runtime with `drape run --record`; each
# recording replays to the run's final state (`drape replay`); each session's pattern
# (pattern/session-1/report.json) holds two half pieces (centre line to side line) whose hip and
# waist widths are compared with `drape pattern --design tight-skirt`'s front and back pieces:
# hip_width_mm with hip_width_mm, waist_width_mm with waist_seam_mm (the waist without the
# darts' intake: the hand drape folds no darts). Bound +-2 mm; every error is printed.
# usage: drape_hand_drape_test.sh DRAPE_EXE SCENARIO_WRITER SCENARIO_DIR
set -u
exe=$1 writer=$2 scenarios=$3
. "$(dirname "$0")/cli_test_lib.sh"
cli_test_setup drape_hand_drape
unset XR_RUNTIME_JSON DRAPE_MOCK_SCENARIO DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_WRITE_FRAMES
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_CONFIG_DIRS=$work/none

"$exe" pattern --design tight-skirt --out design >out.txt 2>&1 || fail "drape pattern exited $?"
for side in front back; do
  "$writer" "$side" "$side.json" >out.txt 2>&1 || fail "hand_drape_scenario $side exited $?"
  python3 - "$side.json" "$scenarios/hand_drape_$side.json" <<'PY' >out.txt 2>&1 ||
import json, sys
def same(a, b):  # numbers to 1e-9 (the writer's sines and cosines may differ in the last bit)
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(map(same, a, b))
    if isinstance(a, float) or isinstance(b, float):
        return abs(a - b) <= 1e-9
    return a == b
sys.exit(0 if same(json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))) else 1)
PY
    fail "assets/scenarios/hand_drape_$side.json is not what hand_drape_scenario writes"
  "$exe" run --scenario "$scenarios/hand_drape_$side.json" --cloth-res 51 --eye-size 64 \
    --no-voice --every 100000 --out "$side" --record "$side/rec" >out.txt 2>&1 ||
    fail "drape run ($side) exited $?"
  live=$(sed -n 's/^drape run: final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' out.txt)
  grep -q "4 cut(s)" out.txt || fail "$side: the four cuts did not all happen"
  "$exe" replay "$side/rec" >out.txt 2>&1 || fail "drape replay ($side) exited $?"
  replayed=$(sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' out.txt)
  [ -n "$live" ] && [ "$replayed" = "$live" ] ||
    fail "$side: the recording replays to '$replayed', the run ended at '$live'"
  echo "$side: recorded and replayed to $live"
done
python3 - <<'PY' || exit 1
import json, sys
design = {p["name"].lower(): p for p in json.load(open("design/report.json"))["pieces"]}
bad = []
for side in ("front", "back"):
    pieces = json.load(open(f"{side}/pattern/session-1/report.json"))["pieces"]
    halves = sorted(pieces, key=lambda p: -p["area_cm2"])[:2]
    want = design[side]
    for k, p in enumerate(halves):
        if "hip_width_mm" not in p or "waist_width_mm" not in p:
            bad.append(f"{side} half {k + 1}: no hip or waist width in the report")
            continue
        for what, got, ref in (("hip", p["hip_width_mm"], want["hip_width_mm"]),
                               ("waist", p["waist_width_mm"], want["waist_seam_mm"])):
            err = got - ref
            print(f"{side} half {k + 1} ({p['name']}): {what} {got:.2f} mm vs design {ref:.2f} mm:"
                  f" error {err:+.2f} mm")
            if abs(err) > 2.0:
                bad.append(f"{side} half {k + 1} {what} error {err:+.2f} mm (bound 2 mm)")
for b in bad:
    print("FAIL:", b)
sys.exit(1 if bad else 0)
PY
echo PASS
