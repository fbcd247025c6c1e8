#!/usr/bin/env python3
"""Writes the binary test models of this directory (cube.bin.stl, cube_le.ply, cube_be.ply)
from the same unit cube as the text files beside them. Run from this directory."""
import struct

P = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
QUADS = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
TRIS = [t for a, b, c, d in QUADS for t in ((a, b, c), (a, c, d))]

# Binary STL whose 80-byte header starts with "solid", as some CAD programs write it.
with open("cube.bin.stl", "wb") as f:
    f.write(b"solid cube (binary, header padded with spaces)".ljust(80, b" "))
    f.write(struct.pack("<I", len(TRIS)))
    for t in TRIS:
        f.write(struct.pack("<3f", 0, 0, 0))
        for v in t:
            f.write(struct.pack("<3f", *P[v]))
        f.write(b"\0\0")

def ply(name, endian, fmt, count_t, index_t, prop):
    head = (
        f"ply\nformat {fmt} 1.0\ncomment unit cube, mixed property types\n"
        "element vertex 8\nproperty float x\nproperty uchar red\nproperty double y\n"
        "property short z\n"
        "element edge 1\nproperty list uchar int vertex_indices\n"
        f"element face 6\nproperty list {count_t[0]} {index_t[0]} {prop}\nproperty float quality\n"
        "end_header\n"
    )
    with open(name, "wb") as f:
        f.write(head.encode())
        for i, (x, y, z) in enumerate(P):
            f.write(struct.pack(endian + "fBdh", x, 200 + i, y, z))
        f.write(struct.pack(endian + "B2i", 2, 0, 6))
        for q in QUADS:
            f.write(struct.pack(endian + count_t[1], 4))
            f.write(struct.pack(endian + "4" + index_t[1], *q))
            f.write(struct.pack(endian + "f", 0.5))

ply("cube_le.ply", "<", "binary_little_endian", ("uchar", "B"), ("int", "i"), "vertex_indices")
ply("cube_be.ply", ">", "binary_big_endian", ("ushort", "H"), ("uint", "I"), "vertex_index")
