#!/usr/bin/env python3
"""Copies an LCM event log without the events of one channel, renumbering the rest.

bench/long_run.sh --without-ground-truth uses it to measure the pipeline's memory on input that carries no
ground truth (a `run` keeps every ground-truth state it reads, for the final ATE). Event layout (lcm-logger):
sync word 0xEDA1DA01, int64 event number, int64 utime, int32 channel length, int32 data length, channel,
data, all big-endian. The log's own checksum events are copied as they are; they then describe another
log, which `dynavins` reports and does not check.
Usage: drop_channel.py IN.lcmlog OUT.lcmlog CHANNEL
"""
import struct
import sys

SYNC = 0xEDA1DA01
HEADER = struct.Struct(">IqqII")


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    src, dst, drop = sys.argv[1], sys.argv[2], sys.argv[3].encode()
    n_in = n_out = 0
    with open(src, "rb", buffering=1 << 24) as f, open(dst, "wb", buffering=1 << 24) as g:
        while True:
            offset = f.tell()
            head = f.read(HEADER.size)
            if not head:
                break
            if len(head) < HEADER.size:
                sys.exit(f"{src}: truncated event header at byte {offset}")
            sync, _, utime, clen, dlen = HEADER.unpack(head)
            if sync != SYNC:
                sys.exit(f"{src}: no sync word at byte {offset} (event {n_in})")
            channel, data = f.read(clen), f.read(dlen)
            if len(channel) < clen or len(data) < dlen:
                sys.exit(f"{src}: truncated event at byte {offset} (event {n_in})")
            n_in += 1
            if channel == drop:
                continue
            g.write(HEADER.pack(sync, n_out, utime, clen, dlen))
            g.write(channel)
            g.write(data)
            n_out += 1
    print(f"drop_channel: {n_in} events in, {n_out} out ({n_in - n_out} on {drop.decode()} dropped)")


if __name__ == "__main__":
    main()
