#!/usr/bin/env python3
"""The right hand's palm for the external-hands tests (drape_hands_test.sh): it approaches the
cloth at the point P, pushes its palm forward (palm_push: the pinch on), moves the cloth, stays
still (dwell: release), pushes again (the pinch off). Writes it as a trace (tracking/trace.hpp's
format) or sends it over UDP (docs/tracking.md, "The UDP stream") at its timestamps, with bad
packets mixed in when asked:
  --noise      malformed (too short, truncated) and out-of-order packets;
  --bad        oversized, malformed (bad magic, bad joint count), out-of-order and stale (a new
               sequence number with an old timestamp) packets;
  --lowconf    confidence 0.1 during the move: a short dip (0.1 s) and then 0.9 s, after which
               nothing more is sent (the pinch must be held through the dip, then released);
  --key HEX    sign the packets (version 2) with this pairing key;
  --attack     (with --key) forged packets (another key's tag, unsigned, a changed position)
               and replays of earlier signed packets, all moving the palm far away.

Or both palms' two-hand gestures as a trace (two_hand_path).

Or the right palm touching the app's calibration markers (calibration_path).

usage: hands_trace.py trace FILE PX PY PZ
       hands_trace.py two FILE PX PY PZ
       hands_trace.py calib FILE YAW_DEG TX TY TZ [--collinear]
       hands_trace.py udp ADDR PORT PX PY PZ [--noise] [--bad] [--lowconf] [--key HEX] [--attack]
"""
import hashlib
import hmac
import socket
import struct
import sys
import time

RATE = 60.0  # frames per second


def lerp(a, b, u):
    return tuple(x + (y - x) * u for x, y in zip(a, b))


def sample(segments, interp=lerp):
    """(time, position) at RATE along segments of (from, to, seconds)."""
    out, t = [], 0.0
    for a, b, secs in segments:
        n = int(round(secs * RATE))
        for i in range(n):
            out.append((t, interp(a, b, (i + 1) / n)))
            t += 1.0 / RATE
    return out


def path(p):
    """(time, position) of the palm at RATE: segments of straight motion and holds."""
    px, py, pz = p
    start = (px, py, pz + 0.35)
    before_push = (px, py, pz + 0.13)
    at_cloth = (px, py, pz - 0.04)  # through it: the push fires ~12 cm in
    moved = (px + 0.08, py - 0.05, pz + 0.10)
    pushed = (moved[0], moved[1], moved[2] - 0.15)
    segments = [  # (from, to, seconds)
        (start, before_push, 1.5),     # the approach: 13 cm/s, no push
        (before_push, before_push, 0.4),  # a short rest: the push is measured from here
        (before_push, at_cloth, 0.25),  # palm push: 68 cm/s
        (at_cloth, moved, 1.2),        # the move (backwards: no push)
        (moved, moved, 1.5),           # dwell
        (moved, pushed, 0.2),          # palm push again: the pinch off
        (pushed, pushed, 0.3),
    ]
    return sample(segments)


def two_hand_path(p):
    """(time, (left position, right position)) of both palms at RATE: brought together on the
    cloth at P and held (hands_together: pin), spread slowly (nothing), brought to 20 cm and
    spread quickly (hands_apart: undo), both pushed forward (both_push: the cut begins), the right
    palm drawn across the cloth, both pushed again (both_push: the cut ends). No palm rests 1 s
    (no dwell) except while the palms are together."""
    px, py, pz = p

    def pair(dx, dz=0.0, dy=0.0, shift=0.0):
        """The palms dx either side of P (+shift in x), dz in front of it, dy above it."""
        return ((px + shift - dx, py + dy, pz + dz), (px + shift + dx, py + dy, pz + dz))

    lower = -0.12  # the cut's second stroke end: 12 cm down the cloth
    segments = [  # (from, to, seconds); each a (left, right) pair
        (pair(0.3, 0.3), pair(0.3, 0.3), 0.5),
        (pair(0.3, 0.3), pair(0.03), 1.0),  # together on the cloth (6 cm apart)
        (pair(0.03), pair(0.03), 0.8),  # held: hands_together after 0.3 s
        (pair(0.03), pair(0.3, 0.2), 1.5),  # slowly apart and back
        (pair(0.3, 0.2), pair(0.1, 0.2), 0.8),
        (pair(0.1, 0.2), pair(0.1, 0.2), 0.3),
        (pair(0.1, 0.2), pair(0.35, 0.2), 0.25),  # quick spread: hands_apart
        (pair(0.35, 0.2), pair(0.2, 0.13, 0, -0.2), 0.8),  # the right palm in front of P
        (pair(0.2, 0.13, 0, -0.2), pair(0.2, 0.13, 0, -0.2), 0.4),
        (pair(0.2, 0.13, 0, -0.2), pair(0.2, -0.04, 0, -0.2), 0.25),  # both pushed: cut begins
        (pair(0.2, -0.04, 0, -0.2), pair(0.2, -0.02, lower, -0.2), 0.8),  # the stroke down
        (pair(0.2, -0.02, lower, -0.2), pair(0.2, 0.13, lower, -0.2), 0.6),
        (pair(0.2, 0.13, lower, -0.2), pair(0.2, 0.13, lower, -0.2), 0.3),
        (pair(0.2, 0.13, lower, -0.2), pair(0.2, -0.04, lower, -0.2), 0.25),  # both: cut ends
        (pair(0.2, -0.04, lower, -0.2), pair(0.2, -0.04, lower, -0.2), 0.3),
    ]
    return sample(segments, lambda a, b, u: (lerp(a[0], b[0], u), lerp(a[1], b[1], u)))


# The app's marked calibration points (xr_app/app/calibration_mode.cpp), stage metres.
MARKERS = [(0.0, 1.30, 0.16), (0.12, 0.95, 0.16), (-0.30, 0.0, 0.40), (0.30, 0.0, 0.40)]


def calibration_path(yaw_deg, t, collinear):
    """(time, position) of the right palm in a tracker's frame that the stage sees rotated by
    yaw_deg about y and moved by t (stage = R tracker + t): it rests 1.5 s on each marker in turn
    (tracker = R^T (marker - t)) and moves 0.8 s between them. collinear: the four rests on one
    line of the tracker's frame instead (a broken calibration)."""
    import math
    c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))

    def to_tracker(m):
        d = [m[i] - t[i] for i in range(3)]
        return (c * d[0] - s * d[2], d[1], s * d[0] + c * d[2])  # R^T d, R = yaw about y

    if collinear:
        rests = [(0.1 * i, 0.2 * i, -1.0) for i in range(4)]
    else:
        rests = [to_tracker(m) for m in MARKERS]
    segments = [(rests[0], rests[0], 1.5)]
    for a, b in zip(rests, rests[1:]):
        segments += [(a, b, 0.8), (b, b, 1.5)]
    return sample(segments)


def write_trace(fname, frames):
    with open(fname, "w") as f:
        f.write("# drape-trace v1\n")
        for t, (x, y, z) in frames:
            f.write(f"{t:.6f},1,1,0.9,{x:.6f},{y:.6f},{z:.6f},0,0,0,1,0\n")


def write_two_hand_trace(fname, frames):
    with open(fname, "w") as f:
        f.write("# drape-trace v1\n")
        for t, (left, right) in frames:
            for hand, (x, y, z) in ((0, left), (1, right)):
                f.write(f"{t:.6f},{hand},1,0.9,{x:.6f},{y:.6f},{z:.6f},0,0,0,1,0\n")


def packet(seq, t, pos, conf=0.9, key=None):
    head = struct.pack("<IHHIdB3x", 0x53485244, 2 if key else 1, 0, seq, t, 1)
    hand = struct.pack("<BBBxf4f3f", 1, 1, 1, conf, 0.0, 0.0, 0.0, 1.0, *pos)
    body = head + hand
    return body + hmac.new(key, body, hashlib.sha256).digest() if key else body


def confidence(t, lowconf):
    """0.1 in the dips of --lowconf (a short one, then a long one), else 0.9."""
    if lowconf and (2.25 <= t < 2.35 or 2.6 <= t < 3.5):
        return 0.1
    return 0.9


def send(addr, port, frames, opts):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    key = bytes.fromhex(opts["key"]) if opts["key"] else None
    other_key = bytes(32)
    t0 = time.monotonic()
    seq = 1000
    sent = []  # the signed packets as sent, for the replays
    far = (0.0, 0.2, 2.0)  # where the forged and replayed packets would put the palm
    for i, (t, pos) in enumerate(frames):
        if opts["lowconf"] and t >= 3.5:
            break  # after the long dip: nothing more (no dwell, no second push)
        delay = t0 + t - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        good = packet(seq, t, pos, confidence(t, opts["lowconf"]), key)
        s.sendto(good, (addr, port))
        sent.append(good)
        if opts["noise"] and i % 20 == 5:
            s.sendto(b"not a skeleton packet", (addr, port))  # malformed: too short
            s.sendto(good[:-4], (addr, port))  # malformed: truncated
            s.sendto(packet(seq - 3, t, pos), (addr, port))  # out of order
        if opts["bad"] and i % 20 == 5:
            bad = [
                good + bytes(3000),  # oversized
                b"XXXX" + good[4:],  # malformed: bad magic
                good[:26] + b"\x05" + good[27:],  # malformed: 5 joints
                packet(seq - 3, t, far),  # out of order
                packet(seq + 1, t - 0.5, far),  # stale: an old timestamp
            ]
            k = (i // 20) % len(bad)  # each kind in turn sent last (the app names the last)
            for b in bad[k + 1:] + bad[:k + 1]:
                s.sendto(b, (addr, port))
            seq += 1  # the next good packet stays above the stale one's number
        if opts["attack"] and i % 20 == 5:
            s.sendto(packet(seq + 1, t, far, key=other_key), (addr, port))  # another key
            s.sendto(packet(seq + 1, t, far), (addr, port))  # unsigned
            forged = bytearray(packet(seq + 1, t, pos, key=key))
            forged[56:60] = struct.pack("<f", far[2])  # the palm's z changed after signing
            s.sendto(bytes(forged), (addr, port))
            if len(sent) > 10:
                s.sendto(sent[-10], (addr, port))  # a replay of an earlier packet
        seq += 1


def main():
    a = sys.argv[1:]
    if len(a) >= 5 and a[0] == "trace":
        write_trace(a[1], path(tuple(map(float, a[2:5]))))
    elif len(a) >= 6 and a[0] == "calib":
        t = tuple(map(float, a[3:6]))
        write_trace(a[1], calibration_path(float(a[2]), t, "--collinear" in a[6:]))
    elif len(a) >= 5 and a[0] == "two":
        write_two_hand_trace(a[1], two_hand_path(tuple(map(float, a[2:5]))))
    elif len(a) >= 6 and a[0] == "udp":
        rest = a[6:]
        opts = {k: "--" + k in rest for k in ("noise", "bad", "lowconf", "attack")}
        opts["key"] = rest[rest.index("--key") + 1] if "--key" in rest else None
        send(a[1], int(a[2]), path(tuple(map(float, a[3:6]))), opts)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
