#!/usr/bin/env bash
# The sewn garment in the live app: `drape xr --garment tight-skirt` on the simulated runtime
# (through the OpenXR loader, real frames, the sim in lock step) playing
# tests/xr_app/scenarios/garment_pinch.json: the head looks at the skirt on the form, the right
# hand pinches its front at the hip line and pulls it out, the left hand points twice (colour map
# none -> strain -> ease). Checks, from xr_session.txt and the runtime's frames:
#   * the garment loaded: vertices, triangles and seam ties counted at tick 0;
#   * after the 240 ticks (the pinch included) the seams are closed (largest tie gap < 1 mm) and
#     nothing lies in the form (< 1 mm);
#   * the pinch took a garment particle and moved it more than 5 cm;
#   * the frame with the ease map (230) shows the garment on the form: over 1500 pixels in the
#     map's colours, in a box centred on the form, narrower than the form's surroundings, with
#     the form's cover above it; the frame before the toggle (140) has under a tenth of them
#     (png_pixels.py garment).
# The dress (`--garment dress`: the bodice and the tight skirt sewn at the waist) plays the same
# scenario: over 1500 seam ties, closed and out of the form after the pinch, the pinch moving it,
# and its ease map reaching from the shoulders to below the hip (png_pixels.py dress).
# Bad input: an unknown design or fabric and --garment-fabric alone are errors naming the option.
# A save asked for (scenarios/garment_save.json: the menu held 1 s) is refused.
# usage: drape_garment_xr_test.sh DRAPE_EXE
set -u
exe=$(realpath "$1")
here=$(cd "$(dirname "$0")" && pwd)
source "$here/cli_test_lib.sh"
cli_test_setup drape_garment_xr
unset XR_RUNTIME_JSON DRAPE_MOCK_SCENARIO DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_WINDOW DISPLAY \
  WAYLAND_DISPLAY
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_CONFIG_DIRS=$work/none
export DRAPE_MOCK_FAST=1

expect 2 "--garment: no such design: nosuch" -- xr --garment nosuch --frames 2
expect 2 "--garment-fabric silk" "no preset 'silk'" -- \
  xr --garment tight-skirt --garment-fabric silk --frames 2
expect 2 "--garment-fabric: needs --garment" -- xr --garment-fabric denim --frames 2

export DRAPE_MOCK_WRITE_FRAMES=$work/frames DRAPE_MOCK_WRITE_EVERY=10
# pinch_run DESIGN MIN_VERTICES MIN_TIES PIXEL_CHECK: plays garment_pinch.json with the design
# and checks the log and the frames (see the top).
pinch_run() {
  local design=$1 min_nv=$2 min_ties=$3 check=$4
  rm -rf frames && mkdir -p frames
  expect 0 "exiting" -- xr --garment "$design" --scenario "$here/scenarios/garment_pinch.json" \
    --frames 240 --eye-size 256 --no-feedback-panel --out "$work/$design"
  local log=$design/xr_session.txt start end nv nt nties gap inside moved
  cp "$log" out.txt
  start=$(grep "^garment: tick 0: " "$log") || fail "$design: no garment line at tick 0"
  end=$(grep "^garment: tick 240: " "$log") || fail "$design: no garment line at tick 240"
  echo "$start"
  echo "$end"
  read -r nv nt nties <<<"$(sed -n 's/.*: \([0-9]*\) vertices, \([0-9]*\) triangles, \([0-9]*\) seam ties.*/\1 \2 \3/p' <<<"$start")"
  [ "${nv:-0}" -gt "$min_nv" ] && [ "${nt:-0}" -gt $((2 * min_nv)) ] &&
    [ "${nties:-0}" -gt "$min_ties" ] || fail "$design: $nv vertices, $nt triangles, $nties ties"
  read -r gap inside <<<"$(sed -n 's/.*seam gap max \([0-9.]*\) mm, \([0-9.]*\) mm in the form.*/\1 \2/p' <<<"$end")"
  /usr/bin/python3 -c "import sys; sys.exit(not (float('$gap') < 1.0 and float('$inside') < 1.0))" ||
    fail "$design after 240 ticks: seam gap $gap mm, $inside mm in the form (bounds 1 mm)"
  grep -q "^garment: tick 240: $nv vertices, $nt triangles, $nties seam ties" "$log" ||
    fail "$design: the garment's vertices or ties changed"
  moved=$(sed -n 's/^pinch: right hand let particle [0-9]* go at .* (moved \([0-9.]*\) mm)/\1/p' "$log")
  [ -n "$moved" ] && /usr/bin/python3 -c "import sys; sys.exit(not float('$moved') > 50)" ||
    fail "$design: the pinch did not move the garment more than 5 cm (moved: ${moved:-nothing})"
  echo "ok: the pinch moved the $design $moved mm"
  grep -q "^colour map: strain" "$log" && grep -q "^colour map: ease" "$log" ||
    fail "$design: the colour map was not toggled to strain and ease"
  /usr/bin/python3 "$here/png_pixels.py" "$check" frames/frame_000140.png frames/frame_000230.png ||
    fail "$design: the frames do not show the garment on the form"
}
pinch_run tight-skirt 5000 500 garment
# The dress: the bodice's and the tight skirt's seams and the waist seam.
pinch_run dress 20000 1500 dress
# Asked to save (the menu held 1 s): a garment session is not saved, and says so.
unset DRAPE_MOCK_WRITE_FRAMES
expect 0 "exiting" -- xr --garment tight-skirt --scenario "$here/scenarios/garment_save.json" \
  --frames 130 --eye-size 64 --no-feedback-panel --out "$work/save"
cp save/xr_session.txt out.txt
grep -q "button.menu_hold begin hand left -> save once" save/xr_session.txt || fail "no save asked"
grep -q "^save: frame [0-9]*: a garment session is not saved" save/xr_session.txt ||
  fail "the save was not refused"
[ ! -e save/saved_session.drape ] || fail "a garment session was saved"
echo "ok: a garment session is not saved"
echo "all ok"
