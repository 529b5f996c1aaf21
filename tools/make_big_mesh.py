#!/usr/bin/env python3
"""Writes a big closed test mesh (a latitude-longitude sphere) as binary little-endian PLY, for the
5-million-triangle benchmark of docs/ROBUSTNESS.md. Never committed: write it to /tmp.

    python3 tools/make_big_mesh.py /tmp/sphere5m.ply [--triangles 5000000]

The sphere has radius 1, two poles and `rings` rings of `2 * rings` vertices; its triangle count is
4 * rings * rings (two poles' fans and the quads between rings), the smallest such count at or
above --triangles. Pure Python (array + struct), no numpy: about 20 s for 5 million triangles.
"""
import argparse
import array
import math
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("output")
    ap.add_argument("--triangles", type=int, default=5_000_000)
    a = ap.parse_args()
    rings = max(2, math.ceil(math.sqrt(a.triangles / 4)))
    lon = 2 * rings
    # Vertices: north pole, rings 1..rings (latitude), south pole.
    nv = 2 + rings * lon
    nf = 2 * lon + 2 * lon * (rings - 1)
    pos = array.array("f", bytes(12 * nv))
    pos[2] = 1.0
    cosl = [math.cos(2 * math.pi * j / lon) for j in range(lon)]
    sinl = [math.sin(2 * math.pi * j / lon) for j in range(lon)]
    k = 3
    for i in range(1, rings + 1):
        theta = math.pi * i / (rings + 1)
        z, r = math.cos(theta), math.sin(theta)
        for j in range(lon):
            pos[k] = r * cosl[j]
            pos[k + 1] = r * sinl[j]
            pos[k + 2] = z
            k += 3
    pos[k + 2] = -1.0
    south = nv - 1
    # Faces: one byte count (3) and three int32 indices each, counter-clockwise seen from outside.
    rec = array.array("i")

    def ring(i, j):
        return 1 + (i - 1) * lon + (j % lon)

    for j in range(lon):
        rec.extend((0, ring(1, j), ring(1, j + 1)))
    for i in range(1, rings):
        for j in range(lon):
            a0, a1, b0, b1 = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            rec.extend((a0, b0, b1))
            rec.extend((a0, b1, a1))
    for j in range(lon):
        rec.extend((south, ring(rings, j + 1), ring(rings, j)))
    assert len(rec) == 3 * nf
    if sys.byteorder != "little":
        pos.byteswap()
        rec.byteswap()
    tri = rec.tobytes()
    with open(a.output, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\ncomment sffd tools/make_big_mesh.py: %d rings\n"
                 "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                 "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (rings, nv, nf)).encode())
        f.write(pos.tobytes())
        # Interleave the count byte with each 12-byte index triple, in slices to bound memory.
        step = 12 * 65536
        for s in range(0, len(tri), step):
            part = tri[s:s + step]
            out = bytearray(len(part) // 12 * 13)
            out[0::13] = b"\x03" * (len(part) // 12)
            for c in range(12):
                out[1 + c::13] = part[c::12]
            f.write(out)
    print("%s: %d vertices, %d triangles" % (a.output, nv, nf))


if __name__ == "__main__":
    main()
