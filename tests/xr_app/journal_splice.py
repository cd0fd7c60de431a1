#!/usr/bin/env python3
"""Continues a killed session's journal with another run's inputs (drape_record_test.sh kill).

usage: journal_splice.py KILLED FULL TICK OUT
Writes OUT: KILLED's preamble and whole records (a cut-off tail is dropped), then FULL's input
(kind 2) and checkpoint (kind 4) records of ticks >= TICK and its end record (kind 3): the
killed session as resumed at TICK and given the inputs the uninterrupted run got from there.
Each record: u32 length, u32 CRC32 of the payload, the payload (its first byte the kind, a tick
record's and a checkpoint record's tick the next 8 bytes, little-endian)."""
import struct
import sys
import zlib


def records(data):
    pos = 12
    while pos + 8 <= len(data):
        n, crc = struct.unpack_from("<II", data, pos)
        payload = data[pos + 8:pos + 8 + n]
        if n == 0 or len(payload) < n or zlib.crc32(payload) != crc:
            return
        yield data[pos:pos + 8 + n], payload
        pos += 8 + n


def main():
    killed, full, tick, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    k = open(killed, "rb").read()
    f = open(full, "rb").read()
    body = [raw for raw, p in records(k) if p[0] != 3]
    for raw, p in records(f):
        if p[0] in (2, 4) and struct.unpack_from("<Q", p, 1)[0] >= tick or p[0] == 3:
            body.append(raw)
    open(out, "wb").write(k[:12] + b"".join(body))


if __name__ == "__main__":
    main()
