#!/usr/bin/env python3
"""The palm of hands_trace.py sent over UDP through a faulty network (faults_test.sh packets):
each packet is dropped with probability 0.2, one in ten is held back and sent after the next
(reordered), one in ten is sent twice (duplicated) and one in eight is followed by garbage
(random bytes, a truncated packet, a packet with a bad magic number). Seeded: every run sends
the same stream. Prints what it did.

usage: faulty_hands.py ADDR PORT PX PY PZ
"""
import random
import socket
import sys
import time

import hands_trace


def main():
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    addr, port = sys.argv[1], int(sys.argv[2])
    frames = hands_trace.path(tuple(map(float, sys.argv[3:6])))
    rng = random.Random(20)
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    counts = {"sent": 0, "dropped": 0, "reordered": 0, "duplicated": 0, "garbage": 0}
    held = None
    t0 = time.monotonic()
    for i, (t, pos) in enumerate(frames):
        delay = t0 + t - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        p = hands_trace.packet(1000 + i, t, pos)
        if rng.random() < 0.2:
            counts["dropped"] += 1
        elif held is None and rng.random() < 0.1:
            held = p  # sent after the next one
            counts["reordered"] += 1
        else:
            s.sendto(p, (addr, port))
            counts["sent"] += 1
            if rng.random() < 0.1:
                s.sendto(p, (addr, port))
                counts["duplicated"] += 1
            if held is not None:
                s.sendto(held, (addr, port))
                counts["sent"] += 1
                held = None
        if rng.random() < 0.125:
            kind = rng.randrange(3)
            if kind == 0:
                junk = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 120)))
            elif kind == 1:
                junk = p[: rng.randrange(1, len(p))]
            else:
                junk = b"XXXX" + p[4:]
            s.sendto(junk, (addr, port))
            counts["garbage"] += 1
    print("faulty_hands: " + ", ".join(f"{k} {v}" for k, v in counts.items()))


if __name__ == "__main__":
    main()
