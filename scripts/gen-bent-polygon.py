#!/usr/bin/env python3
"""Writes a Figure 9 input with a polygon that is not flat: a regular K-gon of radius 2.5
around the z axis whose vertices are off the plane z = 0 by up to DEV (uniform, signed),
and N random points in [-1, 1]^2 x [-0.1, 0.1] (none on z = 0). A TetGen .poly; mesh it
with -pc (one polygon encloses no volume).

usage: scripts/gen-bent-polygon.py N OUT.poly SEED DEV K
"""
import math
import random
import sys


def main(argv):
    if len(argv) != 6:
        print(__doc__, file=sys.stderr)
        return 2
    n, out, seed, dev, k = int(argv[1]), argv[2], int(argv[3]), float(argv[4]), int(argv[5])
    rng = random.Random(seed)
    pts = []
    for i in range(k):
        t = 2 * math.pi * i / k + 0.1
        pts.append((2.5 * math.cos(t), 2.5 * math.sin(t), dev * rng.uniform(-1, 1)))
    while len(pts) < n + k:
        z = rng.uniform(-0.1, 0.1)
        if z != 0.0:
            pts.append((rng.uniform(-1, 1), rng.uniform(-1, 1), z))
    with open(out, "w") as f:
        f.write(f"# {k}-gon off its plane by up to {dev:g}, {n} points near it (seed {seed}).\n")
        f.write("# Written by scripts/gen-bent-polygon.py; do not edit.\n")
        f.write(f"{len(pts)} 3 0 0\n")
        for i, p in enumerate(pts):
            f.write(f"{i + 1} {p[0]!r} {p[1]!r} {p[2]!r}\n")
        f.write(f"1 0\n1\n{k} {' '.join(str(i + 1) for i in range(k))}\n0\n0\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
