#!/usr/bin/python3
"""Converts an X window dump (`xwd -root`, 24/32-bit TrueColor) to PNG, for README screenshots taken
under Xvfb without ImageMagick. Usage: xwd_to_png.py IN.xwd OUT.png [--crop X Y W H]"""
import struct
import sys

import matplotlib.image
import numpy as np


def read_xwd(path):
    data = open(path, "rb").read()
    if len(data) < 100:
        sys.exit(f"{path}: too short for an XWD header ({len(data)} bytes)")
    h = struct.unpack(">25I", data[:100])
    header_size, width, height = h[0], h[4], h[5]
    byte_order, bits_per_pixel, bytes_per_line, ncolors = h[7], h[11], h[12], h[19]
    if bits_per_pixel != 32:
        sys.exit(f"{path}: {bits_per_pixel} bits per pixel; only 32 (24-bit TrueColor screens) is supported")
    start = header_size + 12 * ncolors
    need = start + bytes_per_line * height
    if len(data) < need:
        sys.exit(f"{path}: truncated: {len(data)} bytes, the header says {need}")
    rows = np.frombuffer(data[start:need], dtype=np.uint8).reshape(height, bytes_per_line)
    px = rows[:, : width * 4].reshape(height, width, 4)
    return px[:, :, [2, 1, 0]] if byte_order == 0 else px[:, :, [1, 2, 3]]  # LSB first: B G R x


def main():
    if len(sys.argv) not in (3, 8):
        sys.exit(__doc__)
    img = read_xwd(sys.argv[1])
    if len(sys.argv) == 8:
        x, y, w, h = map(int, sys.argv[4:8])
        img = img[y : y + h, x : x + w]
    matplotlib.image.imsave(sys.argv[2], np.ascontiguousarray(img))


if __name__ == "__main__":
    main()
