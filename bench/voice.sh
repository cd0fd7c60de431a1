#!/usr/bin/env bash
# ./drape bench voice: synthesises two disjoint sets with espeak-ng and mixes pink noise with sox
# at 10 dB SNR (measured on the speech):
#   TUNING set: 4 voices x 2 speeds x the command phrases + 16 non-command sentences x 3 voices;
#   TEST set:   5 OTHER voices x 3 other speeds x the phrases + 20 other sentences x 5 voices,
#               noise taken from another part of the noise recording.
# build/bin/voice_bench --tune picks the filler margin and the duration limit (optionally wip and
# the filler-path length) on the tuning set
# only; the test set is then decoded once with that fixed configuration -> out/bench/voice.json.
# VOICE_PHRASES=assets/voice/words.tsv measures the old one-word commands.
set -euo pipefail
ROOT="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$ROOT"
BUILD="${DRAPE_BUILD_DIR:-build}"
SET="$BUILD/voice_set2"
PHRASES="${VOICE_PHRASES:-assets/voice/phrases.tsv}"
NOISE="${VOICE_NOISE:-pinknoise}"
mkdir -p "$SET" out/bench
# One reproducible noise recording (sox -R); the tuning set uses its first half, the test set
# its second half.
[ -s "$SET/$NOISE.wav" ] || sox -R -n -r 16000 -c 1 -b 16 "$SET/$NOISE.wav" synth 400 "$NOISE"
mapfile -t PHR < <(grep -v '^#' "$PHRASES" | cut -f1)
mapfile -t CMD < <(grep -v '^#' "$PHRASES" | cut -f2)
TUNE_VOICES=(en-us en-us+f3 en-us+m3 en-gb-x-rp)
TUNE_SPEEDS=(130 170)
TEST_VOICES=(en-us+f2 en-us+m1 en-gb en-029 en-us-nyc)
TEST_SPEEDS=(120 150 180)
TUNE_SENT=("the weather is nice today" "please hand me the scissors" "I think we should go home"
  "where is the red fabric" "can you help me with this" "the dress is almost finished"
  "what time is it now" "this looks really good" "let me see the pattern" "open the window please"
  "how long is the skirt" "we need more thread" "the cloth is too long here"
  "I will cut it later" "move a little to the left" "that pin is crooked")
TEST_SENT=("good morning everyone" "the sleeve needs another fitting" "is the kettle on"
  "I like the blue one better" "turn the form around" "that was a long day"
  "she sewed the hem by hand" "pass me the tape measure" "we can finish this tomorrow"
  "the seam allowance is one centimetre" "do you have the pattern paper" "it fits much better now"
  "cut the fabric along the grain" "pin the sleeve to the bodice" "can we undo the last seam"
  "the map is on the table" "stop talking and listen" "please release the brake"
  "move the chair over there" "I need a pinch of salt")
gen() { # list out text voice speed expect noise_offset_s
  local list="$1" out="$2" text="$3" v="$4" s="$5" exp="$6" off="$7"
  local t="$out.t.wav" sp="$out.s.wav" c="$out.c.wav" n="$out.n.wav"
  if [ ! -s "$out" ] || [ ! -s "$sp" ]; then
    espeak-ng -v "$v" -s "$s" -w "$t" "$text"
    sox "$t" -r 16000 -c 1 -b 16 "$sp" norm -6
    local rs; rs=$(sox "$sp" -n stat 2>&1 | awk '/RMS +amplitude/{print $3}')
    sox "$sp" "$c" pad 0.5 0.8
    local d; d=$(soxi -D "$c")
    sox "$SET/$NOISE.wav" "$n" trim "$off" "$d"
    local rn; rn=$(sox "$n" -n stat 2>&1 | awk '/RMS +amplitude/{print $3}')
    local g; g=$(awk -v a="$rs" -v b="$rn" 'BEGIN{print a/b/10^(10/20)}')
    sox -m -v 1 "$c" -v "$g" "$n" "$out"
    rm -f "$t" "$c" "$n"
  fi
  # speech ends 0.5 s + speech length into the file
  local e; e=$(awk -v a="$(soxi -D "$sp")" 'BEGIN{print 0.5+a}')
  printf '%s\t%s\t%s\t%s\n' "$out" "$exp" "$text" "$e" >> "$list"
}
name() { echo "$1" | tr ' +' '__'; }
echo "synthesising tuning and test sets into $SET ($NOISE, 10 dB SNR) ..."
TUNE="$SET/tune.tsv" TEST="$SET/test.tsv"
: > "$TUNE"
: > "$TEST"
k=0
for v in "${TUNE_VOICES[@]}"; do
  for s in "${TUNE_SPEEDS[@]}"; do
    for i in "${!PHR[@]}"; do
      k=$((k + 1))
      gen "$TUNE" "$SET/tune_$(name "$v")_${s}_$(name "${PHR[$i]}").wav" "${PHR[$i]}" "$v" "$s" \
        "${CMD[$i]}" $((k % 190))
    done
  done
done
for t in "${TUNE_SENT[@]}"; do
  for v in en-us en-us+f3 en-gb-x-rp; do
    k=$((k + 1))
    gen "$TUNE" "$SET/tune_sent_$(name "$v")_$(name "$t").wav" "$t" "$v" 150 - $((k % 190))
  done
done
for v in "${TEST_VOICES[@]}"; do
  for s in "${TEST_SPEEDS[@]}"; do
    for i in "${!PHR[@]}"; do
      k=$((k + 1))
      gen "$TEST" "$SET/test_$(name "$v")_${s}_$(name "${PHR[$i]}").wav" "${PHR[$i]}" "$v" "$s" \
        "${CMD[$i]}" $((200 + k % 190))
    done
  done
done
for t in "${TEST_SENT[@]}"; do
  for v in "${TEST_VOICES[@]}"; do
    k=$((k + 1))
    gen "$TEST" "$SET/test_sent_$(name "$v")_$(name "$t").wav" "$t" "$v" 150 - $((200 + k % 190))
  done
done
"$BUILD/bin/voice_bench" --tune "$TUNE" "$SET/tuned.txt" --phrases "$PHRASES" \
  --wips "${VOICE_WIPS:-0.65}" --min-fillers-grid "${VOICE_MIN_FILLERS:-1}" ${VOICE_SINGLE:+--single}
read -r MINF WIP MARGIN MAXS < "$SET/tuned.txt"
exec "$BUILD/bin/voice_bench" "$TEST" "${VOICE_OUT:-out/bench/voice.json}" --phrases "$PHRASES" \
  --min-fillers "$MINF" --wip "$WIP" --margin "$MARGIN" --max-s "$MAXS" ${VOICE_SINGLE:+--single}
