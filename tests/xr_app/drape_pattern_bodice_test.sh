#!/usr/bin/env bash
# `drape pattern --design bodice | dress | dress-flared` from the command line: each report's
# bounds (widths +-2 mm, piece areas +-1 %, sewn girths +-1 %, the dress's waist seams +-2 mm)
# checked from report.json, every exported file read back by a real reader (the DXF by ezdxf,
# both PDFs by pdfinfo, the SVG by rsvg-convert), and a bad bodice design named with nothing
# written.
# usage: drape_pattern_bodice_test.sh DRAPE_EXE
set -u
exe=$1
. "$(cd "$(dirname "$0")" && pwd)/cli_test_lib.sh"
cli_test_setup drape_pattern_bodice_test
# run DESIGN PIECES LEGS...: drape the design, then read its files back; LEGS lists the dart-leg
# lines (DXF layer 8) of each piece's block in order.
run() {
  local design=$1 pieces=$2
  shift 2
  "$exe" pattern --design "$design" --out "$design" >out.txt 2>&1 || fail "drape pattern --design $design"
  grep -q "FAIL" out.txt && fail "$design: a bound failed"
  grep -q "pass sewn bust girth" out.txt || fail "$design: no sewn bust girth check printed"
  /usr/bin/python3 - "$design/pattern.dxf" "$pieces" "$@" <<'PY' || fail "$design: DXF read back"
import sys, ezdxf
doc = ezdxf.readfile(sys.argv[1])
ins = [e for e in doc.modelspace() if e.dxftype() == 'INSERT']
assert len(ins) == int(sys.argv[2]), len(ins)
for i, want in zip(ins, sys.argv[3:]):
    b = doc.blocks[i.dxf.name]
    bd = [e for e in b if e.dxftype() == 'POLYLINE' and e.dxf.layer == '1']
    assert len(bd) == 1 and bd[0].is_closed, i.dxf.name
    legs = sum(1 for e in b if e.dxftype() == 'LINE' and e.dxf.layer == '8')
    assert legs == int(want), (i.dxf.name, legs, want)
    print('%s: %s, %d dart legs' % (sys.argv[1], i.dxf.name, legs))
PY
  for pdf in pattern_a4.pdf pattern_letter.pdf; do
    pdfinfo "$design/$pdf" >pdf.txt 2>&1 || { cat pdf.txt; fail "$design/$pdf: pdfinfo"; }
    grep -q "^Pages:" pdf.txt || fail "$design/$pdf: no pages"
  done
  # The bodice's four darts (two per piece) carry a fold arrow.
  [ "$(grep -c 'class="fold"' "$design/pattern.svg")" = 4 ] || fail "$design: not 4 fold arrows"
  rsvg-convert -o "$design/pattern.png" "$design/pattern.svg" || fail "$design/pattern.svg: rsvg-convert"
  [ -s "$design/pattern.png" ] || fail "$design/pattern.svg: nothing rendered"
  echo "ok: $design"
}
run bodice 2 4 4
run dress 4 4 4 4 4
run dress-flared 4 4 4 0 0
# The reports' bounds, read from report.json (not from the pass flags alone).
/usr/bin/python3 - bodice/report.json dress/report.json dress-flared/report.json <<'PY' || fail "report bounds"
import json, sys
def bodice(r):
    assert len(r['pieces']) == 2
    for p in r['pieces']:
        assert abs(p['bust_width_mm'] - p['bust_arc_mm']) <= 2, p['name']
        assert abs(p['waist_width_mm'] - p['waist_arc_mm']) <= 2, p['name']
        assert abs(p['area_error_pct']) <= 1, p['name']
        assert p['waist_dart']['intake_mm'] > 0 and p['shoulder_dart']['intake_mm'] > 0
    assert abs(r['sewn_bust_girth_mm'] - r['form_bust_girth_mm']) <= 0.01 * r['form_bust_girth_mm']
    assert abs(r['sewn_waist_girth_mm'] - r['form_waist_girth_mm']) <= 0.01 * r['form_waist_girth_mm']
    assert r['all_pass'] and all(c['pass'] for c in r['checks'])
b = json.load(open(sys.argv[1]))
bodice(b)
for path in sys.argv[2:]:
    d = json.load(open(path))
    bodice(d['bodice'])
    assert len(d['waist_mismatch_mm']) == 2
    for k, v in d['waist_mismatch_mm'].items():
        assert abs(v) <= 2, (path, k, v)
    assert abs(d['skirt']['hip_width_error_mm']) <= 2 and abs(d['skirt']['waist_width_error_mm']) <= 2
    assert d['skirt']['area_error_pct'] <= 1
    assert abs(d['skirt']['garment_waist_girth_error_pct']) <= 1
    assert d['all_pass']
    print(path, 'waist seams', d['waist_mismatch_mm'])
PY
# With ease: the bodice's widths and girths follow the eased form (--ease reaches the bodice).
"$exe" pattern --design dress --ease 40 --out eased >out.txt 2>&1 || fail "drape pattern --design dress --ease 40"
grep -q "FAIL" out.txt && fail "dress with 40 mm ease: a bound failed"
/usr/bin/python3 - eased/report.json <<'PY' || fail "dress with ease: report"
import json, sys
d = json.load(open(sys.argv[1]))
b = d['bodice']
assert b['ease_mm'] == 40 and d['all_pass']
assert abs(b['sewn_bust_girth_mm'] - (b['form_bust_girth_mm'] + 40)) <= 0.01 * b['form_bust_girth_mm']
print('eased dress: sewn bust %.1f mm' % b['sewn_bust_girth_mm'])
PY
# A bad bodice design: the file and field named, nothing written.
cat >bad.json <<'JSON'
{"name": "bad", "type": "bodice",
 "pieces": [{"name": "Bodice front", "centre_line": "centre_front", "apex_angle_deg": 95}]}
JSON
"$exe" pattern --design ./bad.json --out bad >out.txt 2>&1 && fail "a bad bodice design was accepted"
grep -qF "bad.json.pieces[0].apex_angle_deg" out.txt || fail "the bad field is not named"
[ ! -e bad ] || fail "an output directory was written for a bad design"
echo '{"name": "bad", "type": "gown"}' >bad2.json
"$exe" pattern --design ./bad2.json --out bad2 >out.txt 2>&1 && fail "an unknown design type was accepted"
grep -qF "bad2.json.type: 'gown'" out.txt || fail "the unknown type is not named"
[ ! -e bad2 ] || fail "an output directory was written for an unknown design type"
echo "all ok"
