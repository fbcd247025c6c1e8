#!/usr/bin/env python3
"""Rings on the spokes of needle fans and a layer of free points above them, against the
shims the referee counts.

usage: scripts/fan-layer.py MODEL.off WORK_DIR --apexes A,B,... [--ring-c C] [--r0 R0]
           [--height-factor F] [--skip-encroaching K] [--tall-apex T] [--fit-heights]
           [--off-slabs] [--no-free] [--flags FLAGS] [--bin PATH] [--tools DIR]

The experiment of the eighteenth and nineteenth rounds on attene_cdt/112544.off (see
docs/112544.md). At each apex, the input edges that meet another edge there at under 8
degrees (the spokes of a fan of needle triangles) are split on the same radii, r0 and then
r + C*sqrt(r) (C from --ring-c, 0.004; r0 from --r0, 0.01), so that the pieces of
neighbouring spokes form isosceles trapezoids (cocircular, so the flat tets folded over a
spoke have their circumspheres centred near the surface, not far beyond it). Every cell
between two spokes of a fan triangle then gets a free point (an isolated node of the
.poly) above its centre, on the domain's side, at F (--height-factor, 1.5) times the
largest slab half-thickness the referee gives the merged facets at the apex: inside the
folded tets' circumspheres, outside every slab. With --skip-encroaching K, a cell gets no
point when its spoke pieces could no longer be Delaunay edges with the point in: when a
sphere through a piece's ends must lie deeper than K times the spokes' distance apart
there to leave the point out (that depth is (p^2/4 - h^2)/(2h) for a piece p long and a
point h high).

With --tall-apex T, the needle cells at the apex (between the apex and the first ring)
get their points anyway, but higher: at T * r0 / 2 (T a little over 1 puts the point
just outside the diametral sphere of the spoke pieces beside it), or higher still if the
sphere through the cell's circle and the point would otherwise hold a point of another
spoke. A cell gets none when no height keeps every such point out. With --fit-heights,
the other cells are held to the same test: a cell's point goes at F slabs, or at 1.25
times the lowest admissible height if that is higher (halfway to the highest if 1.25
times is too high), and a cell whose admissible heights all lie below F slabs gets none.

The points keep their distance from the surface, but a point can still lie in the slab
of a merged facet elsewhere, within that facet's box, where the referee counts it as a
vertex of the facet (at an apex whose fan is not flat, points above one triangle can
lie in another's plane). With --off-slabs such points are dropped.

It writes WORK_DIR/cur.poly (every triangle a facet), meshes it with FLAGS (default
`-pQM`) into WORK_DIR/out, and prints the shims by merged facet and by distance from the
first apex. It needs numpy.
"""
import importlib.util
import math
import os
import subprocess
import sys
from collections import Counter

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def load(name, file):
    spec = importlib.util.spec_from_file_location(name, os.path.join(HERE, file))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class Slabs:
    """The referee's slab of every merged facet. A Steiner point inside one, within the
    facet's box, counts as lying on that facet."""

    def __init__(self, vm, report, model):
        groups, _ = vm.merge_coplanar(model.pts, model.polys, model.facet_of)
        self.tol = {}  # polygon -> the slab half-thickness of its merged facet
        rows = []
        for g in groups:
            nrm, own, mean, tol = report.group_slab(vm, model.pts, [model.polys[i] for i in g], model.diag)
            self.tol.update((i, tol) for i in g)
            q = model.pts[own]
            rows.append((nrm, mean, tol, q.min(0) - tol, q.max(0) + tol))
        self.nrm, self.mean, self.half, self.lo, self.hi = (np.array([r[k] for r in rows]) for k in range(5))

    def holds(self, x):
        """Whether the referee would count point `x` as lying on some merged facet."""
        box = np.all((x >= self.lo) & (x <= self.hi), axis=1)
        off = np.abs(np.einsum("ij,ij->i", x - self.mean[box], self.nrm[box]))
        return bool((off <= self.half[box]).any())


class Surface:
    """The input triangles: which side of them a point is on, and how far."""

    def __init__(self, model):
        tris = np.array([(p[0], p[k], p[k + 1]) for p in model.polys for k in range(1, len(p) - 1)])
        self.a, self.b, self.c = (model.pts[tris[:, i]] for i in range(3))
        self.centre = (self.a + self.b + self.c) / 3
        self.radius = np.max([np.linalg.norm(x - self.centre, axis=1) for x in (self.a, self.b, self.c)], axis=0)

    def inside(self, o):
        """Ray parity along a direction no input edge is likely to lie on."""
        d = np.array([0.5773, 0.5774, 0.5775])
        e1, e2 = self.b - self.a, self.c - self.a
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-300
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = o - self.a
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        return int((ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)).sum()) % 2 == 1

    def distance(self, x, reach):
        """Distance from `x` to the nearest triangle that comes within `reach` of it (inf
        if none does)."""
        near = np.linalg.norm(self.centre - x, axis=1) <= self.radius + reach
        if not near.any():
            return math.inf
        a, b, c = self.a[near], self.b[near], self.c[near]
        n = np.cross(b - a, c - a)
        n = n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
        h = np.einsum("ij,ij->i", x - a, n)
        q = x - h[:, None] * n

        def side(u, v):
            return np.einsum("ij,ij->i", np.cross(v - u, q - u), n)

        def seg(u, v):
            d = v - u
            t = np.clip(np.einsum("ij,ij->i", x - u, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0, 1)
            return np.linalg.norm(u + t[:, None] * d - x, axis=1)

        within = (side(a, b) >= 0) & (side(b, c) >= 0) & (side(c, a) >= 0)
        edge = np.minimum(np.minimum(seg(a, b), seg(b, c)), seg(c, a))
        return float(np.where(within, np.abs(h), edge).min())


def fan_edges(model, apex):
    """The spokes of the fan at `apex` (see shim-rounds.py), with directions and lengths."""
    fan = {}
    for k in model.fan_edges(apex, 8):
        d = model.pts[sum(model.edges[k]) - apex] - model.pts[apex]
        fan[k] = (d / np.linalg.norm(d), float(np.linalg.norm(d)))
    return fan


def circle(a, b, c):
    """Centre and squared radius of the circle through three points."""
    ab, ac = b - a, c - a
    w = np.cross(ab, ac)
    centre = a + (np.cross(w, ab) * (ac @ ac) + np.cross(ac, w) * (ab @ ab)) / (2 * (w @ w))
    return centre, float((a - centre) @ (a - centre))


def heights(corners, m, up, others):
    """The heights h at which the sphere through the circle of `corners` and the point
    m + h * up leaves out every point of `others` within three radii of the circle's
    centre (the spheres wanted are not much larger than the circle): (lowest, highest),
    or None.

    The sphere's centre lies t = (h^2 + d^2 - R^2) / (2h) along `up` from the circle's
    centre (d: m's distance from it), which grows with h. A point at z along `up`, and
    at squared distance R^2 + e from the circle's centre, is out when e >= 2 t z: that
    bounds t from above for points on the `up` side and from below for the others."""
    centre, r2 = circle(*corners)
    d2 = float((m - centre) @ (m - centre))
    near = others[np.sum((others - centre) ** 2, axis=1) < 9 * r2]
    e = np.sum((near - centre) ** 2, axis=1) - r2
    z = (near - centre) @ up
    if np.any((z == 0) & (e < 0)):
        return None
    t_hi = float(np.min(e[z > 0] / (2 * z[z > 0]))) if (z > 0).any() else math.inf
    t_lo = float(np.max(e[z < 0] / (2 * z[z < 0]))) if (z < 0).any() else -math.inf
    if t_lo > t_hi:
        return None

    def h(t):
        return t + math.sqrt(t * t + r2 - d2)

    return (h(t_lo) if t_lo > -math.inf else 0.0), (h(t_hi) if t_hi < math.inf else math.inf)


def layer(model, surface, tol, apex, ring_c, r0, factor, skip, tall, fit, off_slabs):
    """Splits the fan's spokes on shared rings and returns the free points above its cells."""
    fan = fan_edges(model, apex)
    if not fan:
        return 0, 0, []
    radii = [r0]
    longest = max(length for _, length in fan.values())
    while radii[-1] < longest:
        radii.append(radii[-1] + ring_c * math.sqrt(radii[-1]))
    for k, (_, length) in fan.items():
        a, _b = model.edges[k]
        model.splits[k] = [r / length if a == apex else 1 - r / length for r in radii if r < 0.98 * length]
    top = model.pts[apex]
    ring = np.array(radii)
    on_spoke = {k: top + np.outer(ring[ring < 0.98 * length], d) for k, (d, length) in fan.items()}
    polys = [i for i, p in enumerate(model.polys) if apex in p]
    height = factor * max(tol[i] for i in polys)
    points = []
    for i in polys:
        p = model.polys[i]
        j = p.index(apex)
        ends = [p[(j + 1) % len(p)], p[j - 1]]
        ks = [model.edges.index((min(apex, e), max(apex, e))) for e in ends]
        if not all(k in fan for k in ks):
            continue
        (du, lu), (dv, lv) = fan[ks[0]], fan[ks[1]]
        corners = model.pts[p]
        n = np.cross(corners[1] - corners[0], corners[2] - corners[0])
        n /= np.linalg.norm(n)
        angle = math.acos(min(1.0, float(du @ dv)))
        rr = [0.0] + [r for r in radii if r < 0.98 * min(lu, lv)]
        fitting = tall or fit
        others = np.concatenate([on_spoke[k] for k in fan if k not in ks] + [np.zeros((0, 3))]) if fitting else None
        side = None
        for r1, r2 in zip(rr, rr[1:]):
            piece, apart = r2 - r1, angle * (r1 + r2) / 2
            m = top + (du + dv) / 2 * (r1 + r2) / 2
            if side is None:
                side = 1.0 if surface.inside(m + n * height) else -1.0
            apex_cell = tall and r1 == 0
            if not apex_cell and skip > 0 and (piece * piece / 4 - height * height) / (2 * height) > skip * apart:
                continue
            h = height
            if apex_cell or fit:
                corners = [top + du * r1 if r1 else top + du * r2, top + dv * r1, top + dv * r2]
                span = heights(corners, m, side * n, others)
                if span is None:
                    continue
                lo, hi = span
                if apex_cell:
                    if max(lo, tall * r2 / 2) > hi:
                        continue
                    h = max(lo, tall * r2 / 2, height)
                else:
                    if hi < height:
                        continue
                    h = max(height, 1.25 * lo)
                    if h > hi:
                        h = (max(height, lo) + hi) / 2
            x = m + side * n * h
            if off_slabs is not None and off_slabs.holds(x):
                continue
            if surface.distance(x, 2 * h) >= 0.9 * height and surface.inside(x):
                points.append(x.tolist())
    return len(fan), len(radii), points


def main(argv):
    shim_rounds = load("shim_rounds", "shim-rounds.py")
    option = shim_rounds.option
    report = shim_rounds.load_report()
    vm = report.load_referee(argv)
    valued = {"--apexes", "--ring-c", "--r0", "--height-factor", "--skip-encroaching", "--tall-apex", "--flags",
              "--bin", "--tools"}
    args = [a for i, a in enumerate(argv) if not a.startswith("--") and (i == 0 or argv[i - 1] not in valued)]
    if len(args) != 2 or not args[0].endswith(".off") or "--apexes" not in argv:
        sys.exit(__doc__)
    path, work = args
    apexes = [int(v) for v in option(argv, "--apexes", "").split(",") if v]
    ring_c = float(option(argv, "--ring-c", "0.004"))
    r0 = float(option(argv, "--r0", "0.01"))
    factor = float(option(argv, "--height-factor", "1.5"))
    skip = float(option(argv, "--skip-encroaching", "0"))
    tall = float(option(argv, "--tall-apex", "0"))
    flags = option(argv, "--flags", "-pQM").split()
    binary = option(argv, "--bin", os.path.join(HERE, "..", "target", "release", "tetcdt"))
    os.makedirs(work, exist_ok=True)
    model = shim_rounds.Model(vm, path)
    slabs = Slabs(vm, report, model)
    surface = Surface(model)
    for apex in apexes:
        edges, rings, points = layer(model, surface, slabs.tol, apex, ring_c, r0, factor, skip, tall,
                                      "--fit-heights" in argv, slabs if "--off-slabs" in argv else None)
        if "--no-free" not in argv:
            model.free.extend(points)
        print(f"apex {apex}: {edges} spokes, {rings} rings, {len(points)} free points", flush=True)
    poly, out = os.path.join(work, "cur.poly"), os.path.join(work, "out")
    model.write_poly(poly)
    run = subprocess.run([binary, *flags, poly, "-o", out], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"tetcdt exited {run.returncode}: {run.stderr.strip()[-400:]}")
    P, _raw, base, _ = vm.read_node(out + ".node")
    T = vm.read_ele(out + ".ele", base)
    found = report.find_shims(vm, model.pts, model.polys, model.facet_of, P, T)
    print(f"{len(P)} points, {len(T)} tets, {len(found)} shims")
    print("by merged facet:", ", ".join(f"{g}: {n}" for g, n in Counter(g for g, *_ in found).most_common(10)))
    bands = [0, 0.01, 0.1, 1, 3, math.inf]
    dist = [float(np.linalg.norm(P[tv].mean(0) - model.pts[apexes[0]])) for _g, tv, *_ in found]
    counts = np.histogram(dist, bins=bands)[0] if dist else [0] * (len(bands) - 1)
    print(f"by distance from apex {apexes[0]}:",
          ", ".join(f"[{lo}, {hi}): {n}" for lo, hi, n in zip(bands, bands[1:], counts)))


if __name__ == "__main__":
    main(sys.argv[1:])
