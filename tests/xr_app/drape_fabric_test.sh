#!/usr/bin/env bash
# `drape fabric test|calibrate`: bad input fails with a message naming what is wrong (unknown
# preset, missing or broken fabrics file, out-of-range numbers, a disc wider than the specimen),
# a coarse drape test writes its shadow PNG, glTF and R(theta) CSV and prints DC and nodes, and a
# calibrated preset written with --out drapes again from that file.
# usage: drape_fabric_test.sh DRAPE_EXE
set -u
exe=$1
. "$(cd "$(dirname "$0")" && pwd)/cli_test_lib.sh"
cli_test_setup drape_fabric_test
expect 0 test calibrate -- fabric --help
expect 0 --fabric --specimen --disc --resolution --seed --seeds --out -- fabric test --help
expect 0 --density --dc --nodes --rmin --rmax --out -- fabric calibrate --help
expect 2 "A subcommand is required" -- fabric
expect 2 "--fabric" -- fabric test
expect 1 "no preset 'nosuch'" "muslin" -- fabric test --fabric nosuch
expect 1 "missing.json: no such file" -- fabric test --fabric missing.json
printf '{"broken": {"areal_density": -1}}' > bad.json
expect 1 "bad.json" "broken.areal_density" -- fabric test --fabric bad.json
printf '{ not json' > notjson.json
expect 1 "notjson.json" "invalid JSON" -- fabric test --fabric notjson.json
expect 2 "--density" -- fabric calibrate --density -5 --dc 0.5
expect 2 "--density" -- fabric calibrate --density abc --dc 0.5
expect 2 "--dc" -- fabric calibrate --density 120 --dc 1.5
expect 2 "--dc" "--photo" -- fabric calibrate --density 120
expect 2 "--dc" "--photo" -- fabric calibrate --density 120 --dc 0.5 --photo x.png
expect 2 "--rmin and --rmax go together" -- fabric calibrate --density 120 --dc 0.5 --rmin 100
expect 2 "R_min below R_max" -- fabric calibrate --density 120 --dc 0.5 --rmin 140 --rmax 100
printf 'not a picture' > junk.png
expect 1 "junk.png: cannot read it as an image" -- fabric calibrate --density 120 --photo junk.png
expect 2 "--resolution" -- fabric test --fabric muslin --resolution 2
expect 1 "disc diameter" -- fabric test --fabric muslin --disc 0.4
# A coarse drape: figures printed, files written.
expect 0 "DC 0." "nodes" "mean over 2 drapes" "face up / face down" -- \
  fabric test --fabric muslin --resolution 6 --seeds 2 --out res
for f in seed1_shadow.png seed1_drape.gltf seed1_drape.bin seed1_profile.csv seed2_shadow.png; do
  [ -s "res/$f" ] || fail "res/$f not written"
done
[ "$(wc -l < res/seed1_profile.csv)" -eq 361 ] || fail "R(theta) CSV has not 360 bins"
head -c 8 res/seed1_shadow.png | od -An -c | grep -q "P   N   G" || fail "shadow is not a PNG"
# Calibration into a new fabrics file, then the preset drapes from it.
expect 0 "fitted in" "residual" "predicted: nodes" "wrote preset 'mine'" -- \
  fabric calibrate --density 120 --dc 0.5 --nodes 8 --resolution 6 --seeds 1 --name mine --out my.json
expect 0 "fabric mine: 120 g/m^2" -- fabric test --fabric my.json:mine --resolution 6 --out res2
expect 0 "fabric mine" -- fabric test --fabric my.json --resolution 6 --out res3
# The warp/weft ratio fitted to a fold depth too: a second fit of B at the ratio found.
expect 0 "warp/weft 1.60" "fold depth R_max - R_min" "measured 30.0" "wrote preset 'deep'" -- \
  fabric calibrate --density 120 --dc 0.5 --rmin 110 --rmax 140 --resolution 6 --seeds 1 \
  --name deep --out my.json
grep -q '"deep"' my.json && grep -q '"mine"' my.json || fail "my.json lacks 'deep' or 'mine'"
grep -q 'fold depth measured 30.0 mm' my.json || fail "the preset's source lacks the fold depth"
ratio=$(sed -n 's/.*(ratio \([0-9.]*\)).*/\1/p' out.txt)
awk -v r="$ratio" 'BEGIN { exit !(r != "" && r >= 1 && r <= 4) }' || fail "fitted ratio '$ratio' not in [1, 4]"
# The tester's own shadow image as a photo: the drape dark on white, the specimen's circle
# printed around it. Its DC is the drape's (printed by the test above) within 0.01.
expect 0 "photo res/seed1_shadow.png" "fitted in" -- \
  fabric calibrate --photo res/seed1_shadow.png --density 130 --resolution 6 --seeds 1
photo_dc=$(sed -n 's/^photo .*, DC \([0-9.]*\),.*/\1/p' out.txt)
"$exe" fabric test --fabric muslin --resolution 6 --out res4 > test.txt 2>&1
drape_dc=$(sed -n 's/^seed 1 *DC \([0-9.]*\) .*/\1/p' test.txt)
awk -v a="$photo_dc" -v b="$drape_dc" 'BEGIN { d = a - b; exit !(a != "" && b != "" && d < 0.01 && d > -0.01) }' ||
  fail "photo DC '$photo_dc' is not the drape's DC '$drape_dc'"
echo "ok: photo DC $photo_dc, drape DC $drape_dc"
# A broken file is not overwritten by --out.
cp notjson.json keep.json
expect 1 "keep.json: invalid JSON, not overwritten" -- \
  fabric calibrate --density 120 --dc 0.5 --resolution 6 --seeds 1 --out keep.json
cmp -s keep.json notjson.json || fail "keep.json was changed"
echo "all fabric CLI checks passed"
