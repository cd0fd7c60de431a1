#!/usr/bin/env python3
"""The right hand's palm for the external-hands tests (drape_hands_test.sh): it approaches the
cloth at the point P, pushes its palm forward (palm_push: the pinch on), moves the cloth, stays
still (dwell: release), pushes again (the pinch off). Writes it as a trace (tracking/trace.hpp's
format) or sends it over UDP (tracking/udp_source.hpp's packet format) at its timestamps, with
malformed and out-of-order packets mixed in when asked.

usage: hands_trace.py trace FILE PX PY PZ
       hands_trace.py udp ADDR PORT PX PY PZ [--noise]
"""
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


def packet(seq, t, pos):
    head = struct.pack("<IHHIdB3x", 0x53485244, 1, 0, seq, t, 1)
    hand = struct.pack("<BBBxf4f3f", 1, 1, 1, 0.9, 0.0, 0.0, 0.0, 1.0, *pos)
    return head + hand


def send(addr, port, frames, noise):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    t0 = time.monotonic()
    seq = 1000
    for i, (t, pos) in enumerate(frames):
        delay = t0 + t - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        s.sendto(packet(seq, t, pos), (addr, port))
        if noise and i % 20 == 5:
            s.sendto(b"not a skeleton packet", (addr, port))  # malformed: too short
            s.sendto(packet(seq, t, pos)[:-4], (addr, port))  # malformed: truncated
            s.sendto(packet(seq - 3, t, pos), (addr, port))  # out of order
        seq += 1


def main():
    a = sys.argv[1:]
    if len(a) >= 5 and a[0] == "trace":
        write_trace(a[1], path(tuple(map(float, a[2:5]))))
    elif len(a) >= 6 and a[0] == "udp":
        send(a[1], int(a[2]), path(tuple(map(float, a[3:6]))), "--noise" in a[6:])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
