#!/usr/bin/env bash
# External hands in the app (`drape xr --hands ...`, the simulated runtime giving the head):
#   trace   --hands trace FILE: a trace of the right palm approaching the cloth, a palm push (the
#           pinch on), a move, a dwell (release), a second palm push (the pinch off) -> the log
#           shows the pinch taking a particle, the release and the pinch letting it go.
#   calibrated the same trace 0.5 m lower, lifted into the stage by --calibration FILE.
#   udp     the same trace sent over UDP at its timestamps by `drape hands send`
#           (--hands udp:127.0.0.1:PORT).
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
#   bad     oversized, malformed, out-of-order and stale (old timestamp) packets mixed in: each
#           kind counted in the message, still the pinch.
#   lowconf the palm's confidence drops below the threshold during the move, briefly (the pinch
#           holds) and then for 0.9 s: the hand is lost, its pinch held for the grace, then let go.
#   signed  --hands udp:0.0.0.0:PORT without a key: exit 2 saying how to pair; `drape hands pair`
#           writes the key (0600); the app (the default key file) accepts the signed packets and
#           drops and counts the forged and replayed ones mixed in: still the pinch.
#   sendkey `drape hands send --key --rate 75` (signed, resampled) to an app listening on 0.0.0.0
#           with --hands-key FILE.
#   loop    `drape hands send --loop` of a short trace: more than two laps, sequence numbers
#           consecutive and timestamps increasing across laps.
#   missing --hands trace with no such file: exit 2 naming the file; a bad --hands value: exit 2
#           naming the option; --hands-key without udp or with a key file others may read, and
#           bad `drape hands` values: exit 2 naming the option or the file; a malformed trace: the
#           session runs (exit 0), its status logged; --kinect-record with no recording, or
#           without --hands kinect: exit 2 naming it; --hands kinect with no device: its status,
#           the session runs (exit 0).
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
# The last "packets dropped" message: the counts of the kinds $1 and $2 (e.g. malformed, forged)
# both above 0.
both_counted() {
  local last a b
  last=$(grep -o "hands: udp: [0-9]* packets dropped ([^)]*)" "$log" | tail -1)
  [ -n "$last" ] || fail "no message about the dropped packets"
  echo "$last"
  a=$(echo "$last" | grep -o "[0-9]* $1" | cut -d' ' -f1)
  b=$(echo "$last" | grep -o "[0-9]* $2" | cut -d' ' -f1)
  [ "${a:-0}" -gt 0 ] && [ "${b:-0}" -gt 0 ] || fail "$1 ${a:-none}, $2 ${b:-none}: expected both > 0"
}
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
  udp|noisy|bad|lowconf|signed|sendkey)
    addr=127.0.0.1
    key_args=()
    if [ "$mode" = signed ]; then
      "$exe" xr --frames 5 --hands "udp:0.0.0.0:$port" >"$log" 2>&1
      rc=$?
      [ $rc -eq 2 ] || fail "0.0.0.0 without a key: exit $rc, expected 2"
      grep -q "drape xr: --hands udp:0.0.0.0:...: listening beyond this machine needs a pairing key; run .drape hands pair." "$log" ||
        fail "no message saying how to pair"
      "$exe" hands pair >"$work/key.hex" 2>"$work/pair.txt" || fail "drape hands pair: exit $?"
      keyfile=$XDG_CONFIG_HOME/drape/hands.key
      [ "$(stat -c %a "$keyfile")" = 600 ] || fail "the key file is not 0600"
      grep -Eqx "[0-9a-f]{64}" "$work/key.hex" || fail "pair did not print 64 hex digits"
      "$exe" hands pair >"$work/key2.hex" 2>/dev/null || fail "second pair: exit $?"
      cmp -s "$work/key.hex" "$work/key2.hex" || fail "a second pair changed the key"
    fi
    if [ "$mode" = sendkey ]; then
      "$exe" hands pair --key "$work/sender.key" >/dev/null 2>&1 || fail "pair --key"
      addr=0.0.0.0
      key_args=(--hands-key "$work/sender.key")
    fi
    scenario 1000 false
    : >"$log"
    xr --hands "udp:$addr:$port" "${key_args[@]}" >"$log" 2>&1 &
    app=$!
    for _ in $(seq 1 300); do grep -q "hands: udp: no packets yet" "$log" && break; sleep 0.1; done
    grep -q "hands: udp: no packets yet on $addr:$port" "$log" || { kill "$app"; fail "no 'no packets yet' status"; }
    case $mode in
      udp|sendkey)
        python3 "$here/hands_trace.py" trace "$work/hands.csv" $P || { kill "$app"; fail "trace writer"; }
        send_key=()
        [ "$mode" = sendkey ] && send_key=(--key "$work/sender.key" --rate 75)  # resampled
        "$exe" hands send "$work/hands.csv" --to "127.0.0.1:$port" "${send_key[@]}" >"$work/send.txt" 2>&1 ||
          { kill "$app"; cat "$work/send.txt"; fail "drape hands send: exit code"; }
        cat "$work/send.txt"
        ;;
      signed) python3 "$here/hands_trace.py" udp 127.0.0.1 "$port" $P --key "$(cat "$work/key.hex")" --attack || { kill "$app"; fail "sender"; } ;;
      *)
        flag=--$mode
        [ "$mode" = noisy ] && flag=--noise
        python3 "$here/hands_trace.py" udp 127.0.0.1 "$port" $P "$flag" || { kill "$app"; fail "sender"; }
        ;;
    esac
    wait "$app" || fail "exit code $?"
    if [ "$mode" = lowconf ]; then
      s=$work/out/xr_session.txt
      [ "$(grep -c "pinch: right hand took particle" "$s")" = 1 ] || fail "not exactly one pinch taken"
      grep -q "right hand lost: holding the pinch" "$s" || fail "no 'lost: holding the pinch'"
      [ "$(grep -c "^pinch: right hand lost for .*: let go of particle" "$s")" = 1 ] ||
        fail "the pinch not let go exactly once after the grace"
      grep "pinch: right hand\|lost" "$s"
    else
      check_pinch
    fi
    case $mode in
      noisy|bad)
        grep -q "hands: udp: [0-9]* packets dropped (.*), last: " "$log" || fail "no reason given for the dropped packets"
        both_counted malformed "out of order"
        if [ "$mode" = bad ]; then
          grep -q "last: oversized packet (30[0-9][0-9] bytes)" "$log" || fail "no oversized packet named"
          grep -q "last: old timestamp" "$log" || fail "no stale (old timestamp) packet named"
        fi
        ;;
      signed)
        grep -q "hands: udp source 127.0.0.1:$port (signed packets only)" "$log" || fail "the key not used"
        grep -q "packets dropped (0 malformed, 0 out of order, " "$log" || fail "signed packets dropped as malformed or out of order"
        both_counted forged replayed
        ;;
      sendkey)
        grep -q "hands: udp source 0.0.0.0:$port (signed packets only)" "$log" || fail "the key not used"
        grep -q "packets (.* hand frames, signed) to 127.0.0.1:$port" "$work/send.txt" || fail "the sender did not sign"
        ! grep -q "packets dropped" "$log" || fail "signed packets dropped: $(grep -m1 'packets dropped' "$log")"
        ;;
    esac
    ;;
  loop)  # `drape hands send --loop` of a 0.1 s trace: laps with growing numbers and times
    printf '# drape-trace v1\n' >"$work/tiny.csv"
    for t in 0.00 0.02 0.04 0.06 0.08 0.10; do echo "$t,1,1,0.9,0.1,1.2,0.3,0,0,0,1,0" >>"$work/tiny.csv"; done
    python3 - "$port" >"$work/received.txt" 2>&1 <<'PY' &
import socket, struct, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", int(sys.argv[1])))
s.settimeout(3.0)
got = []
try:
    while True:
        d = s.recv(2048)
        magic, version, _, seq, t = struct.unpack("<IHHId", d[:20])
        got.append((seq, t))
except socket.timeout:
    pass
seqs = [q for q, _ in got]
times = [t for _, t in got]
ok = len(got) > 12 and all(b == (a + 1) % 2**32 for a, b in zip(seqs, seqs[1:])) \
    and all(b > a for a, b in zip(times, times[1:])) and times[-1] > 0.2
print(f"received {len(got)} packets, last timestamp {times[-1] if times else -1:.3f} s")
sys.exit(0 if ok else 1)
PY
    rx=$!
    sleep 0.5
    timeout 1.5 "$exe" hands send "$work/tiny.csv" --loop --to "127.0.0.1:$port" >"$log" 2>&1
    rc=$?
    [ $rc -eq 124 ] || fail "--loop ended by itself (exit $rc) before the timeout"
    wait "$rx" || { cat "$work/received.txt"; fail "the laps' packets: too few, or numbers/times not increasing"; }
    cat "$work/received.txt"
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
    # --hands-key: only with --hands udp; a key file others may read is refused naming the file.
    "$exe" xr --frames 5 --hands-key "$work/none.key" >"$log" 2>&1
    [ $? -eq 2 ] || fail "--hands-key without --hands udp: not exit 2"
    grep -q "drape xr: --hands-key: only with --hands udp" "$log" || fail "no message naming --hands-key"
    "$exe" hands pair --key "$work/open.key" >/dev/null 2>&1 || fail "pair --key"
    chmod 644 "$work/open.key"
    "$exe" xr --frames 5 --hands udp:0.0.0.0:$port --hands-key "$work/open.key" >"$log" 2>&1
    [ $? -eq 2 ] || fail "a readable key file: not exit 2"
    grep -q "drape xr: --hands-key: .*open.key: permissions 644 .*chmod 600" "$log" || fail "no message naming the key file"
    # drape hands send: its options, and bad values naming the option or the file.
    "$exe" hands send --help >"$log" 2>&1 || fail "hands send --help: exit $?"
    for o in --to --rate --loop --key; do grep -q -- "$o" "$log" || fail "hands send --help lacks $o"; done
    "$exe" hands send "$work/none.csv" >"$log" 2>&1
    [ $? -eq 2 ] && grep -q "drape hands send: .*none.csv: cannot open" "$log" || fail "hands send: missing trace"
    printf '# drape-trace v1\n0.0,1,1,0.9,0.1,1.3,0.5,0,0,0,1,0\n' >"$work/one.csv"
    "$exe" hands send "$work/one.csv" --to nowhere:1 >"$log" 2>&1
    [ $? -eq 2 ] && grep -q "drape hands send: --to: not an IPv4 address: 'nowhere'" "$log" || fail "hands send: bad --to"
    "$exe" hands send "$work/one.csv" --rate 0.5x >"$log" 2>&1
    [ $? -eq 2 ] && grep -q -- "--rate" "$log" || fail "hands send: bad --rate"
    "$exe" hands send "$work/one.csv" --key "$work/open.key" >"$log" 2>&1
    [ $? -eq 2 ] && grep -q "drape hands send: --key: .*open.key: permissions 644" "$log" || fail "hands send: readable key"
    "$exe" hands nosuch >"$log" 2>&1
    [ $? -eq 2 ] && grep -q "drape hands: unknown tool 'nosuch'" "$log" || fail "hands: unknown tool"
    printf '# drape-trace v1\n0.0,1,1,0.9,0.1,1.3,0.5,0,0,0,1,0\n0.1,7,1,0.9,0.1,1.3,0.5,0,0,0,1,0\n' >"$work/bad.csv"
    scenario 30 true
    xr --hands trace "$work/bad.csv" >"$log" 2>&1 || fail "malformed trace: exit code $?"
    grep -q "hands: .*bad.csv.*hand" "$log" || fail "no status naming the malformed trace"
    grep "hands: " "$log"
    ;;
  *) echo "unknown mode $mode"; exit 2 ;;
esac
echo "PASS $mode"
