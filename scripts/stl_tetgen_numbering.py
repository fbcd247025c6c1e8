#!/usr/bin/env python3
"""Writes an STL file as a .smesh whose points are numbered as in TetGen's output .node.

usage: stl_tetgen_numbering.py INPUT.stl TETGEN.node OUTPUT.smesh

An STL file repeats every triangle corner. TetGen numbers each welded point by the copy
its (randomized Hilbert) insertion order reaches first; tetcdt by its first appearance.
The symbolic perturbation breaks ties among cospherical points by these numbers, so the
two CDTs of a cospherical STL model differ. Meshed from this .smesh, the same PLC with
TetGen's numbering, ours must be TetGen's, tet for tet. Used by scripts/corpus.sh and
scripts/gen-stl-numbering.sh (corpus.sh's helper also reads STL with `corners`). Exits 1 if TetGen's points are not the STL's corners.
"""
import struct
import sys


def corners(path):
    """The triangle corners of an ASCII or binary STL file, three per triangle."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:5].lower() == b"solid" and b"facet" in data[:1000]:
        words = [l.split() for l in data.decode(errors="replace").splitlines()]
        return [tuple(float(c) for c in w[1:4]) for w in words if w[:1] == ["vertex"]]
    n = struct.unpack("<I", data[80:84])[0]
    out = []
    for k in range(n):
        vals = struct.unpack("<12f", data[84 + 50 * k: 84 + 50 * k + 48])
        out += [tuple(float(v) for v in vals[3 + 3 * j: 6 + 3 * j]) for j in range(3)]
    return out


def main():
    stl, node, out = sys.argv[1:4]
    cs = corners(stl)
    rows = [l.split() for l in open(node) if l.split() and not l.startswith("#")]
    n = int(rows[0][0])
    pts = [r[1:4] for r in rows[1:1 + n]]
    index = {tuple(float(c) for c in p): i for i, p in enumerate(pts)}
    if len(index) != len(set(cs)) or any(c not in index for c in cs):
        sys.exit(1)
    tris = [[index[c] for c in cs[k:k + 3]] for k in range(0, len(cs) - 2, 3)]
    tris = [t for t in tris if len(set(t)) == 3]
    with open(out, "w") as f:
        name = stl.rsplit("/", 1)[-1]
        f.write(f"# {name} with its points numbered as TetGen numbers them\n")
        f.write(f"{n} 3 0 0\n")
        for i, p in enumerate(pts):
            f.write(f"{i + 1} {' '.join(p)}\n")
        f.write(f"{len(tris)} 0\n")
        for t in tris:
            f.write(f"3 {t[0] + 1} {t[1] + 1} {t[2] + 1}\n")
        f.write("0\n0\n")


if __name__ == "__main__":
    main()
