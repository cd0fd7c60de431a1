#!/usr/bin/env bash
# ./drape bench voice: synthesises a command / non-command test set with espeak-ng (several
# voices and speeds), mixes pink and white noise with sox at 10 dB SNR (measured on the speech),
# then runs build/bin/voice_bench, which writes out/bench/voice.json and prints a table.
set -euo pipefail
ROOT="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$ROOT"
BUILD="${DRAPE_BUILD_DIR:-build}"
SET="$BUILD/voice_set"
NOISE="${VOICE_NOISE:-pinknoise}"
mkdir -p "$SET" out/bench
VOICES=(en-us en-us+f3 en-us+m3 en-gb-x-rp en-us+f2)
SPEEDS=(130 170)
COMMANDS=(pinch release pin cut stop map move undo redo)
SENTENCES=("the weather is nice today" "please hand me the scissors" "I think we should go home"
  "where is the red fabric" "can you help me with this" "the dress is almost finished"
  "what time is it now" "this looks really good" "let me see the pattern" "open the window please"
  "how long is the skirt" "we need more thread")
LIST="$SET/list.tsv"
: > "$LIST"
gen() { # out text voice speed
  local out="$1" text="$2" v="$3" s="$4"
  if [ ! -s "$out" ]; then
    espeak-ng -v "$v" -s "$s" -w "$SET/t.wav" "$text"
    sox "$SET/t.wav" -r 16000 -c 1 -b 16 "$SET/s.wav" norm -6
    local rs; rs=$(sox "$SET/s.wav" -n stat 2>&1 | awk '/RMS +amplitude/{print $3}')
    sox "$SET/s.wav" "$SET/c.wav" pad 0.5 0.8
    local d; d=$(soxi -D "$SET/c.wav")
    sox -n -r 16000 -c 1 -b 16 "$SET/n.wav" synth "$d" "$NOISE"
    local rn; rn=$(sox "$SET/n.wav" -n stat 2>&1 | awk '/RMS +amplitude/{print $3}')
    local g; g=$(awk -v a="$rs" -v b="$rn" 'BEGIN{print a/b/10^(10/20)}')
    sox -m -v 1 "$SET/c.wav" -v "$g" "$SET/n.wav" "$out"
  fi
  # speech ends 0.5 s + speech length into the file
  local e; e=$(awk -v a="$(soxi -D "$SET/s.wav" 2>/dev/null || echo 0)" 'BEGIN{print 0.5+a}')
  printf '%s\t%s\t%s\t%s\n' "$out" "$5" "$text" "$e" >> "$LIST"
}
echo "synthesising test set into $SET ($NOISE, 10 dB SNR) ..."
for v in "${VOICES[@]}"; do
  for s in "${SPEEDS[@]}"; do
    for c in "${COMMANDS[@]}"; do gen "$SET/${NOISE}_${v}_${s}_$c.wav" "$c" "$v" "$s" "$c"; done
  done
done
i=0
for t in "${SENTENCES[@]}"; do
  for v in en-us en-us+f3 en-gb-x-rp; do
    i=$((i + 1))
    gen "$SET/${NOISE}_sent_${i}.wav" "$t" "$v" 150 "-"
  done
done
exec "$BUILD/bin/voice_bench" "$LIST" out/bench/voice.json
