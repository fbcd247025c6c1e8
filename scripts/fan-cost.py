#!/usr/bin/env python3
"""Estimates how many points a layer of well-shaped cells would need over the fans of
needle triangles of a surface model (docs/112544.md, twenty-fourth round).

usage: scripts/fan-cost.py MODEL.off [--angle DEG] [--r0 R] [--apexes A,B,...]

A fan's cell is a triangle's corner with an angle under DEG degrees (default 1) at its
apex A; its two edges from A are spokes. Cells about as long as they are wide need the
spokes split on rings r, r(1 + alpha), r(1 + alpha)^2, ... from r0 (default 0.01) out to
the spoke's end, alpha being the smallest cell angle beside the spoke, in radians: about
ln(R / r0) / alpha points on a spoke R long. A layer of interior points, one per cell
and ring, needs about ln(R / r0) / alpha more per cell, R being its shorter spoke.
Prints the totals over the model and, with --apexes, per apex (0-based vertex ids).
"""
import math
import sys
from collections import defaultdict


def read_off(path):
    """Vertices and triangles of an OFF file (polygons fanned from their first corner)."""
    words = []
    for line in open(path):
        line = line.split("#", 1)[0]
        words.extend(line.split())
    if not words or words[0].upper() != "OFF":
        raise SystemExit(f"fan-cost.py: {path}: not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    pos = 4
    pts = []
    for _ in range(nv):
        pts.append(tuple(float(x) for x in words[pos:pos + 3]))
        pos += 3
    tris = []
    for _ in range(nf):
        k = int(words[pos])
        ring = [int(x) for x in words[pos + 1:pos + 1 + k]]
        pos += 1 + k
        tris.extend((ring[0], ring[i], ring[i + 1]) for i in range(1, k - 1))
    return pts, tris


def length(a, b):
    return math.dist(a, b)


def angle_at(pts, a, b, c):
    """The angle at a of triangle (a, b, c), in radians."""
    u = [pts[b][i] - pts[a][i] for i in range(3)]
    v = [pts[c][i] - pts[a][i] for i in range(3)]
    nu, nv = math.hypot(*u), math.hypot(*v)
    if nu == 0 or nv == 0:
        return math.pi
    cos = sum(u[i] * v[i] for i in range(3)) / (nu * nv)
    return math.acos(max(-1.0, min(1.0, cos)))


def main(argv):
    args = list(argv[1:])
    if not args or args[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if args else 2
    model = args.pop(0)
    opts = {"--angle": "1", "--r0": "0.01", "--apexes": ""}
    while args:
        key = args.pop(0)
        if key not in opts or not args:
            raise SystemExit(f"fan-cost.py: unknown or incomplete option {key} (see --help)")
        opts[key] = args.pop(0)
    limit = math.radians(float(opts["--angle"]))
    r0 = float(opts["--r0"])
    pts, tris = read_off(model)
    spoke_alpha = defaultdict(lambda: math.inf)
    cells = []  # (apex, angle, shorter spoke's length)
    for t in tris:
        for k in range(3):
            a, b, c = t[k], t[(k + 1) % 3], t[(k + 2) % 3]
            alpha = angle_at(pts, a, b, c)
            if alpha < limit and alpha > 0:
                cells.append((a, alpha, min(length(pts[a], pts[b]), length(pts[a], pts[c]))))
                for x in (b, c):
                    spoke_alpha[(a, x)] = min(spoke_alpha[(a, x)], alpha)

    def rings(r, alpha):
        return math.log(r / r0) / alpha if r > r0 else 0.0

    def totals(only=None):
        spokes = sum(rings(length(pts[a], pts[x]), al)
                     for (a, x), al in spoke_alpha.items() if only is None or a == only)
        layer = sum(rings(r, al) for a, al, r in cells if only is None or a == only)
        return spokes, layer

    if not cells:
        print(f"no corner under {opts['--angle']} degrees")
        return 0
    spokes, layer = totals()
    print(f"corners under {opts['--angle']} deg: {len(cells)} at {len({c[0] for c in cells})} apexes, "
          f"{len(spoke_alpha)} spokes; smallest {math.degrees(min(c[1] for c in cells)):.4f} deg")
    print(f"points from r0 = {r0}: {spokes:,.0f} on spokes, {layer:,.0f} in the layer")
    for apex in filter(None, opts["--apexes"].split(",")):
        a = int(apex)
        mine = [c for c in cells if c[0] == a]
        if not mine:
            print(f"apex {a}: no corner under {opts['--angle']} deg")
            continue
        s, l = totals(a)
        print(f"apex {a}: {len(mine)} corners, smallest {math.degrees(min(c[1] for c in mine)):.4f} deg, "
              f"{s:,.0f} points on spokes, {l:,.0f} in the layer")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
