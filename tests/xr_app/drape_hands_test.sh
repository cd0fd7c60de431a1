#!/usr/bin/env bash
# External hands in the app (`drape xr --hands ...`, the simulated runtime giving the head):
#   trace   --hands trace FILE: a trace of the right palm approaching the cloth, a palm push (the
#           pinch on), a move, a dwell (release), a second palm push (the pinch off) -> the log
#           shows the pinch taking a particle, the release and the pinch letting it go.
#   calibrated the same trace 0.5 m lower, lifted into the stage by --calibration FILE.
#   udp     the same poses sent over UDP at their timestamps (--hands udp:127.0.0.1:PORT).
#   noisy   the same with malformed and out-of-order packets mixed in: a message, still the pinch.
#   two     --hands trace FILE of both palms: together (pin), spread slowly (nothing), spread
#           quickly (undo), both pushed twice (the cut's start and end).
#   calibrate --calibrate with a trace of the palm resting on the 4 markers as a tracker turned
#           30 degrees and moved sees them: the saved file's transform is that one within 1 mm,
#           the residual logged; a later session loads the saved file by itself.
#   calibrate_collinear the touches on one line: refused with its reason, nothing saved.
#   kinect  --hands kinect --kinect-record DIR: a synthesized fakenect recording (kinect_record.py)
#           of the same palm seen by a depth camera behind the form facing the user, brought into
#           the stage by its --calibration file -> the same pinch, move, release and pinch off.
#   kinect_end the recording ends mid-pinch (the Kinect going away): its message, the pinch held
#           for the grace and let go, the session runs on to its last frame (exit 0).
#   missing --hands trace with no such file: exit 2 naming the file; a bad --hands value: exit 2
#           naming the option; a malformed trace: the session runs (exit 0), its status logged;
#           --kinect-record with no recording, or without --hands kinect: exit 2 naming it;
#           --hands kinect with no device: its status, the session runs (exit 0).
# usage: drape_hands_test.sh DRAPE_EXE MODE WORKDIR PORT
set -u
exe=$1 mode=$2 work=$3 port=${4:-0}
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
log=$work/log.txt
fail() { echo "FAIL: $*"; echo "--- log:"; cat "$log"; [ -f "$work/out/xr_session.txt" ] && { echo "--- xr_session.txt:"; cat "$work/out/xr_session.txt"; }; exit 1; }
unset XR_RUNTIME_JSON DRAPE_MOCK_SCENARIO DRAPE_MOCK_END_AFTER_FRAMES DRAPE_MOCK_WRITE_FRAMES DRAPE_MOCK_FAST
export HOME=$work/home XDG_CONFIG_HOME=$work/home/.config XDG_CONFIG_DIRS=$work/none
# A point on the hanging muslin of the default scene, in front of the form (stage metres).
P="0.11 1.15 0.115"
# The head looks at the form from 1 m; no hands or controllers (the hands are external). Fast
# (the runtime's virtual 90 Hz clock) for a trace; paced at 90 Hz for UDP (real-time packets).
scenario() {  # frames fast
  cat >"$work/scenario.json" <<JSON
{"name": "external_hands", "end_after_frames": $1, "fast": $2,
 "head": [{"frame": 0, "position": [0.0, 1.6, 1.0], "orientation": [0, 0, 0, 1]}]}
JSON
}
xr() { "$exe" xr --eye-size 64 --cloth-res 12 --scenario "$work/scenario.json" --out "$work/out" -v "$@"; }
check_pinch() {
  local s=$work/out/xr_session.txt
  [ -f "$s" ] || fail "no xr_session.txt"
  grep -q "gesture palm_push begin hand right -> pinch toggle" "$s" || fail "no palm push -> pinch"
  grep -q "pinch: right hand took particle" "$s" || fail "the pinch took no particle"
  grep -q "gesture dwell begin hand right -> release" "$s" || fail "no dwell -> release"
  grep -q "pinch: right hand let particle .* go" "$s" || fail "the pinch never let go"
  grep -q "pinned_added -1 " "$s" || fail "the dwell did not release exactly one pin"
  grep "pinch: right hand\|-> release\|pinched_frames" "$s"
}
case $mode in
  trace)
    python3 "$here/hands_trace.py" trace "$work/hands.csv" $P || fail "trace writer"
    scenario 600 true
    xr --hands trace "$work/hands.csv" >"$log" 2>&1 || fail "exit code $?"
    grep -q "hands: trace source" "$log" || fail "the trace source not opened"
    check_pinch
    ;;
  calibrated)  # the trace in a tracker frame 0.5 m below the stage's, --calibration lifts it
    python3 "$here/hands_trace.py" trace "$work/hands.csv" 0.11 0.65 0.115 || fail "trace writer"
    cat >"$work/calibration.json" <<JSON
{"format": "drape-calibration", "version": 1, "scale": 1.0,
 "rotation": [[1,0,0],[0,1,0],[0,0,1]], "translation": [0, 0.5, 0],
 "rms_residual_m": 0.002, "max_residual_m": 0.004, "pairs": 4}
JSON
    scenario 600 true
    xr --hands trace "$work/hands.csv" --calibration "$work/calibration.json" >"$log" 2>&1 ||
      fail "exit code $?"
    grep -q "hands: calibration .*calibration.json" "$log" || fail "the calibration not loaded"
    check_pinch
    ;;
  udp|noisy)
    scenario 1000 false
    : >"$log"
    xr --hands "udp:127.0.0.1:$port" >"$log" 2>&1 &
    app=$!
    for _ in $(seq 1 300); do grep -q "hands: udp: no packets yet" "$log" && break; sleep 0.1; done
    grep -q "hands: udp: no packets yet on 127.0.0.1:$port" "$log" || { kill "$app"; fail "no 'no packets yet' status"; }
    noise=""
    [ "$mode" = noisy ] && noise=--noise
    python3 "$here/hands_trace.py" udp 127.0.0.1 "$port" $P $noise || { kill "$app"; fail "sender"; }
    wait "$app" || fail "exit code $?"
    check_pinch
    if [ "$mode" = noisy ]; then
      grep -q "hands: udp: .* packets dropped (.* malformed, .* out of order), last: " "$log" ||
        fail "no message about the dropped packets"
      grep -m2 "packets dropped" "$log"
    fi
    ;;
  kinect|kinect_end)
    until=""
    [ "$mode" = kinect_end ] && until="--until 2.6"  # after the push, during the move
    python3 "$here/kinect_record.py" "$work/rec" "$work/calibration.json" $P $until ||
      fail "recording writer"
    frames=1000
    [ "$mode" = kinect_end ] && frames=600
    scenario $frames false
    xr --hands kinect --kinect-record "$work/rec" --calibration "$work/calibration.json" \
      >"$log" 2>&1 || fail "exit code $?"
    grep -q "hands: kinect source recording .*/rec" "$log" || fail "the kinect source not opened"
    grep -q "hands: calibration .*calibration.json" "$log" || fail "the calibration not loaded"
    s=$work/out/xr_session.txt
    if [ "$mode" = kinect ]; then
      check_pinch
    else
      [ -f "$s" ] || fail "no xr_session.txt"
      grep -q "pinch: right hand took particle" "$s" || fail "the pinch took no particle"
      grep -q "hands: kinect: the recording .*/rec ended" "$s" || fail "no message: the Kinect ended"
      grep -q "right hand lost: holding the pinch" "$s" || fail "the pinch not held over the grace"
      grep -q "pinch: right hand lost for 0.3 s: let go of particle" "$s" || fail "not let go after the grace"
      grep -q "pinch: right hand let particle .* go" "$s" || fail "the pinch never let go"
      grep -q "frames: $frames\b\|frames $frames\b\|\"frames\": $frames\b" "$s" "$log" ||
        fail "the session did not run to its last frame"
      grep "kinect: \|lost\|pinch: right" "$s"
    fi
    rm -rf "$work/rec"  # 100 MB of depth frames
    ;;
  two)  # both palms: together -> pin, a quick spread -> undo, both pushed -> the cut's ends
    python3 "$here/hands_trace.py" two "$work/hands.csv" $P || fail "trace writer"
    scenario 1000 true
    xr --hands trace "$work/hands.csv" >"$log" 2>&1 || fail "exit code $?"
    s=$work/out/xr_session.txt
    [ -f "$s" ] || fail "no xr_session.txt"
    n() { grep -c "^\[drape xr\] trigger frame [0-9]*: gesture $1" "$log"; }
    [ "$(n "hands_together begin hand right -> pin once")" = 1 ] || fail "not one together -> pin"
    grep -q "sim: pin: particle" "$s" || fail "the pin not made"
    [ "$(n "hands_apart begin hand right -> undo once")" = 1 ] ||
      fail "not one hands_apart -> undo (the slow spread must not fire it)"
    grep -q "sim: undo: pin" "$s" || fail "the pin not undone"
    [ "$(n "both_push begin hand right -> cut toggle")" = 2 ] || fail "not two both_push -> cut"
    grep -q "cuts 1 " "$s" || fail "no cut made"
    grep -q "palm_push\|gesture dwell" "$s" && fail "a single palm push or a dwell fired"
    grep "gesture \|pin\|undo\|cut" "$s"
    ;;
  calibrate)  # --calibrate: the palm dwells on the 4 markers seen by a tracker yawed 30 degrees
    python3 "$here/hands_trace.py" calib "$work/hands.csv" 30 0.2 0.9 -1.5 || fail "trace writer"
    scenario 1000 true
    xr --hands trace "$work/hands.csv" --calibrate >"$log" 2>&1 || fail "exit code $?"
    s=$work/out/xr_session.txt
    saved=$XDG_CONFIG_HOME/drape/calibration-trace.json
    [ "$(grep -c "^calibration: marker [1-4] (.*) taken at" "$s")" = 4 ] || fail "not 4 markers taken"
    grep -q "^calibration: residual rms [0-9.]* mm, max [0-9.]* mm over 4 points; saved to $saved" "$s" ||
      fail "no residual or not saved"
    [ -f "$saved" ] || fail "no $saved"
    grep -q "palm_push\|gesture dwell" "$s" && fail "a gesture reached the operations while calibrating"
    python3 - "$saved" <<'PY' || fail "the saved transform is not the trace's"
import json, math, sys
c = json.load(open(sys.argv[1]))
a = math.radians(30)
R = [[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]]
t = [0.2, 0.9, -1.5]
# Each axis of the tracker mapped 1 m out: the transform's image within 1 mm of the truth's.
for k in range(4):
    p = [1.0 if i == k else 0.0 for i in range(3)]
    got = [c["scale"] * sum(c["rotation"][i][j] * p[j] for j in range(3)) + c["translation"][i] for i in range(3)]
    want = [sum(R[i][j] * p[j] for j in range(3)) + t[i] for i in range(3)]
    err = math.dist(got, want)
    print(f"point {p}: {got} vs {want}: {err * 1e3:.3f} mm")
    assert err < 1e-3, err
print("scale", c["scale"], "rms", c["rms_residual_m"], "max", c["max_residual_m"])
PY
    grep "^calibration: " "$s"
    # A later session with no --calibration uses the saved one and says so.
    python3 "$here/hands_trace.py" trace "$work/hands2.csv" $P || fail "trace writer"
    scenario 30 true
    "$exe" xr --eye-size 64 --cloth-res 12 --scenario "$work/scenario.json" --out "$work/out2" -v \
      --hands trace "$work/hands2.csv" >"$log" 2>&1 || fail "exit code $?"
    grep -q "hands: calibration $saved (the saved calibration of this source)" "$log" ||
      fail "the saved calibration not loaded"
    ;;
  calibrate_collinear)  # the four touches on one line: refused with its reason, nothing saved
    python3 "$here/hands_trace.py" calib "$work/hands.csv" 0 0 0 0 --collinear || fail "trace writer"
    scenario 1000 true
    xr --hands trace "$work/hands.csv" --calibrate >"$log" 2>&1 || fail "exit code $?"
    s=$work/out/xr_session.txt
    grep -q "^calibration: refused: calibration: points are coincident or collinear; nothing saved" "$s" ||
      fail "no message: collinear"
    [ -e "$XDG_CONFIG_HOME/drape/calibration-trace.json" ] && fail "a calibration saved"
    grep "^calibration: " "$s"
    "$exe" xr --frames 5 --calibrate >"$log" 2>&1
    [ $? -eq 2 ] || fail "--calibrate with the runtime's hands: not exit 2"
    grep -q "drape xr: --calibrate: needs --hands udp, trace or kinect" "$log" || fail "no message naming --calibrate"
    ;;
  missing)
    "$exe" xr --frames 5 --hands trace "$work/none.csv" >"$log" 2>&1
    rc=$?
    [ $rc -eq 2 ] || fail "missing trace: exit $rc, expected 2"
    grep -q "drape xr: --hands trace: no such file: .*none.csv" "$log" || fail "no message naming the file"
    "$exe" xr --frames 5 --hands leap >"$log" 2>&1
    rc=$?
    [ $rc -eq 2 ] || fail "bad --hands: exit $rc, expected 2"
    grep -q "drape xr: --hands: unknown source 'leap'" "$log" || fail "no message naming --hands"
    "$exe" xr --frames 5 --hands kinect --kinect-record "$work/norec" >"$log" 2>&1
    rc=$?
    [ $rc -eq 2 ] || fail "missing recording: exit $rc, expected 2"
    grep -q "drape xr: --kinect-record: no fakenect recording in .*norec (no INDEX.txt)" "$log" ||
      fail "no message naming --kinect-record and the directory"
    # No Kinect plugged in (no USB device here): a status, the session runs.
    scenario 30 true
    xr --hands kinect >"$log" 2>&1 || fail "--hands kinect with no device: exit code $?"
    grep -q "hands: kinect: no Kinect found (libfreenect reports 0 devices)\|hands: kinect: libfreenect init failed" "$log" ||
      fail "no status: no Kinect"
    mkdir -p "$work/rec" && : >"$work/rec/INDEX.txt"
    "$exe" run --frames 5 --hands udp --kinect-record "$work/rec" >"$log" 2>&1
    rc=$?
    [ $rc -eq 2 ] || fail "--kinect-record without kinect: exit $rc, expected 2"
    grep -q "drape run: --kinect-record: needs --hands kinect" "$log" || fail "no message: needs kinect"
    "$exe" xr --frames 5 --hands udp:127.0.0.1:99999 >"$log" 2>&1
    [ $? -eq 2 ] || fail "bad port: not exit 2"
    grep -q "drape xr: --hands: bad port '99999'" "$log" || fail "no message naming the port"
    printf '# drape-trace v1\n0.0,1,1,0.9,0.1,1.3,0.5,0,0,0,1,0\n0.1,7,1,0.9,0.1,1.3,0.5,0,0,0,1,0\n' >"$work/bad.csv"
    scenario 30 true
    xr --hands trace "$work/bad.csv" >"$log" 2>&1 || fail "malformed trace: exit code $?"
    grep -q "hands: .*bad.csv.*hand" "$log" || fail "no status naming the malformed trace"
    grep "hands: " "$log"
    ;;
  *) echo "unknown mode $mode"; exit 2 ;;
esac
echo "PASS $mode"
