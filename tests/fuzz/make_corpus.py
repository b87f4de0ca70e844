#!/usr/bin/env python3
"""Writes the seed corpus of the packet fuzz harnesses (tests/fuzz/corpus/{sacn,artnet}/).

Seeds are packets laid out from the standards' tables (E1.31-2018 Table 4-1, Art-Net 4 ArtDmx
and ArtPoll), valid ones of several sizes plus one of each broken kind, so the fuzzer starts
past the identifier checks. Run it again after changing the seeds; the files are committed.
"""
import os
import struct
import sys


def sacn(universe=1, slots=b"\xff", priority=100, seq=0, options=0, start=0, name=b"seed",
         cid=bytes(range(16))):
    dmp = struct.pack(">BBHHH", 0x02, 0xA1, 0, 1, len(slots) + 1) + bytes([start]) + slots
    dmp = struct.pack(">H", 0x7000 | (len(dmp) + 2)) + dmp
    framing = (struct.pack(">I", 2) + name.ljust(64, b"\0") +
               struct.pack(">BHBBH", priority, 0, seq, options, universe) + dmp)
    framing = struct.pack(">H", 0x7000 | (len(framing) + 2)) + framing
    root = struct.pack(">I", 4) + cid + framing
    root = struct.pack(">H", 0x7000 | (len(root) + 2)) + root
    return struct.pack(">HH", 0x10, 0) + b"ASC-E1.17\0\0\0" + root


def artdmx(port_address=0, slots=b"\xff\x00", seq=1):
    return (b"Art-Net\0" + struct.pack("<H", 0x5000) + struct.pack(">H", 14) +
            bytes([seq, 0, port_address & 0xFF, port_address >> 8]) +
            struct.pack(">H", len(slots)) + slots)


def artpoll(flags=0x02):
    return b"Art-Net\0" + struct.pack("<H", 0x2000) + struct.pack(">H", 14) + bytes([flags, 0])


def main():
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
    seeds = {
        "sacn": {
            "one_slot": sacn(),
            "full_512": sacn(universe=63999, slots=bytes(i & 0xFF for i in range(512))),
            "short_universe_24": sacn(universe=7, slots=bytes(range(24)), priority=200),
            "terminated": sacn(options=0x40, seq=255),
            "preview": sacn(options=0x80),
            "start_dd": sacn(start=0xDD, slots=bytes([100] * 16)),
            "no_slots": sacn(slots=b""),
            "bad_universe_0": sacn(universe=0),
            "bad_priority_201": sacn(priority=201),
            "truncated": sacn(slots=bytes(32))[:100],
            "sync": struct.pack(">HH", 0x10, 0) + b"ASC-E1.17\0\0\0" +
                    struct.pack(">HI", 0x7000 | 33, 8) + bytes(16) +
                    struct.pack(">HIBH2x", 0x7000 | 11, 1, 3, 1),
        },
        "artnet": {
            "dmx_2": artdmx(),
            "dmx_512": artdmx(port_address=0x7FFF, slots=bytes(i & 0xFF for i in range(512))),
            "dmx_odd": artdmx(slots=b"\x01\x02\x03"),
            "poll": artpoll(),
            "poll_v4_targeted": artpoll(0x22) + bytes([0, 0, 0, 1, 0, 0]),
            "old_protver": artdmx()[:10] + struct.pack(">H", 13) + artdmx()[12:],
            "sync": b"Art-Net\0" + struct.pack("<H", 0x5200) + struct.pack(">H", 14) + bytes(2),
        },
    }
    for kind, files in seeds.items():
        d = os.path.join(root, kind)
        os.makedirs(d, exist_ok=True)
        for name, data in files.items():
            with open(os.path.join(d, name + ".bin"), "wb") as f:
                f.write(data)
    return 0


if __name__ == "__main__":
    sys.exit(main())
