#!/usr/bin/env python3
"""Writes nearly flat quad grids: a unit cube whose six sides are K x K quads, every grid
vertex moved off its side's plane by a random amount of at most D (so every quad is a
polygon that is not flat, and each side merges into one facet within TetGen's 0.1
degrees), with N random points inside the cube, half of them within 0.05 of a side.

usage: scripts/gen-flat-grids.py K D N SEED OUT.poly

Deterministic for a given SEED. TetGen meshes such models with no Steiner point on the
polygons; so must we (issue: insert only what the mesh needs).
"""
import random
import sys


def main(argv):
    if len(argv) != 5:
        sys.exit(__doc__)
    k, d, n, seed, out = int(argv[0]), float(argv[1]), int(argv[2]), int(argv[3]), argv[4]
    rng = random.Random(seed)
    index = {}
    pts = []

    def vertex(x, y, z, axis, lo):
        key = (x, y, z)
        if key not in index:
            p = [x / k, y / k, z / k]
            # Move the vertex off the side's plane, inward, unless it is on an edge of the
            # cube (shared with another side, which would then not be flat either).
            on_edge = sum(c in (0, k) for c in key) > 1
            if not on_edge:
                p[axis] += (1 if lo else -1) * d * rng.random()
            index[key] = len(pts)
            pts.append(p)
        return index[key]

    quads = []
    for axis in range(3):
        for lo in (True, False):
            c = 0 if lo else k
            u, w = (axis + 1) % 3, (axis + 2) % 3
            for i in range(k):
                for j in range(k):
                    ring = []
                    for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)):
                        key = [0, 0, 0]
                        key[axis], key[u], key[w] = c, a, b
                        ring.append(vertex(*key, axis, lo))
                    if lo:
                        ring.reverse()
                    quads.append(ring)
    for _ in range(n):
        p = [rng.uniform(0.01, 0.99) for _ in range(3)]
        if rng.random() < 0.5:
            axis = rng.randrange(3)
            p[axis] = rng.choice((rng.uniform(0.001, 0.05), rng.uniform(0.95, 0.999)))
        pts.append(p)
    with open(out, "w") as f:
        f.write(f"# gen-flat-grids.py {k} {d} {n} {seed}: a cube of {k}x{k} quads per side, "
                f"vertices off their plane by up to {d}, {n} points inside\n")
        f.write(f"{len(pts)} 3 0 0\n")
        for i, p in enumerate(pts):
            f.write(f"{i} {p[0]!r} {p[1]!r} {p[2]!r}\n")
        f.write(f"{len(quads)} 0\n")
        for q in quads:
            f.write(f"1\n4 {q[0]} {q[1]} {q[2]} {q[3]}\n")
        f.write("0\n0\n")


if __name__ == "__main__":
    main(sys.argv[1:])
