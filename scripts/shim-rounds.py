#!/usr/bin/env python3
"""Rounds of changes to a model's input against the shims the referee counts.

usage: scripts/shim-rounds.py MODEL.off ROUNDS [--lens free|proj|mid] [--lens-after N]
           [--fallback-mid] [--margin M]
           [--presplit APEX,APEX,... [--per-doubling N] [--from R] [--phase] [--fan-degrees D]]
           [--bin PATH] [--tools DIR] [--work DIR]

The experiments on 112544.off in docs/112544.md. Each round writes the model as
a .poly (WORK/cur.poly; every triangle a facet) with the points added so far, meshes it
with `tetcdt -pQ` (WORK/out.*), finds the shims that validate_mesh.py would count
against the original MODEL.off (with scripts/shim-report.py's search), prints their
number, and adds points for the next round:

  - a shim whose circumcentre lies on the domain's side (a point a quarter of its
    longest edge from its centroid toward the circumcentre is inside the mesh) gets a
    free point, an isolated node of the .poly, one longest edge from the centroid on
    that side (half of it, a quarter, ... where that is outside the mesh or near an
    earlier free point);
  - a shim whose circumcentre lies beyond the surface is treated by --lens:
    `free` (the default) puts the free point on the other side, the domain's;
    `proj` splits a subsegment among its edges at the projection of one of its other
    vertices, where that falls in the piece's middle (all but a fraction --margin, 0.1,
    at either end); `mid` splits its longest subsegment at the midpoint. A split is an
    extra vertex of every polygon on the input edge. With --lens-after N such shims are
    treated as by `free` in the first N rounds; with --fallback-mid, `proj` splits at the
    midpoint where no projection falls inside.

--presplit splits, before the first round, every input edge that meets another at one
of the given apexes at under --fan-degrees (8) on the radii 2^(k/N) (N from
--per-doubling, 32) from --from (0.01) around the apex; --phase shifts each edge's radii
by a fraction of a step of its own, so that no two edges share a radius.

Only .off models (triangles or polygons without holes). It needs numpy; a round of
112544.off takes 20 to 40 s.
"""
import importlib.util
import math
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def option(argv, name, default):
    return argv[argv.index(name) + 1] if name in argv else default


def load_report():
    spec = importlib.util.spec_from_file_location("shim_report", os.path.join(HERE, "shim-report.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class Model:
    """The input with the points added to it."""

    def __init__(self, vm, path):
        self.pts, _raw, polys, self.facet_of, _holes = vm.read_off(path)
        self.polys = [list(p) for p in polys]
        self.diag = float(np.linalg.norm(self.pts.max(0) - self.pts.min(0)))
        self.edges = sorted({(min(p[k], p[(k + 1) % len(p)]), max(p[k], p[(k + 1) % len(p)]))
                             for p in self.polys for k in range(len(p))})
        self.e0 = self.pts[[a for a, _ in self.edges]]
        self.e1 = self.pts[[b for _, b in self.edges]]
        self.splits = {}  # edge index -> parameters along (a, b), a < b
        self.free = []

    def write_poly(self, path):
        pts = self.pts.tolist()
        on_edge = {}
        for k, ts in self.splits.items():
            a, b = self.edges[k]
            for t in sorted(set(ts)):
                on_edge.setdefault((a, b), []).append(len(pts))
                pts.append((self.pts[a] + t * (self.pts[b] - self.pts[a])).tolist())
        pts.extend(self.free)
        with open(path, "w") as f:
            f.write(f"{len(pts)} 3 0 0\n")
            f.writelines(f"{i} {p[0]!r} {p[1]!r} {p[2]!r}\n" for i, p in enumerate(pts))
            f.write(f"{len(self.polys)} 0\n")
            for p in self.polys:
                ring = []
                for k in range(len(p)):
                    a, b = p[k], p[(k + 1) % len(p)]
                    ring.append(a)
                    inner = on_edge.get((min(a, b), max(a, b)), [])
                    ring.extend(inner if a < b else inner[::-1])
                f.write(f"1 0\n{len(ring)} " + " ".join(map(str, ring)) + "\n")
            f.write("0\n0\n")

    def edge_at(self, x):
        """The input edge through point `x` (within 1e-9 of the diagonal) and the
        parameter of `x` on it, if any."""
        d = self.e1 - self.e0
        t = ((x - self.e0) * d).sum(1) / (d * d).sum(1)
        dist = np.linalg.norm(self.e0 + t[:, None] * d - x, axis=1)
        dist[(t <= 0) | (t >= 1)] = np.inf
        k = int(np.argmin(dist))
        return (k, float(t[k])) if dist[k] < 1e-9 * self.diag else None

    def fan_edges(self, apex, fan_degrees):
        """The input edges at `apex` that meet another edge there at under `fan_degrees`."""
        ks = [k for k, e in enumerate(self.edges) if apex in e]
        unit = {}
        for k in ks:
            d = self.pts[sum(self.edges[k]) - apex] - self.pts[apex]
            unit[k] = d / np.linalg.norm(d)
        cos_max = math.cos(math.radians(fan_degrees))
        return {i for i in ks for j in ks if i != j and unit[i] @ unit[j] > cos_max}

    def presplit(self, apexes, per_doubling, r_from, fan_degrees, phase):
        apex_of = {k: x for x in apexes for k in sorted(self.fan_edges(x, fan_degrees))}
        rng = np.random.default_rng(0)
        for k, x in sorted(apex_of.items()):
            a, b = self.edges[k]
            length = np.linalg.norm(self.pts[b] - self.pts[a])
            shift = rng.random() if phase else 0.0
            step = math.ceil(per_doubling * math.log2(r_from))
            ts = []
            while (r := 2 ** ((step + shift) / per_doubling)) < 0.98 * length:
                ts.append(r / length if x == a else 1 - r / length)
                step += 1
            self.splits[k] = ts
        return len(apex_of), sum(len(v) for v in self.splits.values())


def inside(P, T, x):
    """Is `x` in one of the tets (floating point; enough for choosing places)?"""
    A, B, C, D = (P[T[:, k]] for k in range(4))

    def vol(a, b, c, d):
        return np.einsum("ij,ij->i", a - d, np.cross(b - d, c - d))

    s = np.sign(vol(A, B, C, D))
    X = np.broadcast_to(x, A.shape)
    return bool(((np.sign(vol(X, B, C, D)) * s >= 0) & (np.sign(vol(A, X, C, D)) * s >= 0)
                 & (np.sign(vol(A, B, X, D)) * s >= 0) & (np.sign(vol(A, B, C, X)) * s >= 0)).any())


def circumcentre(V):
    return np.linalg.solve(2 * (V[1:] - V[0]), (V[1:] ** 2).sum(1) - V[0] @ V[0])


def add_free(model, P, T, centroid, u, d):
    for _ in range(6):
        x = centroid + u * d
        if inside(P, T, x) and all(np.linalg.norm(np.array(f) - x) > 0.25 * d for f in model.free):
            model.free.append(x.tolist())
            return True
        d *= 0.5
    return False


def split(model, V, how, fallback=False, margin=0.1):
    """Splits a subsegment among the tet's edges (`proj` or `mid`); whether it did."""
    best = None
    for i in range(4):
        for j in range(i + 1, 4):
            on = model.edge_at(0.5 * (V[i] + V[j]))
            if on is None:
                continue
            k = on[0]
            a, b = model.pts[model.edges[k][0]], model.pts[model.edges[k][1]]
            d = b - a
            ti, tj = sorted(((V[i] - a) @ d / (d @ d), (V[j] - a) @ d / (d @ d)))
            length = np.linalg.norm(V[i] - V[j])
            if best is not None and length <= best[0]:
                continue
            if how == "mid":
                best = (length, k, 0.5 * (ti + tj))
                continue
            for m in set(range(4)) - {i, j}:
                tm = (V[m] - a) @ d / (d @ d)
                if ti + margin * (tj - ti) < tm < tj - margin * (tj - ti):
                    best = (length, k, float(tm))
                    break
    if best is None and fallback:
        return split(model, V, "mid")
    if best is None:
        return False
    model.splits.setdefault(best[1], []).append(best[2])
    return True


def main(argv):
    report = load_report()
    vm = report.load_referee(argv)
    valued = {"--lens", "--lens-after", "--margin", "--presplit", "--per-doubling", "--from", "--fan-degrees", "--bin", "--tools", "--work"}
    args = [a for i, a in enumerate(argv) if not a.startswith("--") and (i == 0 or argv[i - 1] not in valued)]
    if len(args) != 2 or not args[0].endswith(".off"):
        sys.exit(__doc__)
    path, rounds = args[0], int(args[1])
    lens = option(argv, "--lens", "free")
    lens_after = int(option(argv, "--lens-after", "0"))
    fallback, margin = "--fallback-mid" in argv, float(option(argv, "--margin", "0.1"))
    if lens not in ("free", "proj", "mid"):
        sys.exit(__doc__)
    binary = option(argv, "--bin", os.path.join(HERE, "..", "target", "release", "tetcdt"))
    work = option(argv, "--work", ".")
    model = Model(vm, path)
    if "--presplit" in argv:
        apexes = [int(v) for v in option(argv, "--presplit", "").split(",") if v]
        edges, points = model.presplit(apexes, float(option(argv, "--per-doubling", "32")),
                                       float(option(argv, "--from", "0.01")),
                                       float(option(argv, "--fan-degrees", "8")), "--phase" in argv)
        print(f"split in advance: {edges} edges, {points} points", flush=True)
    history = []
    for r in range(rounds):
        poly, out = os.path.join(work, "cur.poly"), os.path.join(work, "out")
        model.write_poly(poly)
        run = subprocess.run([binary, "-pQ", poly, "-o", out], capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"round {r}: tetcdt exited {run.returncode}: {run.stderr.strip()[-400:]}")
        P, _raw, base, _ = vm.read_node(out + ".node")
        T = vm.read_ele(out + ".ele", base)
        found = report.find_shims(vm, model.pts, model.polys, model.facet_of, P, T)
        history.append(len(found))
        print(f"round {r}: {len(found)} shims ({len(model.free)} free points, "
              f"{sum(len(v) for v in model.splits.values())} split points added)", flush=True)
        if not found or r + 1 == rounds:
            break
        free = splits = 0
        for _gi, tv, _kind, _h in found:
            V = P[tv]
            centroid = V.mean(0)
            longest = max(np.linalg.norm(V[i] - V[j]) for i in range(4) for j in range(i + 1, 4))
            normal = np.linalg.svd(V - centroid)[2][2]
            try:
                toward = normal if (circumcentre(V) - centroid) @ normal > 0 else -normal
            except np.linalg.LinAlgError:
                toward = normal
            if inside(P, T, centroid + toward * longest * 0.25):
                free += add_free(model, P, T, centroid, toward, longest)
            elif lens == "free" or r < lens_after:
                free += add_free(model, P, T, centroid, -toward, longest)
            else:
                splits += split(model, V, lens, fallback, margin)
        print(f"   adding {free} free points and {splits} split points", flush=True)
    print("shims by round:", ", ".join(map(str, history)))


if __name__ == "__main__":
    main(sys.argv[1:])
