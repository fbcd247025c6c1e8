#!/usr/bin/env python3
"""Writes CSG parts as a solid modeller exports them: unions and differences of boxes,
cylinders and spheres computed by the manifold3d library (Apache-2.0,
https://github.com/elalish/manifold), turned by a random rotation, and every coordinate
rounded to 6 significant digits, as an OFF triangle soup. Rounding leaves the
tessellated flat faces a little off flat and the triangles of curved faces nearly
coplanar with their neighbours.

usage: scripts/gen-csg-parts.py KIND SEED OUT.off [--scale S]

KIND:
  cheese   a box with 20 to 60 spherical and cylindrical holes, some cutting its faces;
  flange   a disc with a hub, a bore, and 6 to 16 bolt holes on one or two circles;
  bricks   a union of 10 to 30 boxes and cylinders at random places and slight tilts,
           minus a few of them.
--scale S multiplies the number of circle segments (default 1: 24 to 48 per circle).

Deterministic for a given SEED and manifold3d version. Made for this project (no
third-party data). Needs `pip install manifold3d`.
"""
import math
import random
import sys

try:
    import manifold3d as mf
    import numpy as np
except ImportError:
    sys.exit("gen-csg-parts.py: needs manifold3d and numpy (pip install manifold3d)")


def rotation(rng):
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(x * x for x in q))
    a, b, c, d = (x / n for x in q)
    return np.array([[a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)],
                     [2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)],
                     [2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d]])


def cylinder(r, h, seg, center=True):
    return mf.Manifold.cylinder(h, r, r, seg, center)


def cheese(rng, scale):
    size = [rng.uniform(8, 14), rng.uniform(6, 10), rng.uniform(4, 8)]
    part = mf.Manifold.cube(size, True)
    for _ in range(rng.randint(20, 60)):
        c = [rng.uniform(-s / 2, s / 2) for s in size]
        r = rng.uniform(0.3, 1.4)
        if rng.random() < 0.7:
            hole = mf.Manifold.sphere(r, int(scale * rng.choice([16, 24, 32])))
        else:
            hole = cylinder(r * 0.6, rng.uniform(1, 6), int(scale * rng.choice([16, 24, 32])))
            hole = hole.rotate([rng.uniform(0, 180), rng.uniform(0, 180), 0])
        part = part - hole.translate(c)
    return part


def flange(rng, scale):
    seg = int(scale * rng.choice([32, 48, 64]))
    r_out = rng.uniform(8, 12)
    t = rng.uniform(1, 2.5)
    disc = cylinder(r_out, t, seg)
    hub = cylinder(r_out * rng.uniform(0.35, 0.5), t + rng.uniform(2, 5), seg).translate(
        [0, 0, rng.uniform(1, 2)])
    part = disc + hub
    part = part - cylinder(r_out * rng.uniform(0.15, 0.3), 40, seg)
    circles = rng.choice([1, 2])
    for k in range(circles):
        n = rng.randint(6, 16 // circles)
        rr = r_out * (0.75 if k == 0 else 0.58)
        hr = rng.uniform(0.4, 0.8)
        for i in range(n):
            a = 2 * math.pi * (i + 0.5 * k) / n
            part = part - cylinder(hr, 40, int(scale * 24)).translate(
                [rr * math.cos(a), rr * math.sin(a), 0])
    return part


def bricks(rng, scale):
    part = mf.Manifold.cube([4, 4, 1], True)
    shapes = []
    for _ in range(rng.randint(10, 30)):
        if rng.random() < 0.6:
            s = mf.Manifold.cube([rng.uniform(0.5, 3) for _ in range(3)], True)
        else:
            s = cylinder(rng.uniform(0.3, 1.2), rng.uniform(0.5, 3),
                         int(scale * rng.choice([24, 32, 48])))
        s = s.rotate([rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(0, 90)])
        shapes.append(s.translate([rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-1, 2)]))
    for s in shapes:
        part = part + s
    for s in rng.sample(shapes, k=min(3, len(shapes))):
        part = part - s.scale([0.5, 0.5, 1.5])
    return part


KINDS = {"cheese": cheese, "flange": flange, "bricks": bricks}


def main(argv):
    args = list(argv[1:])
    scale = 1.0
    if "--scale" in args:
        i = args.index("--scale")
        scale = float(args[i + 1])
        del args[i:i + 2]
    if len(args) != 3 or args[0] not in KINDS:
        print(__doc__, file=sys.stderr)
        return 2
    kind, seed, out = args[0], int(args[1]), args[2]
    rng = random.Random(f"{kind}/{seed}")
    part = KINDS[kind](rng, scale)
    mesh = part.to_mesh()
    pts = np.asarray(mesh.vert_properties)[:, :3] @ rotation(rng).T
    tris = np.asarray(mesh.tri_verts)
    with open(out, "w") as f:
        f.write(f"OFF\n{len(pts)} {len(tris)} 0\n")
        for p in pts:
            f.write(" ".join(f"{x:.6g}" for x in p) + "\n")
        for t in tris:
            f.write(f"3 {t[0]} {t[1]} {t[2]}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
