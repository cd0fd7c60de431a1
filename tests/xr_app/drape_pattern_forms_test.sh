#!/usr/bin/env bash
# `drape form --vit`, `drape pattern --vit / --mesh` and the designs beyond the tight skirt from
# the command line: a form from hand-written individual measurements, a scanned form reaching
# the pattern pipeline, bad files named (file, line, measurement, reference line) with nothing
# written, and the flared skirt's report.
# usage: drape_pattern_forms_test.sh DRAPE_EXE VIT_DIR
set -u
exe=$1
vit=$2
. "$(cd "$(dirname "$0")" && pwd)/cli_test_lib.sh"
cli_test_setup drape_pattern_forms_test
expect 0 --vit -- form --help
expect 0 --vit --mesh -- pattern --help
expect 2 "--vit" -- form --size 9AR --vit "$vit/nine_ar_cm.vit"
expect 2 "--mesh" -- pattern --form 9AR --mesh form.obj
# The 9AR figure's .vit gives the 9AR form's girths.
expect 0 "individual measurements" "bust       1.1500        830.0" "waist      0.9700        640.0" \
         "hip        0.7800        910.0" -- form --vit "$vit/nine_ar_cm.vit"
# Bad files: named with the line or every missing measurement; no output directory is made.
expect 1 "malformed.vit:9: malformed XML: mismatched tag" -- \
         pattern --vit "$vit/malformed.vit" --out bad1
expect 1 "missing.vit: the form needs measurements the file lacks" "waist girth" "bust height" \
         "hip height" "neck height" -- pattern --vit "$vit/missing.vit" --out bad2
expect 1 "malformed.vit:9" -- form --vit "$vit/malformed.vit"
[ ! -e bad1 ] && [ ! -e bad2 ] || fail "an output directory was written for a bad .vit"
# A pattern on the .vit form (inches, front and back arcs).
expect 0 "design tight-skirt on form arcs_inch" "hip widths sum 965.20 mm" -- \
         pattern --vit "$vit/arcs_inch.vit" --out vit_inch
[ -s vit_inch/report.json ] && [ -s vit_inch/pattern.dxf ] || fail "no pattern from the .vit form"
# A scanned form: the 9AR form written as a mesh comes back through --mesh with its lines.
expect 0 "wrote form9.glb" -- form --size 9AR --export form9.glb
expect 0 "design tight-skirt on form form9" "hip widths sum" -- \
         pattern --mesh form9.glb --out mesh9
python3 - mesh9/report.json <<'PY' || fail "mesh form: report out of bounds"
import json, sys
r = json.load(open(sys.argv[1]))
print('mesh form: hip %+.3f mm, waist %+.3f mm, area %.3f %%' % (
    r['hip_width_error_mm'], r['waist_width_error_mm'], r['area_error_pct']))
assert abs(r['hip_width_error_mm']) < 2 and abs(r['waist_width_error_mm']) < 2
assert r['area_error_pct'] < 1
PY
# A cylinder has no waist: the error says which lines cannot be found, nothing is written.
python3 - <<'PY'
import math
with open('cylinder.obj', 'w') as f:
    n, rings = 64, 40
    for j in range(rings):
        for i in range(n):
            a = 2 * math.pi * i / n
            f.write('v %.5f %.5f %.5f\n' % (0.15 * math.sin(a), 0.6 + 0.75 * j / (rings - 1), 0.12 * math.cos(a)))
    for j in range(rings - 1):
        for i in range(n):
            a, b = j * n + i + 1, j * n + (i + 1) % n + 1
            f.write('f %d %d %d\nf %d %d %d\n' % (a, b, b + n, a, b + n, a + n))
PY
expect 1 "cylinder.obj: reference lines not found on the form: waist (no narrowing" -- \
         pattern --mesh cylinder.obj --out bad3
[ ! -e bad3 ] || fail "an output directory was written for a form without reference lines"
# The flared skirt: darts closed, the hem sweep reported.
expect 0 "design flared-skirt" "slash and spread (close_darts)" "hem sweep" -- \
         pattern --design flared-skirt --out flared
python3 - flared/report.json <<'PY' || fail "flared skirt: report out of bounds"
import json, sys
r = json.load(open(sys.argv[1]))
assert r['flare'] == 'close_darts'
assert abs(r['hip_width_error_mm']) < 2 and abs(r['waist_width_error_mm']) < 2
assert r['area_error_pct'] < 1 and abs(r['garment_waist_girth_error_pct']) < 1
assert r['hem_sweep_mm'] > r['form_hip_girth_mm'] + 300
print('flared skirt: hem sweep %.1f mm' % r['hem_sweep_mm'])
PY
echo "all ok"
