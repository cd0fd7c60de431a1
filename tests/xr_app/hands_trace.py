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

usage: hands_trace.py trace FILE PX PY PZ
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
    out, t = [], 0.0
    for a, b, secs in segments:
        n = int(round(secs * RATE))
        for i in range(n):
            out.append((t, lerp(a, b, (i + 1) / n)))
            t += 1.0 / RATE
    return out


def write_trace(fname, frames):
    with open(fname, "w") as f:
        f.write("# drape-trace v1\n")
        for t, (x, y, z) in frames:
            f.write(f"{t:.6f},1,1,0.9,{x:.6f},{y:.6f},{z:.6f},0,0,0,1,0\n")


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
    elif len(a) >= 6 and a[0] == "udp":
        rest = a[6:]
        opts = {k: "--" + k in rest for k in ("noise", "bad", "lowconf", "attack")}
        opts["key"] = rest[rest.index("--key") + 1] if "--key" in rest else None
        send(a[1], int(a[2]), path(tuple(map(float, a[3:6]))), opts)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
