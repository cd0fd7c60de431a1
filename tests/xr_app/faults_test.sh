#!/usr/bin/env bash
# Faults injected into a real `drape xr` run on the simulated runtime, one mode a ctest
# (docs/faults.md has the table of what the user sees and what is kept):
#   packets      the right palm over a real UDP socket with 20 % of the packets dropped, some
#                reordered, duplicated, and garbage mixed in (faulty_hands.py): the pinch, the
#                release and the pinch's end still happen; the log counts the bad packets.
#   session_loss the runtime loses the XR session while the right hand holds a pinch (scenario
#                event session_loss): the pinch ends at the loss where the hand held it (not
#                where the next session puts the hand), the session is re-created, the run ends
#                normally, the cloth and its outputs are kept (the same tick count).
#   mic_gone     --voice mic through ALSA (a `file` PCM reading a tone) unplugged after 0.5 s:
#                snd_pcm_readi returns -ENODEV (fault_inject.so): a voice message naming the
#                microphone, the session goes on, the cloth the same as with --voice off.
#   device_lost  vkWaitForFences returns VK_ERROR_DEVICE_LOST from the 20th frame on
#                (fault_inject.so): one render message naming it, every frame still run, the
#                cloth the same as without the fault, all outputs written.
#   disk_full    the outputs' folder full (ENOSPC from the first byte, and after 3000 bytes)
#                while the session log, the glTF and xr_session.txt are written: a message
#                naming each file, exit 0, the previous run's files there byte for byte.
#   disk_full_pattern  `drape pattern --out DIR` over an earlier pattern with the disk full (from
#                the first byte, and after 100000 bytes): exit 1, a message naming the file and
#                saying the earlier files are kept; they are, byte for byte.
#   journal_full the recording's folder full (--record DIR): without checkpoints, the journal's
#                write fails after 12000 bytes: a message says the recording stopped, the session
#                goes on to the same cloth as an unrecorded run, the journal's whole records replay;
#                with a checkpoint every 0.5 s, the first checkpoint's file cannot be written: a
#                message names it, no partial file is left, the journal's whole records replay to
#                the state of a recording without the fault at the same tick.
# usage: faults_test.sh DRAPE_EXE FAULT_INJECT_SO MODE WORKDIR [PORT]
set -u
exe=$1 inject=$2 mode=$3 work=$4 port=${5:-0}
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
log=$work/log.txt
: >"$log"
fail() { echo "FAIL: $*"; echo "--- log:"; cat "$log"; exit 1; }
unset XR_RUNTIME_JSON DRAPE_MOCK_SCENARIO DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_WRITE_FRAMES
unset DRAPE_MOCK_FAST DRAPE_MOCK_WINDOW DRAPE_MOCK_LOSE_SESSION_AT_FRAME
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_CONFIG_DIRS=$work/none
mkdir -p "$HOME"

# The right hand reaches the muslin, pinches it (near frame 82) and holds it against the form
# until the end. scenario FRAMES FAST [EVENTS-JSON]
scenario() {
  cat >"$work/scenario.json" <<JSON
{"name": "fault", "end_after_frames": $1, "fast": $2,
 "interaction_profile": "/interaction_profiles/oculus/touch_controller",
 "head": [{"frame": 0, "position": [0.0, 1.45, 1.1], "orientation": [-0.0872, 0, 0, 0.9962]}],
 "hands": {"right": [
   {"frame": 0, "palm": {"position": [0.3, 1.0, 0.6]}, "pinch": 0.0},
   {"frame": 60, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 0.0},
   {"frame": 66, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 0.0},
   {"frame": 76, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 1.0},
   {"frame": 88, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 1.0},
   {"frame": 110, "palm": {"position": [0.12, 1.04, 0.21]}, "pinch": 1.0},
   {"frame": 2000, "palm": {"position": [0.12, 1.04, 0.21]}, "pinch": 1.0}]},
 "events": [${3:-}]}
JSON
}

# run NAME ARGS...: `drape xr` on the scenario into $work/NAME; sets rc and out.
run() {
  local name=$1; shift
  out=$work/$name
  "$exe" xr --scenario "$work/scenario.json" --eye-size 64 --cloth-res 12 --out "$out" -v "$@" \
    >"$work/$name.txt" 2>&1
  rc=$?
  { echo "--- drape xr $* (exit $rc)"; cat "$work/$name.txt"; } >>"$log"
}

# The run ended normally with every frame and all three outputs.
check_complete() {
  [ $rc -eq 0 ] || fail "$1: exit code $rc"
  grep -q "^drape xr: exiting" "$work/$1.txt" || fail "$1: the session did not end normally"
  for f in session_log.json drape_cloth.gltf xr_session.txt; do
    [ -s "$work/$1/$f" ] || fail "$1: $f not written"
  done
}

same_cloth() {
  cmp -s "$work/$1/drape_cloth.gltf" "$work/$2/drape_cloth.gltf" && cmp -s "$work/$1/drape_cloth.bin" "$work/$2/drape_cloth.bin" ||
    fail "the cloth of $1 differs from $2's"
  echo "cloth of '$1' identical to '$2'"
}

case $mode in
  packets)
    cat >"$work/scenario.json" <<JSON
{"name": "external_hands", "end_after_frames": 1000, "fast": false,
 "head": [{"frame": 0, "position": [0.0, 1.6, 1.0], "orientation": [0, 0, 0, 1]}]}
JSON
    "$exe" xr --eye-size 64 --cloth-res 12 --scenario "$work/scenario.json" --out "$work/out" -v \
      --hands "udp:127.0.0.1:$port" >"$log" 2>&1 &
    app=$!
    for _ in $(seq 1 300); do grep -q "hands: udp: no packets yet" "$log" && break; sleep 0.1; done
    grep -q "hands: udp: no packets yet on 127.0.0.1:$port" "$log" || { kill "$app"; fail "the app is not listening"; }
    PYTHONPATH=$here python3 "$here/faulty_hands.py" 127.0.0.1 "$port" 0.11 1.15 0.115 >"$work/sender.txt" 2>&1 ||
      { kill "$app"; cat "$work/sender.txt"; fail "sender"; }
    cat "$work/sender.txt"
    wait "$app"
    rc=$?
    [ $rc -eq 0 ] || fail "exit code $rc"
    s=$work/out/xr_session.txt
    [ -s "$s" ] || fail "no xr_session.txt"
    grep -q "pinch: right hand took particle" "$s" || fail "the pinch took no particle"
    grep -q "gesture dwell begin hand right -> release" "$s" || fail "no dwell -> release"
    grep -q "pinch: right hand let particle .* go" "$s" || fail "the pinch never let go"
    grep -q "hands: udp: .* packets dropped (.* malformed, .* out of order), last: " "$log" ||
      fail "no message about the dropped packets"
    grep -m1 "packets dropped" "$log"
    ;;
  session_loss)
    scenario 300 true '{"frame": 150, "type": "session_loss"}'
    run lost
    check_complete lost
    grep -q "sessions 2 (lost 1)" "$work/lost.txt" || fail "the session was not lost and re-created"
    grep -q "pinch: right hand took particle" "$work/lost/xr_session.txt" || fail "no pinch before the loss"
    s=$work/lost/xr_session.txt
    grep -q "^session lost: the operations in progress end here (stop); the cloth is kept" "$s" ||
      fail "no message about the operations ended at the loss"
    # The pinch ends where the hand held it, not where the next session puts the hand.
    let_go=$(sed -n '/^session lost: /,$p' "$s" | grep -m1 "pinch: right hand let particle .* go") ||
      fail "the pinch was not let go after the loss"
    echo "$let_go"
    mm=$(sed -n 's/.*(moved \([0-9.]*\) mm).*/\1/p' <<<"$let_go")
    python3 -c "import sys; sys.exit(0 if float('$mm') < 50 else 1)" ||
      fail "the pinched particle moved $mm mm: carried across the loss"
    scenario 300 true
    run reference
    check_complete reference
    a=$(grep -o "^frames [0-9]*" "$work/lost/xr_session.txt")
    b=$(grep -o "^frames [0-9]*" "$work/reference/xr_session.txt")
    [ "$a" = "$b" ] || fail "frames after the loss: '$a', without: '$b'"
    echo "the same frames with and without the loss: $a"
    ;;
  mic_gone)
    scenario 180 false
    sox -n -r 16000 -c 1 -b 16 -e signed-integer "$work/mic.raw" synth 10 sine 300 vol 0.1 >>"$log" 2>&1 ||
      fail "sox failed"
    cat >"$work/asound.conf" <<EOF
pcm.!default {
  type file
  slave.pcm { type null }
  file "/dev/null"
  infile "$work/mic.raw"
  format "raw"
}
EOF
    export ALSA_CONFIG_PATH=$work/asound.conf
    DRAPE_FAULT_PCM_GONE_AFTER=8000 LD_PRELOAD=$inject run gone --voice mic
    unset ALSA_CONFIG_PATH
    check_complete gone
    grep -q "fault_inject: snd_pcm_readi: -ENODEV" "$work/gone.txt" || fail "the capture never failed"
    grep -q "^voice: listening to microphone (ALSA 'default')" "$work/gone/xr_session.txt" ||
      fail "the microphone was not opened"
    line=$(grep "^voice: .*microphone 'default'.*voice commands are off" "$work/gone/xr_session.txt") ||
      fail "no voice message naming the microphone"
    echo "$line"
    run reference --voice off
    check_complete reference
    same_cloth gone reference
    ;;
  device_lost)
    scenario 120 true
    run reference
    check_complete reference
    DRAPE_FAULT_VK_LOST_AFTER=20 LD_PRELOAD=$inject run lost
    check_complete lost
    grep -q "fault_inject: vkWaitForFences: VK_ERROR_DEVICE_LOST" "$work/lost.txt" || fail "the device was never lost"
    n=$(grep -c "^render: .*VK_ERROR_DEVICE_LOST" "$work/lost/xr_session.txt")
    [ "$n" -eq 1 ] || fail "$n render messages about the lost device in xr_session.txt, expected 1"
    grep "^render: " "$work/lost/xr_session.txt"
    grep -q "frames 120 (" "$work/lost.txt" || fail "not every frame ran"
    same_cloth lost reference
    ;;
  disk_full)
    scenario 100 true
    run before
    check_complete before
    cp -r "$work/before" "$work/kept"
    scenario 140 true
    for after in 0 3000; do
      DRAPE_FAULT_ENOSPC_MATCH="$work/before/" DRAPE_FAULT_ENOSPC_AFTER=$after LD_PRELOAD=$inject run before
      [ $rc -eq 0 ] || fail "disk full after $after bytes: exit code $rc"
      grep -q "fault_inject: ENOSPC" "$work/before.txt" || fail "the disk was never full"
      for what in "session log" "glTF" "session text"; do
        grep -q "^drape: $what not saved: $work/before/[a-z_]*\.[a-z]*: .*(the previous file, if any, is kept)" "$work/before.txt" ||
          fail "disk full after $after bytes: no message for the $what"
      done
      grep "^drape: .* not saved" "$work/before.txt"
      for f in session_log.json drape_cloth.gltf drape_cloth.bin xr_session.txt; do
        cmp -s "$work/kept/$f" "$work/before/$f" || fail "disk full after $after bytes: $f changed"
      done
      [ -e "$work/before/.partial" ] && fail "the partial folder was left behind"
      echo "disk full after $after bytes: the previous outputs kept byte for byte"
    done
    run before
    check_complete before
    cmp -s "$work/kept/xr_session.txt" "$work/before/xr_session.txt" && fail "the run with room did not replace the outputs"
    grep -q "^frames 140 " "$work/before/xr_session.txt" || fail "the run with room: not its outputs"
    echo "with room again, the outputs are replaced"
    ;;
  journal_full)
    scenario 140 true
    run reference
    check_complete reference
    replay_hash() {  # replay_hash DIR [ARGS]: "HASH TICK" of drape replay
      local d=$1; shift
      "$exe" replay "$d" "$@" --out "$work/r.json" 2>>"$log" |
        sed -n 's/^final state hash \([0-9a-f]*\) at tick \([0-9]*\)$/\1 \2/p'
    }
    DRAPE_FAULT_ENOSPC_MATCH="$work/rec/" DRAPE_FAULT_ENOSPC_AFTER=12000 LD_PRELOAD=$inject \
      run full --record "$work/rec" --checkpoint-every 0
    check_complete full
    grep -q "fault_inject: ENOSPC" "$work/full.txt" || fail "the disk was never full"
    grep -q "journal: .*cannot .* the journal.*(recording stopped)" "$work/full/xr_session.txt" ||
      fail "no message that the recording stopped"
    grep "journal: " "$work/full/xr_session.txt" | head -1
    same_cloth full reference
    got=$(replay_hash "$work/rec")
    [ -n "$got" ] || fail "the journal's whole records do not replay"
    echo "the journal's whole records replay: $got"
    # With checkpoints: the first checkpoint's file does not fit.
    run recorded --record "$work/rec_ok" --checkpoint-every 0.5
    check_complete recorded
    DRAPE_FAULT_ENOSPC_MATCH="$work/rec_ck/" DRAPE_FAULT_ENOSPC_AFTER=20000 LD_PRELOAD=$inject \
      run full_ck --record "$work/rec_ck" --checkpoint-every 0.5
    check_complete full_ck
    grep -q "checkpoint: $work/rec_ck/checkpoint-45.bin: cannot write the checkpoint" "$work/full_ck/xr_session.txt" ||
      fail "no message naming the checkpoint that could not be written"
    ls "$work/rec_ck" | grep -q "checkpoint-" && fail "a checkpoint file or its partial file was left"
    got=$(replay_hash "$work/rec_ck")
    read -r _ tick <<<"$got"
    want=$(replay_hash "$work/rec_ok" --until-tick "$tick" --from-start)
    [ -n "$got" ] && [ "$got" = "$want" ] || fail "the journal kept replays to '$got', the recording without the fault to '$want'"
    echo "checkpoint not written, named; the journal's records replay to $got as without the fault"
    ;;
  disk_full_pattern)
    pattern() { "$exe" pattern --design tight-skirt --form 9AR --out "$work/pattern" "$@"; }
    pattern >"$work/first.txt" 2>&1 || { cat "$work/first.txt" >>"$log"; fail "first pattern: exit $?"; }
    cp -r "$work/pattern" "$work/kept"
    for after in 0 100000; do
      DRAPE_FAULT_ENOSPC_MATCH="$work/pattern/" DRAPE_FAULT_ENOSPC_AFTER=$after LD_PRELOAD=$inject \
        pattern --ease 30 >"$work/full.txt" 2>&1
      rc=$?
      cat "$work/full.txt" >>"$log"
      [ $rc -eq 1 ] || fail "disk full after $after bytes: exit $rc, expected 1"
      grep -q "fault_inject: ENOSPC" "$work/full.txt" || fail "the disk was never full"
      line=$(grep "^drape pattern: $work/pattern/[a-z0-9_]*\.[a-z]*: .* (the pattern files already in $work/pattern are kept)" "$work/full.txt") ||
        fail "disk full after $after bytes: no message naming the file"
      echo "$line"
      for f in "$work"/kept/*; do
        cmp -s "$f" "$work/pattern/$(basename "$f")" || fail "disk full after $after bytes: $(basename "$f") changed"
      done
      [ "$(ls -A "$work/pattern" | wc -l)" -eq "$(ls -A "$work/kept" | wc -l)" ] || fail "files left behind"
      echo "disk full after $after bytes: the earlier pattern kept byte for byte"
    done
    pattern --ease 30 >"$work/room.txt" 2>&1 || { cat "$work/room.txt" >>"$log"; fail "pattern with room: exit $?"; }
    cmp -s "$work/kept/report.json" "$work/pattern/report.json" && fail "the run with room did not replace the pattern"
    echo "with room again, the pattern is replaced"
    ;;
  *) fail "unknown mode $mode" ;;
esac
echo "PASS $mode"
