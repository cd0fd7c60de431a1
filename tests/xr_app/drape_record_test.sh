#!/usr/bin/env bash
# The session journal end to end (docs/sessions.md): `drape xr --record DIR` plays the scenario
# assets/scenarios/record_replay.json (pinch and pull, pin, cut, undo) on the simulated runtime,
# then `drape replay DIR` rebuilds the World from the journal's header, feeds each recorded input
# at its tick in lock step and must print exactly the final state hash the recorded run printed.
#   free  the recorded run's sim free-running on its own 90 Hz clock (--sim-free)
#   lock  the recorded run in lock step (one tick per frame)
#   kill  lock step, a checkpoint every 0.5 s of session time: recording runs killed with SIGKILL
#         at 20 random points (when its journal reaches a random size). Each killed session is resumed from its newest whole checkpoint
#         and its journal (drape replay): its state at the kill's tick is the one the
#         uninterrupted run's journal replays to from the start at that tick (drape replay
#         --until-tick --from-start), and, given the uninterrupted run's inputs after that tick
#         (its journal's records spliced after the killed journal's whole records), it reaches
#         the uninterrupted run's final state hash. The kills fall after the first checkpoint
#         (from a quarter of the journal on): at least 18 of the 20 resumes must start from a
#         checkpoint (one killed between a checkpoint's journal record and its file's rename
#         starts from the one before; before any file is written, from the start).
#   tee   --record with --voice FILE.wav and --hands trace FILE: audio.wav holds the audio as
#         captured (a prefix of the recording, sample for sample) and hands.csv the external
#         tracker's frames as received (a prefix of the trace, in its format).
#   resume lock step: `drape run --resume DIR` (live, the simulated runtime's window under Xvfb,
#         --frames 40) replays the recording, goes on live and appends to its journal: the
#         journal then replays to the resumed run's final state at tick 300 + 40; a copy cut off
#         mid-record resumes with the cut-off message; a recording with checkpoints resumes from
#         its newest (30 ticks replayed) and its journal then replays to the resumed run's state.
#   save  "save session" spoken (espeak-ng, the scenario's audio cue at frame 150) saves the
#         session whole (saved_session.drape);
#         `drape open FILE` under Xvfb starts from exactly that state and goes on, recorded (its
#         journal replays to it; --from-start is refused); a bad file is an error naming the field.
# free and lock also check that a journal cut off mid-record replays up to its last whole
# record with a message naming the byte offset, and that a bad header is an error naming the
# file and the field. lock records with a checkpoint every 0.5 s: the replay starts from the
# newest, equals the replay from the start, and a newest checkpoint cut off mid-record is named
# (byte offset) and passed over for the one before it, to the same final state. lock and kill
# also record the session without checkpoints: it ends at the same state hash as with them
# (checkpoints hold the solver's state; the sim goes on through them unchanged).
# usage: drape_record_test.sh DRAPE_EXE MODE WORKDIR
set -u
exe=$1 mode=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
log=$work/log.txt
fail() { echo "FAIL: $*"; echo "--- log:"; cat "$log"; exit 1; }
# "HASH TICK" of a live run's log (drape run / drape open).
live_line() { sed -n 's/^drape run: final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$1"; }
unset XR_RUNTIME_JSON DRAPE_MOCK_SCENARIO DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_WRITE_FRAMES
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_CONFIG_DIRS=$work/none
case $mode in
  free) sim=(--sim-free) ;;
  lock | kill) sim=(--checkpoint-every 0.5) ;;
  resume) sim=() ;;
  tee)
    here=$(cd "$(dirname "$0")" && pwd)
    cd "$work" || exit 1
    python3 "$here/hands_trace.py" trace in.csv 0.11 0.65 0.115 || fail "trace writer"
    python3 - <<'PY' || fail "wav writer"
import random, struct, wave
random.seed(1)
w = wave.open("in.wav", "wb")
w.setnchannels(1); w.setsampwidth(2); w.setframerate(16000)
w.writeframes(b"".join(struct.pack("<h", random.randint(-40, 40)) for _ in range(16000 * 4)))
w.close()
PY
    "$exe" xr --frames 120 --eye-size 64 --cloth-res 12 --voice in.wav --hands trace in.csv \
      --record rec >"$log" 2>&1 || fail "drape xr exited with $?"
    python3 - <<'PY' || fail "the tees differ from their inputs"
import sys, wave
a, b = wave.open("rec/audio.wav"), wave.open("in.wav")
n = a.getnframes()
assert (a.getframerate(), a.getnchannels(), a.getsampwidth()) == (16000, 1, 2), "audio.wav format"
assert n > 16000 // 2, f"only {n} samples in audio.wav"
assert a.readframes(n) == b.readframes(n), "audio.wav is not the recording's start"
rec = open("rec/hands.csv").read().splitlines()
src = [l for l in open("in.csv").read().splitlines() if not l.startswith("#")]
assert rec[0] == "# drape-trace v1", rec[0]
assert len(rec) > 10, f"only {len(rec) - 1} frames in hands.csv"
for i, line in enumerate(rec[1:]):
    got = [float(x) for x in line.split(",")]
    want = [float(x) for x in src[i].split(",")]
    assert len(got) == len(want) and all(abs(g - w) < 1e-5 for g, w in zip(got, want)), (line, src[i])
print(f"audio.wav: {n} samples; hands.csv: {len(rec) - 1} frames, as received")
PY
    echo "PASS"
    exit 0
    ;;
  save)
    # "save session" spoken (espeak-ng, 16 kHz) in the scripted lock-step session: the app
    # saves it whole into OUT/saved_session.drape; `drape open FILE` (the simulated runtime's
    # window under Xvfb) goes on draping from exactly that state, recorded.
    command -v xvfb-run >/dev/null || fail "xvfb-run is not installed (Debian xvfb)"
    espeak-ng -s 140 -w "$work/save_22k.wav" "save session" >>"$log" 2>&1 || fail "espeak-ng failed"
    sox "$work/save_22k.wav" -r 16000 -c 1 -b 16 "$work/save.wav" pad 0.2 1 >>"$log" 2>&1 || fail "sox failed"
    # The scenario's audio cue: the spoken phrase at frame 150 (decoded by the app's recogniser).
    repo=$(cd "$(dirname "$0")/../.." && pwd)
    python3 - "$work/save.wav" "$work/save_scenario.json" "$repo/assets/scenarios/record_replay.json" <<'PY' || fail "scenario writer"
import json, sys
s = json.load(open(sys.argv[3]))
s["audio"] = [{"wav": sys.argv[1], "frame": 150, "text": "save session"}]
json.dump(s, open(sys.argv[2], "w"))
PY
    "$exe" xr --scenario "$work/save_scenario.json" --eye-size 64 --cloth-res 16 \
      --record "$work/rec" --out "$work/out" >>"$log" 2>&1 || fail "drape xr exited with $?"
    saved=$work/out/saved_session.drape
    [ -s "$saved" ] || fail "no $saved"
    grep -q "voice .*save" "$work/rec/session.txt" || fail "no save trigger heard"
    n=$(sed -n "s|^save: the session at tick \([0-9]*\) saved to $saved .*|\1|p" "$work/rec/session.txt")
    [ -n "$n" ] || fail "no save line in session.txt"
    want=$("$exe" replay "$work/rec" --until-tick "$n" --from-start --out "$work/a.json" 2>>"$log" |
      sed -n 's/^final state hash \([0-9a-f]*\) at tick.*/\1/p')
    xvfb-run -a "$exe" open "$saved" --frames 40 --sim-lock-step --no-pattern --voice off \
      --out "$work/live" >"$work/open.log" 2>&1
    rc=$?
    cat "$work/open.log" >>"$log"
    [ $rc -eq 0 ] || fail "drape open exited with $rc"
    grep -q "drape open: $saved: the session at tick $n" "$work/open.log" || fail "no open line"
    live=$(live_line "$work/open.log")
    read -r lhash ltick <<<"$live"
    [ "$ltick" = $((n + 40)) ] || fail "the opened session ended at tick '$ltick', not $n + 40"
    sess=$(ls -d "$work"/live/sessions/*/ | head -1)
    [ -f "$sess/journal.bin" ] || fail "the opened session was not recorded"
    got=$("$exe" replay "$sess" --until-tick "$n" --out "$work/b.json" 2>>"$log" |
      sed -n 's/^final state hash \([0-9a-f]*\) at tick.*/\1/p')
    [ -n "$want" ] && [ "$got" = "$want" ] || fail "the opened state $got differs from the saved session's $want at tick $n"
    again=$("$exe" replay "$sess" --out "$work/c.json" 2>>"$log" | sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p')
    [ "$again" = "$live" ] || fail "the opened session's journal replays to '$again', it ended at '$live'"
    "$exe" replay "$sess" --from-start >/dev/null 2>"$work/start.err"
    [ $? -eq 2 ] && grep -q "header field 'opened'" "$work/start.err" || fail "--from-start of an opened session: $(cat "$work/start.err")"
    printf 'not a checkpoint' >"$work/bad.drape"
    xvfb-run -a "$exe" open "$work/bad.drape" --frames 5 >"$work/bad.log" 2>&1
    [ $? -eq 2 ] && grep -q "$work/bad.drape: byte 0: field 'magic'" "$work/bad.log" || fail "bad file: $(cat "$work/bad.log")"
    echo "saved at tick $n: $want; opened: the same state, on to $live (its journal replays to it)"
    echo "PASS"
    exit 0
    ;;
  *) echo "usage: drape_record_test.sh DRAPE_EXE free|lock|kill|resume|tee|save WORKDIR"; exit 2 ;;
esac
rec=$work/rec
"$exe" xr --scenario assets/scenarios/record_replay.json --eye-size 64 --cloth-res 16 \
  --record "$rec" "${sim[@]}" >"$log" 2>&1
rc=$?
[ $rc -eq 0 ] || fail "drape xr exited with $rc"
journal_bytes=$(stat -c %s "$rec/journal.bin")
for f in journal.bin meta.json session.txt; do
  [ -s "$rec/$f" ] || fail "missing $rec/$f"
done
recorded=$(sed -n 's/^drape xr: final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$log")
[ -n "$recorded" ] || fail "the recorded run printed no final state hash"
read -r rhash rtick <<<"$recorded"
echo "recorded: state hash $rhash at tick $rtick"
# The session did what the scenario asks: a pin, a cut, an undo.
grep -q "pinned_added [1-9]" "$rec/session.txt" || fail "no pin in $rec/session.txt"
grep -q "^sim: cut: .* pieces" "$rec/session.txt" || fail "no cut in $rec/session.txt"
grep -q -- "-> undo" "$rec/session.txt" || fail "no undo trigger in $rec/session.txt"
grep -q "\"final_state_hash\": \"$rhash\"" "$rec/meta.json" || fail "meta.json lacks the final hash"
if [ "$mode" = lock ] || [ "$mode" = kill ]; then
  "$exe" xr --scenario assets/scenarios/record_replay.json --eye-size 64 --cloth-res 16 \
    --record "$work/no_checkpoints" --checkpoint-every 0 >"$work/nock.log" 2>&1 ||
    fail "drape xr --checkpoint-every 0 exited with $?"
  nock=$(sed -n 's/^drape xr: final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$work/nock.log")
  ls "$work/no_checkpoints" | grep -q checkpoint && fail "checkpoints written with --checkpoint-every 0"
  [ "$nock" = "$rhash $rtick" ] ||
    fail "without checkpoints the session ends at '$nock', with a checkpoint every 0.5 s at '$rhash $rtick'"
  echo "without checkpoints: the same final state $nock"
fi

"$exe" replay "$rec" >"$work/replay.out" 2>"$work/replay.err"
rc=$?
cat "$work/replay.err" "$work/replay.out" >>"$log"
[ $rc -eq 0 ] || fail "drape replay exited with $rc"
replayed=$(sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$work/replay.out")
echo "replayed: state hash $replayed"
[ "$replayed" = "$rhash $rtick" ] || fail "replay gave '$replayed', the recorded run '$rhash $rtick'"
grep -q "\"final_state_hash\": \"$rhash\"" "$rec/replay.json" || fail "replay.json lacks the hash"

if [ "$mode" = resume ]; then
  command -v xvfb-run >/dev/null || fail "xvfb-run is not installed (Debian xvfb)"
  resume_run() {  # resume_run DIR LOG: drape run --resume DIR, 40 live lock-step frames
    xvfb-run -a "$exe" run --resume "$1" --frames 40 --sim-lock-step --no-pattern --voice off \
      --out "$work/live" >"$2" 2>&1
  }
  cut=$work/cut_resume
  cp -r "$rec" "$work/resumed" && cp -r "$rec" "$cut"
  resume_run "$work/resumed" "$work/resume.log"
  rc=$?
  cat "$work/resume.log" >>"$log"
  [ $rc -eq 0 ] || fail "drape run --resume exited with $rc"
  grep -q "resume: replayed 300 input records, 300 ticks" "$work/resume.log" || fail "no replay line"
  live=$(live_line "$work/resume.log")
  read -r lhash ltick <<<"$live"
  [ "$ltick" = 340 ] || fail "the resumed run ended at tick '$ltick', not 300 + 40"
  "$exe" replay "$work/resumed" >"$work/resumed.out" 2>&1 || fail "replay of the resumed journal exited with $?"
  again=$(sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$work/resumed.out")
  echo "resumed run: $live; its journal replayed: $again"
  [ "$again" = "$lhash $ltick" ] || fail "the resumed journal replays to '$again', the run ended at '$live'"
  size=$(stat -c %s "$cut/journal.bin")
  head -c $((size - 40)) "$rec/journal.bin" >"$cut/journal.bin"  # the end record and part of the last tick's
  resume_run "$cut" "$work/cut_resume.log"
  rc=$?
  cat "$work/cut_resume.log" >>"$log"
  [ $rc -eq 0 ] || fail "drape run --resume of a cut-off journal exited with $rc"
  grep -q "$cut/journal.bin: byte [0-9]*: .*cut off" "$work/cut_resume.log" || fail "no cut-off message"
  grep -q "resume: replayed 299 input records, 299 ticks" "$work/cut_resume.log" || fail "the cut journal did not replay to its last whole record"
  # A recording with checkpoints (every 0.5 s): the resume starts from the newest, replays the
  # 30 ticks after it, goes on live; the journal then replays to the resumed run's state from
  # its checkpoint and from the start alike.
  ckr=$work/checkpointed
  "$exe" xr --scenario assets/scenarios/record_replay.json --eye-size 64 --cloth-res 16 \
    --record "$ckr" --checkpoint-every 0.5 >>"$log" 2>&1 || fail "drape xr --checkpoint-every exited with $?"
  resume_run "$ckr" "$work/ck_resume.log"
  rc=$?
  cat "$work/ck_resume.log" >>"$log"
  [ $rc -eq 0 ] || fail "drape run --resume of the checkpointed recording exited with $rc"
  grep -q "resume: from checkpoint-270.bin (tick 270)" "$work/ck_resume.log" || fail "the resume did not start from checkpoint-270.bin"
  grep -q "resume: replayed 30 input records, 300 ticks" "$work/ck_resume.log" || fail "no replay of the 30 ticks after the checkpoint"
  live=$(live_line "$work/ck_resume.log")
  for from in "" --from-start; do
    "$exe" replay "$ckr" $from --out "$work/ck.json" >"$work/ck.out" 2>&1 || fail "replay $from of the resumed journal exited with $?"
    again=$(sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$work/ck.out")
    [ "$again" = "$live" ] || fail "the resumed journal replays ($from) to '$again', the run ended at '$live'"
  done
  echo "resumed from checkpoint-270.bin: $live; its journal replays to it from the checkpoint and from the start"
  echo "PASS"
  exit 0
fi

if [ "$mode" = kill ]; then
  here=$(cd "$(dirname "$0")" && pwd)
  # One killed run: SIGKILL once its journal has grown to $2 bytes (a point of the session that
  # does not depend on the machine's load), its session resumed (replayed from its newest whole
  # checkpoint and its journal) and compared with the uninterrupted run; 1 when the run ended
  # before the kill or had recorded no input yet (nothing to compare).
  kill_once() {  # kill_once N BYTES
    local k=$work/kill$1 l=$work/kill$1
    "$exe" xr --scenario assets/scenarios/record_replay.json --eye-size 64 --cloth-res 16 \
      --record "$k" "${sim[@]}" >"$l.log" 2>&1 &
    local pid=$!
    while kill -0 $pid 2>/dev/null &&
      [ "$(stat -c %s "$k/journal.bin" 2>/dev/null || echo 0)" -lt "$2" ]; do
      sleep 0.01
    done
    kill -KILL $pid 2>/dev/null
    wait $pid 2>/dev/null
    grep -q "^drape xr: final state hash" "$l.log" && return 1  # ended first
    [ -f "$k/journal.bin" ] || return 1  # killed before the journal was opened
    "$exe" replay "$k" >"$l.out" 2>"$l.err" ||
      fail "replay of the journal killed at $2 bytes exited with $?: $(cat "$l.err")"
    local got khash ktick want
    got=$(sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$l.out")
    read -r khash ktick <<<"$got"
    [ -n "$ktick" ] || fail "no hash from the killed journal's replay"
    [ "$ktick" -gt 0 ] || return 1  # killed before its first input record
    "$exe" replay "$rec" --until-tick "$ktick" --from-start --out "$l.until.json" >"$l.until" 2>&1 ||
      fail "replay --until-tick $ktick exited with $?"
    want=$(sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$l.until")
    [ "$want" = "$khash $ktick" ] || fail "killed journal's state $khash at $ktick != uninterrupted $want"
    # The resumed session goes on with the uninterrupted run's inputs from the kill's tick on.
    python3 "$here/journal_splice.py" "$k/journal.bin" "$rec/journal.bin" "$ktick" \
      "$k/journal.bin" || fail "journal splice"
    "$exe" replay "$k" >"$l.cont.out" 2>"$l.cont.err" ||
      fail "the resumed session after the kill at tick $ktick: $(cat "$l.cont.err")"
    local final from
    final=$(sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p' "$l.cont.out")
    [ "$final" = "$rhash $rtick" ] || fail "resumed after the kill at $ktick: '$final', uninterrupted '$rhash $rtick'"
    from=$(sed -n 's/^drape replay: from \(checkpoint-[0-9]*.bin\).*/\1/p' "$l.err")
    echo "killed at $2 journal bytes, tick $ktick: $khash (uninterrupted: the same); resumed from ${from:-the start}: final $final"
    [ -n "$from" ] && from_checkpoint=$((from_checkpoint + 1))
    return 0
  }
  killed=0 tries=0 from_checkpoint=0
  while [ $killed -lt 20 ] && [ $tries -lt 40 ]; do
    tries=$((tries + 1))
    at=$(awk -v t="$journal_bytes" -v r="$RANDOM" 'BEGIN { printf "%d", t * (0.25 + 0.6 * r / 32768) }')
    kill_once $tries "$at" && killed=$((killed + 1))
  done
  [ $killed -ge 20 ] || fail "only $killed of $tries runs were killed mid-session"
  echo "$killed kills, $from_checkpoint resumed from a checkpoint"
  [ $from_checkpoint -ge 18 ] || fail "only $from_checkpoint of $killed resumes started from a checkpoint"
  echo "PASS"
  exit 0
fi

if [ "$mode" = lock ]; then
  # Checkpoints every 0.5 s (45 ticks): the replay starts from the newest and equals the replay
  # from the start; the newest cut off mid-record is named and passed over for the one before.
  newest=$(ls "$rec" | sed -n 's/^checkpoint-\([0-9]*\)\.bin$/\1/p' | sort -n | tail -1)
  [ -n "$newest" ] || fail "no checkpoint file in $rec"
  grep -q "^drape replay: from checkpoint-$newest.bin (tick $newest)" "$work/replay.err" ||
    fail "the replay did not start from checkpoint-$newest.bin"
  "$exe" replay "$rec" --from-start --out "$work/start.json" >"$work/start.out" 2>&1 ||
    fail "drape replay --from-start exited with $?"
  grep -q "^final state hash $rhash at tick $rtick$" "$work/start.out" || fail "--from-start: $(cat "$work/start.out")"
  ck=$work/cut_checkpoint
  cp -r "$rec" "$ck"
  size=$(stat -c %s "$rec/checkpoint-$newest.bin")
  head -c $((size / 2)) "$rec/checkpoint-$newest.bin" >"$ck/checkpoint-$newest.bin"
  "$exe" replay "$ck" >"$work/ck.out" 2>"$work/ck.err" || fail "replay with a cut-off checkpoint exited with $?: $(cat "$work/ck.err")"
  cat "$work/ck.err" >>"$log"
  grep -q "$ck/checkpoint-$newest.bin: byte [0-9]*: .*the checkpoint is cut off there" "$work/ck.err" ||
    fail "no cut-off message for the checkpoint: $(cat "$work/ck.err")"
  grep -q "^drape replay: from checkpoint-$((newest - 45)).bin" "$work/ck.err" ||
    fail "the replay did not fall back to checkpoint-$((newest - 45)).bin: $(cat "$work/ck.err")"
  grep -q "^final state hash $rhash at tick $rtick$" "$work/ck.out" || fail "cut checkpoint: $(cat "$work/ck.out")"
  echo "checkpoints: from checkpoint-$newest.bin, from the start, and past a cut-off one: $rhash"
fi

# A journal cut off mid-record: the replay loads its whole records and says where it stops.
cut=$work/cut
mkdir -p "$cut"
size=$(stat -c %s "$rec/journal.bin")
head -c $((size - 13)) "$rec/journal.bin" >"$cut/journal.bin"
"$exe" replay "$cut" >"$work/cut.out" 2>"$work/cut.err"
rc=$?
cat "$work/cut.err" >>"$log"
[ $rc -eq 0 ] || fail "the cut-off journal's replay exited with $rc"
grep -q "$cut/journal.bin: byte [0-9]*: .*cut off" "$work/cut.err" ||
  fail "no cut-off message naming the byte offset: $(cat "$work/cut.err")"
grep -q "^final state hash [0-9a-f]* at tick [0-9]*$" "$work/cut.out" || fail "no hash for the cut journal"

# A bad header: an error naming the file and the field, exit 2.
bad=$work/bad
mkdir -p "$bad"
printf 'NOTAJRNL\001\000\000\000' >"$bad/journal.bin"
"$exe" replay "$bad" >/dev/null 2>"$work/bad.err"
rc=$?
cat "$work/bad.err" >>"$log"
[ $rc -eq 2 ] || fail "a bad header's replay exited with $rc, not 2"
grep -q "$bad/journal.bin: header field 'magic'" "$work/bad.err" || fail "bad header message: $(cat "$work/bad.err")"
# A whole header whose field cannot describe a session: the file and the field named, exit 2.
python3 - "$rec/journal.bin" "$bad/journal.bin" <<'PY' || fail "journal rewriter"
import struct, sys, zlib
d = open(sys.argv[1], "rb").read()
n, = struct.unpack_from("<I", d, 12)
p = d[20:20 + n]
count, = struct.unpack_from("<I", p, 1)
fields, i = {}, 5
for _ in range(count):
    kl, = struct.unpack_from("<I", p, i); k = p[i + 4:i + 4 + kl].decode(); i += 4 + kl
    vl, = struct.unpack_from("<I", p, i); v = p[i + 4:i + 4 + vl].decode(); i += 4 + vl
    fields[k] = v
fields["resolution"] = "9999"
q = bytes([1]) + struct.pack("<I", len(fields))
for k, v in sorted(fields.items()):
    q += struct.pack("<I", len(k)) + k.encode() + struct.pack("<I", len(v)) + v.encode()
open(sys.argv[2], "wb").write(d[:12] + struct.pack("<II", len(q), zlib.crc32(q)) + q + d[20 + n:])
PY
"$exe" replay "$bad" >/dev/null 2>"$work/field.err"
rc=$?
cat "$work/field.err" >>"$log"
[ $rc -eq 2 ] || fail "a bad header field's replay exited with $rc, not 2"
grep -q "$bad/journal.bin: header field 'resolution': '9999'" "$work/field.err" ||
  fail "bad field message: $(cat "$work/field.err")"
echo "PASS"
