#!/usr/bin/env python3
"""Lay out preview PNGs in a grid, for the examples' README pictures (standard library only).

    scripts/png_grid.py OUT.png --row a.png b.png --row c.png d.png

Each --row is one row of images, left to right; every image must have the same size. Reads
8-bit RGB or RGBA PNGs (any filter, not interlaced: what ghostfx's previews write) and writes
an 8-bit RGB PNG, with a 4-pixel dark gap between the images.
"""
import argparse
import struct
import sys
import zlib

GAP = 4
GAP_COLOUR = (20, 20, 24)


def read_png(path):
    """(width, height, rows of RGB bytes) of an 8-bit RGB or RGBA PNG."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"png_grid: '{path}': not a PNG file")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        sys.exit(f"png_grid: '{path}': expected an 8-bit RGB or RGBA PNG, not interlaced")
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        unfilter(kind, line, previous, channels)
        rows.append(bytes(line if channels == 3 else rgb_of(line)))
        previous = line
    return width, height, rows


def unfilter(kind, line, previous, bpp):
    """Undo one scanline's PNG filter in place (PNG spec, section 9)."""
    for i in range(len(line)):
        left = line[i - bpp] if i >= bpp else 0
        up = previous[i]
        corner = previous[i - bpp] if i >= bpp else 0
        if kind == 1:
            line[i] = (line[i] + left) & 255
        elif kind == 2:
            line[i] = (line[i] + up) & 255
        elif kind == 3:
            line[i] = (line[i] + (left + up) // 2) & 255
        elif kind == 4:
            p = left + up - corner
            pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
            pred = left if pa <= pb and pa <= pc else (up if pb <= pc else corner)
            line[i] = (line[i] + pred) & 255


def rgb_of(rgba):
    out = bytearray()
    for i in range(0, len(rgba), 4):
        out += rgba[i:i + 3]
    return out


def write_png(path, width, height, rows):
    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))
    raw = b"".join(b"\x00" + row for row in rows)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--row", nargs="+", action="append", required=True)
    args = parser.parse_args()
    grid = [[read_png(p) for p in row] for row in args.row]
    w, h = grid[0][0][0], grid[0][0][1]
    for row, paths in zip(grid, args.row):
        for (wi, hi, _), p in zip(row, paths):
            if (wi, hi) != (w, h):
                sys.exit(f"png_grid: '{p}' is {wi} x {hi}, expected {w} x {h} like the first")
    columns = max(len(r) for r in grid)
    width = columns * w + (columns - 1) * GAP
    gap_pixel = bytes(GAP_COLOUR)
    out = []
    for k, row in enumerate(grid):
        if k:
            out += [gap_pixel * width] * GAP
        for y in range(h):
            line = b""
            for c in range(columns):
                if c:
                    line += gap_pixel * GAP
                line += row[c][2][y] if c < len(row) else gap_pixel * w
            out.append(line)
    write_png(args.out, width, len(out), out)


if __name__ == "__main__":
    main()
