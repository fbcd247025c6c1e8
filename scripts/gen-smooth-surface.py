#!/usr/bin/env python3
"""Writes a large smooth closed surface: an icosahedron subdivided LEVEL times (20 * 4^LEVEL
triangles: 327,680 at level 7) and projected onto a sphere, each vertex then moved along
its radius by a smooth field of bumps (amplitude about 15% of the radius), as OFF.

usage: scripts/gen-smooth-surface.py LEVEL SEED OUT.off

Deterministic for a given SEED (which places the bumps).
"""
import math
import random
import sys


def icosahedron():
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    return [unit(p) for p in v], f


def unit(p):
    n = math.sqrt(sum(c * c for c in p))
    return tuple(c / n for c in p)


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    level, seed, out = int(argv[0]), int(argv[1]), argv[2]
    rng = random.Random(seed)
    pts, faces = icosahedron()
    for _ in range(level):
        mid = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                mid[key] = len(pts)
                pts.append(unit(tuple((x + y) / 2 for x, y in zip(pts[a], pts[b]))))
            return mid[key]

        nf = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = nf
    bumps = [(unit((rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1))), rng.uniform(-0.05, 0.05),
              rng.uniform(0.2, 0.6)) for _ in range(12)]

    def radius(p):
        r = 1.0
        for c, a, w in bumps:
            d2 = sum((x - y) ** 2 for x, y in zip(p, c))
            r += a * math.exp(-d2 / (w * w))
        return r

    with open(out, "w") as f:
        f.write("OFF\n")
        f.write(f"{len(pts)} {len(faces)} 0\n")
        for p in pts:
            r = radius(p)
            f.write(f"{p[0] * r!r} {p[1] * r!r} {p[2] * r!r}\n")
        for a, b, c in faces:
            f.write(f"3 {a} {b} {c}\n")


if __name__ == "__main__":
    main(sys.argv[1:])
