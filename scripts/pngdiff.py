#!/usr/bin/env python3
"""How much two renders of the same size differ, as a viewer would see it: the pixels whose
8-bit tone-mapped value differs by more than THRESHOLD/255 in some channel.

    scripts/pngdiff.py A.png B.png [--threshold 8] [--side-by-side OUT.png]

Prints "differing PIXELS of TOTAL (PERCENT%), largest difference MAX/255". --side-by-side writes
A, B and the differing pixels (white) next to each other. Standard library only: reads and
writes 8-bit RGB/RGBA PNGs, as glint writes them.
"""
import argparse
import struct
import sys
import zlib


def read_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit("pngdiff: %s: not a PNG" % path)
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                sys.exit("pngdiff: %s: only 8-bit RGB or RGBA, not interlaced" % path)
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line[k] for k in range(stride) if k % channels < 3))
        prev = line
    return width, height, rows


def write_png(path, width, height, rows):
    raw = b"".join(b"\0" + r for r in rows)
    chunk = lambda kind, body: struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--threshold", type=int, default=8, help="in 1/255 steps [8]")
    ap.add_argument("--side-by-side", metavar="OUT.png")
    args = ap.parse_args()
    wa, ha, ra = read_png(args.a)
    wb, hb, rb = read_png(args.b)
    if (wa, ha) != (wb, hb):
        sys.exit("pngdiff: %s is %dx%d, %s is %dx%d" % (args.a, wa, ha, args.b, wb, hb))
    count, largest, mask = 0, 0, []
    for y in range(ha):
        m = bytearray(3 * wa)
        for x in range(wa):
            d = max(abs(ra[y][3 * x + k] - rb[y][3 * x + k]) for k in range(3))
            largest = max(largest, d)
            if d > args.threshold:
                count += 1
                m[3 * x:3 * x + 3] = b"\xff\xff\xff"
        mask.append(bytes(m))
    print("differing %d of %d (%.1f%%), largest difference %d/255" % (count, wa * ha, 100.0 * count / (wa * ha),
                                                                      largest))
    if args.side_by_side:
        write_png(args.side_by_side, 3 * wa, ha, [ra[y] + rb[y] + mask[y] for y in range(ha)])


if __name__ == "__main__":
    main()
