#!/usr/bin/env python3
"""Writes CAD-like parts as a solid modeller exports them: built exactly, then turned by
a random rotation and every coordinate rounded to 6 significant digits, so that their
flat faces are a little off flat and neighbouring faces a little off coplanar.

usage: scripts/gen-cad-parts.py KIND SEED OUT.poly
       scripts/gen-cad-parts.py KIND SEED OUT.off --tessellate TETCDT

With --tessellate, the part is written as a surface mesh exporters make: its faces
triangulated (by TETCDT's CDT of the exact part: slivers at the holes), then turned and
rounded, as an OFF triangle soup.

KIND:
  plate   a plate with 3 to 12 round holes (24- to 48-gons), top and bottom one facet
          each with the holes as hole polygons;
  blocks  a union of unit boxes on a 7x7x3 grid (random, connected), its boundary as unit
          squares (coplanar neighbours merge into larger facets);
  bracket an L-shaped extrusion with two round holes through each flange.

Deterministic for a given SEED. Made for this project (no third-party data).
"""
import math
import random
import sys


def rotation(rng):
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(x * x for x in q))
    a, b, c, d = (x / n for x in q)
    return [[a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
            [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
            [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d]]


def round6(x):
    return float(f"{x:.6g}")


class Part:
    def __init__(self):
        self.pts, self.index, self.facets, self.holes = [], {}, [], []

    def v(self, p):
        key = tuple(round(c, 9) for c in p)
        if key not in self.index:
            self.index[key] = len(self.pts)
            self.pts.append(tuple(p))
        return self.index[key]

    def facet(self, rings, holes=()):
        self.facets.append(([[self.v(p) for p in r] for r in rings], list(holes)))

    def write(self, out, rot, comment):
        def tr(p):
            return tuple(round6(sum(rot[i][k] * p[k] for k in range(3))) for i in range(3))
        with open(out, "w") as f:
            f.write(f"# {comment}\n")
            f.write(f"{len(self.pts)} 3 0 0\n")
            for i, p in enumerate(self.pts):
                q = tr(p)
                f.write(f"{i} {q[0]!r} {q[1]!r} {q[2]!r}\n")
            f.write(f"{len(self.facets)} 0\n")
            for rings, holes in self.facets:
                f.write(f"{len(rings)} {len(holes)}\n")
                for r in rings:
                    f.write(f"{len(r)} " + " ".join(map(str, r)) + "\n")
                for j, h in enumerate(holes):
                    q = tr(h)
                    f.write(f"{j} {q[0]!r} {q[1]!r} {q[2]!r}\n")
            f.write("0\n0\n")


def circle(c, r, n, z):
    return [(c[0] + r * math.cos(2 * math.pi * k / n), c[1] + r * math.sin(2 * math.pi * k / n), z)
            for k in range(n)]


def prism_with_holes(part, outline, holes, z0, z1):
    """An extrusion of `outline` (counterclockwise, 2D) from z0 to z1 with round holes
    (center, radius, sides) through it."""
    bottom = [list(reversed([(x, y, z0) for x, y in outline]))]
    top = [[(x, y, z1) for x, y in outline]]
    hb, ht = [], []
    for c, r, n in holes:
        cb, ct = circle(c, r, n, z0), circle(c, r, n, z1)
        bottom.append(cb)
        top.append(list(reversed(ct)))
        hb.append((c[0], c[1], z0))
        ht.append((c[0], c[1], z1))
        for k in range(n):
            a, b = k, (k + 1) % n
            part.facet([[cb[a], ct[a], ct[b], cb[b]]])
    part.facet(bottom, hb)
    part.facet(top, ht)
    m = len(outline)
    for k in range(m):
        (x0, y0), (x1, y1) = outline[k], outline[(k + 1) % m]
        part.facet([[(x0, y0, z0), (x1, y1, z0), (x1, y1, z1), (x0, y0, z1)]])


def plate(rng):
    part = Part()
    w, h = 10.0, 6.0
    holes = []
    for _ in range(rng.randint(3, 12)):
        for _ in range(100):
            r = rng.uniform(0.3, 0.9)
            c = (rng.uniform(r + 0.3, w - r - 0.3), rng.uniform(r + 0.3, h - r - 0.3))
            if all(math.dist(c, d) > r + s + 0.2 for d, s, _ in holes):
                holes.append((c, r, rng.choice((24, 32, 48))))
                break
    prism_with_holes(part, [(0, 0), (w, 0), (w, h), (0, h)], holes, 0.0, 1.0)
    return part


def bracket(rng):
    part = Part()
    t = rng.uniform(0.4, 0.8)
    outline = [(0, 0), (6, 0), (6, t), (t, t), (t, 4), (0, 4)]
    # Extruded along z; holes go through the flanges along y and x, so they are walls of
    # the extrusion: keep it simple with holes through the extrusion's caps instead.
    holes = [((t / 2 + 2.5, t / 2), min(0.25, t / 3), 24)] if t > 0.5 else []
    prism_with_holes(part, outline, holes, 0.0, 3.0)
    return part


def blocks(rng):
    part = Part()
    n = (7, 7, 3)
    filled = set()
    cell = (3, 3, 0)
    filled.add(cell)
    for _ in range(rng.randint(25, 60)):
        x, y, z = rng.choice(sorted(filled))
        d = rng.choice([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)])
        c = (x + d[0], y + d[1], z + d[2])
        if all(0 <= c[i] < n[i] for i in range(3)):
            filled.add(c)
    for (x, y, z) in sorted(filled):
        for axis in range(3):
            for s in (0, 1):
                nb = [x, y, z]
                nb[axis] += 1 if s else -1
                if tuple(nb) in filled:
                    continue
                u, w = (axis + 1) % 3, (axis + 2) % 3
                corners = []
                for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = [x, y, z]
                    p[axis] += s
                    p[u] += a
                    p[w] += b
                    corners.append(tuple(float(c) for c in p))
                if not s:
                    corners.reverse()
                part.facet([corners])
    return part


def tessellate(part, rot, tetcdt, out, comment):
    """Writes the part's boundary triangles (from tetcdt's CDT of the exact part), turned
    and rounded, as OFF."""
    import os
    import subprocess
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        exact = os.path.join(d, "part.poly")
        ident = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        part.write(exact, ident, "exact")
        subprocess.run([tetcdt, "-pQz", "-o", os.path.join(d, "m"), exact], check=True)
        rows = [l.split() for l in open(os.path.join(d, "m.face")) if l.strip() and l[0] != "#"]
        tris = [tuple(int(x) for x in r[1:4]) for r in rows[1:1 + int(rows[0][0])]]
        nrows = [l.split() for l in open(os.path.join(d, "m.node")) if l.strip() and l[0] != "#"]
        pts = [tuple(float(x) for x in r[1:4]) for r in nrows[1:1 + int(nrows[0][0])]]
    used = sorted({v for t in tris for v in t})
    new = {v: i for i, v in enumerate(used)}
    with open(out, "w") as f:
        # No comment line: TetGen's OFF reader does not take one.
        f.write(f"OFF\n{len(used)} {len(tris)} 0\n")
        for v in used:
            p = pts[v]
            q = [round6(sum(rot[i][k] * p[k] for k in range(3))) for i in range(3)]
            f.write(f"{q[0]!r} {q[1]!r} {q[2]!r}\n")
        for t in tris:
            f.write("3 " + " ".join(str(new[v]) for v in t) + "\n")


def main(argv):
    if len(argv) not in (3, 5):
        sys.exit(__doc__)
    kind, seed, out = argv[0], int(argv[1]), argv[2]
    rng = random.Random(seed)
    part = {"plate": plate, "blocks": blocks, "bracket": bracket}[kind](rng)
    comment = f"gen-cad-parts.py {kind} {seed}: turned and rounded to 6 significant digits"
    if len(argv) == 5 and argv[3] == "--tessellate":
        tessellate(part, rotation(rng), argv[4], out, comment + ", tessellated")
    else:
        part.write(out, rotation(rng), comment)


if __name__ == "__main__":
    main(sys.argv[1:])
