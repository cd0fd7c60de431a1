#!/usr/bin/env bash
# Live voice in `drape xr` (--voice), on the mock runtime with a scripted scenario in which the
# right hand pinches the muslin and holds it against the form. The spoken command is made here
# with espeak-ng and sox (16 kHz mono); nothing is mocked: the app's voice thread decodes it with
# pocketsphinx.
#   wav      --voice FILE.wav: the recording streamed at real time; "pin here" pins the cloth
#            (the voice trigger in xr_session.txt, a "pin" trigger in session_log.json, pinned
#            vertices added); prints the latency from the end of the speech to the trigger.
#   alsa     --voice mic with ALSA pointed (ALSA_CONFIG_PATH) at a `file` PCM whose `infile` is
#            the raw S16_LE recording: the same pin through the real ALSA capture path.
#   no_mic   --voice mic with the default PCM on a card that does not exist: exit 0, all frames,
#            the message naming the device in the log, the cloth the same as with --voice off.
#   bad_wav  --voice on a malformed WAV: exit 0, the message naming the file, the cloth the same.
#   defaults without --voice: the simulated runtime (the fallback, or XR_RUNTIME_JSON naming its
#            manifest) is a scripted run: live voice off, the scenario's audio cue read; a
#            configured runtime (an active_runtime.json, here a copy of the simulated runtime's
#            manifest standing in for a headset) is live: the microphone, no audio cue.
#   pattern  "make pattern", "map pattern" and "strain map" in one recording: each heard as its own
#            command (make/map differ in one vowel: the recogniser must not confuse them); the
#            mid-session pattern written from a snapshot into pattern/session-1/ while the
#            session runs, the end's into session-2/; the colour map turned to strain.
#   args     --voice on a file that does not exist exits 2 naming the option (both commands);
#            `drape run --headless --voice off` exits 2; --help of both lists --voice.
# usage: drape_voice_test.sh DRAPE_EXE MODE WORKDIR
set -u
exe=$1 mode=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
log=$work/log.txt
: >"$log"
fail() { echo "FAIL: $*"; echo "--- log:"; cat "$log"; exit 1; }
unset XR_RUNTIME_JSON DRAPE_MOCK_SCENARIO DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_WRITE_FRAMES
unset DRAPE_MOCK_FAST DRAPE_MOCK_WINDOW
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_CONFIG_DIRS=$work/none
mkdir -p "$HOME"

# The right hand as in the default scenario: it reaches the muslin, pinches it (the gesture fires
# near frame 82) and carries it to the form, then holds it there, pinched, until frame 900 (10 s
# at the runtime's 90 Hz): a "pin here" heard any time after that pins it.
scenario=$work/voice_pin.json
cat >"$scenario" <<'EOF'
{
  "name": "voice_pin",
  "description": "The right hand pinches the muslin and holds it against the form for a spoken pin.",
  "end_after_frames": 900,
  "interaction_profile": "/interaction_profiles/oculus/touch_controller",
  "head": [{"frame": 0, "position": [0.0, 1.45, 1.1], "orientation": [-0.0872, 0, 0, 0.9962]}],
  "hands": {
    "right": [
      {"frame": 0, "palm": {"position": [0.3, 1.0, 0.6]}, "pinch": 0.0},
      {"frame": 60, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 0.0},
      {"frame": 66, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 0.0},
      {"frame": 76, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 1.0},
      {"frame": 88, "palm": {"position": [0.12, 1.02, 0.21]}, "pinch": 1.0},
      {"frame": 110, "palm": {"position": [0.12, 1.04, 0.21]}, "pinch": 1.0},
      {"frame": 900, "palm": {"position": [0.12, 1.04, 0.21]}, "pinch": 1.0}
    ]
  }
}
EOF

# "pin here" after 5 s of silence (the hand has pinched by then), then 1.5 s of silence.
make_speech() {
  espeak-ng -s 140 -w "$work/pin_22k.wav" "pin here" >>"$log" 2>&1 || fail "espeak-ng failed"
  sox "$work/pin_22k.wav" -r 16000 -c 1 -b 16 "$work/pin.wav" pad 5 1.5 >>"$log" 2>&1 ||
    fail "sox failed"
}

# run NAME ARGS...: `drape xr` on the scenario into $work/NAME; sets rc and out.
run() {
  local name=$1; shift
  out=$work/$name
  "$exe" xr --scenario "$scenario" --eye-size 64 --cloth-res 12 --out "$out" "$@" \
    >"$work/$name.txt" 2>&1
  rc=$?
  { echo "--- drape xr $* (exit $rc)"; cat "$work/$name.txt"; } >>"$log"
}

# The pin heard, mapped and applied; prints the heard line with its latency.
check_pin() {
  [ $rc -eq 0 ] || fail "exit code $rc"
  local s=$out/xr_session.txt
  [ -s "$s" ] || fail "no xr_session.txt"
  heard=$(grep "^voice: frame [0-9]* heard 'pin here' -> pin (speech ended in frame" "$s") ||
    fail "'pin here' not heard as pin"
  echo "$heard"
  grep -q "^trigger frame [0-9]*: voice pin begin hand right -> pin once" "$s" ||
    fail "no voice pin trigger through the command map"
  grep -q " pinned_added [1-9][0-9]* " "$s" || fail "nothing pinned"
  python3 - "$out/session_log.json" <<'EOF' || fail "session_log.json has no pin trigger"
import json, sys
events = json.load(open(sys.argv[1]))["events"]
sys.exit(0 if any(e.get("type") == "trigger" and e.get("name") == "pin" for e in events) else 1)
EOF
  local frames
  frames=$(sed -n 's/.*(speech ended in frame [0-9]*: \([0-9]*\) frames.*/\1/p' <<<"$heard")
  [ -n "$frames" ] && [ "$frames" -ge 0 ] || fail "no latency in frames"
  echo "latency from the end of the speech to the trigger: $frames frames"
}

# A failing input: exit 0, every frame, the message in the log, the cloth as with --voice off.
check_failure() {
  local pattern=$1
  [ $rc -eq 0 ] || fail "exit code $rc"
  grep -q "^drape xr: exiting" "$work/$2.txt" || fail "the session did not end normally"
  local line
  line=$(grep "^voice: .*$pattern.*voice commands are off" "$out/xr_session.txt") ||
    fail "no voice status naming '$pattern' in xr_session.txt"
  echo "$line"
  run reference --frames 120 --voice off
  [ $rc -eq 0 ] || fail "reference run: exit code $rc"
  cmp -s "$out/drape_cloth.gltf" "$work/$2/drape_cloth.gltf" ||
    fail "the cloth differs from the run without voice"
  echo "cloth identical to the run with --voice off"
}

# The phrases one after the other (1.2 s of silence before each, 1 s after the last: all heard
# within the scenario's 10 s) into
# $work/phrases.wav.
make_phrases() {
  local parts=() i=0
  for p in "$@"; do
    espeak-ng -s 140 -w "$work/p$i.wav" "$p" >>"$log" 2>&1 || fail "espeak-ng failed"
    sox "$work/p$i.wav" -r 16000 -c 1 -b 16 "$work/q$i.wav" pad 1.2 0 >>"$log" 2>&1 ||
      fail "sox failed"
    parts+=("$work/q$i.wav")
    i=$((i + 1))
  done
  sox "${parts[@]}" "$work/phrases.wav" pad 0 1 >>"$log" 2>&1 || fail "sox concat failed"
}

# The pattern mode's checks on $out.
check_pattern() {
  [ $rc -eq 0 ] || fail "exit code $rc"
  local s=$out/xr_session.txt
  grep "heard 'make pattern' -> pattern" "$s" || fail "'make pattern' not heard as pattern"
  grep "heard 'map pattern' -> map" "$s" || fail "'map pattern' not heard as map"
  grep "heard 'strain map' -> colours" "$s" || fail "'strain map' not heard as colours"
  grep -c "heard '" "$s" | grep -qx 3 || fail "not exactly three phrases heard"
  grep -q "^colour map: strain" "$s" || fail "the colour map did not turn to strain"
  grep "^pattern: [0-9]* piece(s), .* -> $out/pattern/session-1 (tick [0-9]*)" "$s" ||
    fail "no mid-session pattern in session-1"
  for f in pattern.svg pattern.dxf pattern_a4.pdf report.json; do
    [ -s "$out/pattern/session-1/$f" ] || fail "session-1/$f missing"
  done
  grep -q "^pattern: .* -> $out/pattern/session-2\$" "$s" || fail "the end's pattern is not session-2"
}

case $mode in
  pattern)
    make_phrases "make pattern" "map pattern" "strain map"
    run pattern --voice "$work/phrases.wav"
    check_pattern
    ;;
  wav)
    make_speech
    run wav --voice "$work/pin.wav"
    check_pin
    ;;
  alsa)
    make_speech
    sox "$work/pin.wav" -t raw -r 16000 -c 1 -b 16 -e signed-integer "$work/pin.raw" ||
      fail "sox raw failed"
    cat >"$work/asound.conf" <<EOF
pcm.!default {
  type file
  slave.pcm { type null }
  file "/dev/null"
  infile "$work/pin.raw"
  format "raw"
}
EOF
    export ALSA_CONFIG_PATH=$work/asound.conf
    run alsa --voice mic
    grep -q "^voice: listening to microphone (ALSA 'default')" "$out/xr_session.txt" ||
      fail "the microphone was not opened"
    check_pin
    ;;
  no_mic)
    printf 'pcm.!default {\n  type hw\n  card 7\n}\n' >"$work/asound.conf"
    export ALSA_CONFIG_PATH=$work/asound.conf
    run no_mic --frames 120 --voice mic
    check_failure "microphone 'default'" no_mic
    ;;
  bad_wav)
    printf 'RIFF\x24\x00\x00\x00WAVEjunk' >"$work/bad.wav"
    run bad_wav --frames 120 --voice "$work/bad.wav"
    check_failure "$work/bad.wav: " bad_wav
    ;;
  defaults)
    make_speech
    python3 - "$scenario" "$work/pin.wav" <<'EOF' || fail "cannot add the audio cue"
import json, sys
s = json.load(open(sys.argv[1]))
s["audio"] = [{"frame": 20, "wav": sys.argv[2], "text": "pin here"}]
json.dump(s, open(sys.argv[1], "w"))
EOF
    printf 'pcm.!default {\n  type hw\n  card 7\n}\n' >"$work/asound.conf"
    export ALSA_CONFIG_PATH=$work/asound.conf
    run fallback --frames 30
    [ $rc -eq 0 ] || fail "fallback: exit code $rc"
    grep -q "^drape xr: live voice: off" "$work/fallback.txt" || fail "fallback: voice not off"
    grep -q "^voice: 1 audio cue(s)" "$out/xr_session.txt" || fail "fallback: no audio cue"
    XR_RUNTIME_JSON=$(dirname "$exe")/drape_mock_runtime.json run named --frames 30
    [ $rc -eq 0 ] || fail "XR_RUNTIME_JSON: exit code $rc"
    grep -q "^drape xr: live voice: off" "$work/named.txt" || fail "XR_RUNTIME_JSON: voice not off"
    mkdir -p "$work/home/.config/openxr/1"
    bin=$(cd "$(dirname "$exe")" && pwd)
    sed "s|\./libdrape_mock_runtime.so|$bin/libdrape_mock_runtime.so|" \
      "$bin/drape_mock_runtime.json" >"$work/home/.config/openxr/1/active_runtime.json"
    DRAPE_MOCK_SCENARIO=$scenario "$exe" xr --frames 30 --eye-size 64 --cloth-res 12 \
      --out "$work/headset" >"$work/headset.txt" 2>&1
    rc=$?
    { echo "--- drape xr (active_runtime.json, exit $rc)"; cat "$work/headset.txt"; } >>"$log"
    [ $rc -eq 0 ] || fail "configured runtime: exit code $rc"
    grep -q "runtime manifest: (system active runtime)" "$work/headset.txt" ||
      fail "configured runtime: active_runtime.json not used"
    grep -q "^drape xr: live voice: mic" "$work/headset.txt" || fail "configured runtime: not mic"
    grep -q "audio cue" "$work/headset/xr_session.txt" && fail "configured runtime: a cue played"
    grep -q "^voice: microphone 'default': cannot open" "$work/headset/xr_session.txt" ||
      fail "configured runtime: no microphone message"
    echo "simulated runtime: scripted (voice off, cue read); configured runtime: live (mic, no cue)"
    ;;
  args)
    for cmd in xr run; do
      "$exe" $cmd --voice "$work/missing.wav" --out "$work/args_$cmd" >"$work/args.txt" 2>&1
      rc=$?
      cat "$work/args.txt" >>"$log"
      [ $rc -eq 2 ] || fail "drape $cmd --voice missing.wav exited $rc, not 2"
      grep -q -- "--voice: no such file: .*missing.wav" "$work/args.txt" ||
        fail "drape $cmd: the message does not name --voice and the file"
      "$exe" $cmd --help >"$work/help.txt" 2>&1 || fail "drape $cmd --help failed"
      grep -q -- "--voice" "$work/help.txt" || fail "drape $cmd --help does not list --voice"
    done
    "$exe" run --headless --voice off >"$work/args.txt" 2>&1
    rc=$?
    cat "$work/args.txt" >>"$log"
    [ $rc -eq 2 ] || fail "drape run --headless --voice off exited $rc, not 2"
    echo "--voice: a missing file and --headless are usage errors (exit 2)"
    ;;
  *)
    fail "unknown mode $mode"
    ;;
esac
echo "PASS"
