#!/usr/bin/env bash
# `drape pattern --simulate`: the tight skirt sewn and draped on the form by XPBD writes its
# simulated glTF, the fit map PNG (its signature and size read back, its legend's colour bars and
# labels: png_pixels.py legend), garment_sim.json (at rest, seams closed, nothing in the form)
# and a scene file; so does the bodice (its bust band measured, no hip band: no cloth there); an
# unknown fabric and --fabric without --simulate are clear errors that write nothing.
# usage: drape_pattern_simulate_test.sh DRAPE_EXE
set -u
exe=$(realpath "$1")
here=$(cd "$(dirname "$0")" && pwd)
source "$(dirname "$0")/cli_test_lib.sh"
cli_test_setup drape_pattern_simulate

expect 1 "--fabric: needs --simulate" -- pattern --design tight-skirt --fabric muslin --out bad1
[ ! -e bad1 ] || fail "bad1 written"
expect 1 "--fabric silk" "no preset 'silk'" -- pattern --design tight-skirt --simulate --fabric silk --out bad2
[ ! -e bad2 ] || fail "bad2 written"

expect 0 "simulated garment (xpbd, muslin)" "(at rest)" "seam gap max" -- \
  pattern --design tight-skirt --simulate --out sk
for f in pattern.svg report.json garment.gltf garment_sim.gltf fit_map.png garment_sim.json \
  garment_scene.json; do
  [ -s "sk/$f" ] || fail "sk/$f missing"
done
# The fit map is a PNG of two tiles by two (480 x 640 each) over a legend of 120 rows.
/usr/bin/python3 - sk/fit_map.png <<'PY' || fail "fit_map.png is not a 960 x 1400 PNG"
import struct, sys
b = open(sys.argv[1], "rb").read(24)
assert b[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
w, h = struct.unpack(">II", b[16:24])
assert (w, h) == (960, 1400), (w, h)
PY
# The legend: each map's colour bar, its ends the map's ends, and its labels.
/usr/bin/python3 "$here/png_pixels.py" legend sk/fit_map.png || fail "fit_map.png's legend"
/usr/bin/python3 - sk/garment_sim.json <<'PY' || fail "garment_sim.json out of bounds"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["at_rest"], "not at rest"
assert j["seam_gap_max_mm"] < 0.5, j["seam_gap_max_mm"]
assert j["penetration_max_mm"] < 0.5, j["penetration_max_mm"]
assert j["frames"] > 0 and j["ms_per_frame"] > 0
PY
# The bodice: simulated (no longer refused), at rest, seams closed, its bust girth measured.
expect 0 "simulated garment (xpbd, muslin)" "(at rest)" "bust  (y" "hip   (y 0.780 m) no cloth" -- \
  pattern --design bodice --simulate --out bo
for f in pattern.svg report.json garment_sim.gltf fit_map.png garment_sim.json; do
  [ -s "bo/$f" ] || fail "bo/$f missing"
done
/usr/bin/python3 - bo/garment_sim.json <<'PY' || fail "bodice garment_sim.json out of bounds"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["design"] == "bodice", j["design"]
assert j["at_rest"], "not at rest"
assert j["seam_gap_max_mm"] < 0.5, j["seam_gap_max_mm"]
assert j["penetration_max_mm"] < 0.5, j["penetration_max_mm"]
assert j["hip"] is None, j["hip"]
for band in ("waist", "bust"):
    assert abs(j[band]["girth_error_pct"]) < 1.0, (band, j[band])
PY
echo "all ok"
