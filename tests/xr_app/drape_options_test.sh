#!/usr/bin/env bash
# The options of `drape` and of its form, pattern and render commands (CLI11): --help lists
# every option, bad values and ranges fail with a message naming the option and exit 2, the
# global --assets and --simd options reach the commands.
# usage: drape_options_test.sh DRAPE_EXE
set -u
exe=$1
. "$(cd "$(dirname "$0")" && pwd)/cli_test_lib.sh"
cli_test_setup drape_options_test
expect 0 --assets --simd form pattern render run -- --help
expect 2 -- 
expect 2 "unknown command 'nosuch'" -- nosuch
expect 2 "--simd" -- --simd sse9 form
expect 0 --size --measurements --mesh --units --up --front --spacing --report --export -- form --help
expect 0 --design --form --out --ease --seam-allowance --spacing --relax-iterations \
         --static-solver --no-grain-control -- pattern --help
expect 2 "--spacing" -- form --spacing 1
expect 2 "--units" -- form --units furlong
expect 2 "--size" -- form --size 9AR --mesh form.obj
expect 2 "--spacing" -- pattern --spacing 0
expect 2 "--ease" -- pattern --ease -1
expect 2 "--relax-iterations" -- pattern --relax-iterations many
expect 2 "bogus" -- form bogus
# A value that starts with '-' is still a value; the missing file is the error then.
expect 1 "nonexistent.obj" -- form --up -y --mesh nonexistent.obj
expect 0 "dress form from size 7AR" -- --simd none form --size 7AR
# --assets: the pattern command looks for its design there.
expect 1 "/nonexistent/assets/designs/tight-skirt.json" -- --assets /nonexistent/assets pattern
if "$exe" --help 2>&1 | grep -q "^  render "; then
  expect 0 --scene --out --size --samples --colour-map --eye --target --sim-seconds --solver \
           --window --validation --vk-device -- render --help
  expect 2 "--size" -- render --size 0x5
  expect 2 "--samples" -- render --samples 1000
  expect 2 "--eye" -- render --eye 1,2
  expect 2 "--colour-map" -- render --color-map rainbow
  expect 2 "--sim-seconds" -- render --sim-seconds 0
fi
echo PASS
