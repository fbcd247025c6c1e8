#!/usr/bin/env python3
"""What the shims that validate_mesh.py counts in a mesh are made of.

usage: scripts/shim-report.py INPUT OUT_PREFIX [--list] [--spheres] [--tools DIR]

The referee (../shared/tools/validate_mesh.py, imported from DIR, by default the first
of ../shared/tools and /work/shared/tools that has it) merges edge-adjacent polygons
within 0.1 degrees, and counts a flat tet as a shim when its four vertices all lie on
one merged group: the group's own input vertices, or Steiner points inside the group's
bounding box and within its slab (four times the group's deviation from its plane).
This script finds the same shims and sorts each vertex into one of three kinds:

  I  an input vertex of the group;
  S  a Steiner point on one of the group's own edges;
  F  a "foreign" Steiner point: on no edge of the group, but inside its slab.

It prints how many shims there are of each composition, then the heights of the
foreign vertices above the group's plane as fractions of the slab's half-thickness.
With --list it also prints every shim. With --spheres it tells, for each shim with a face
on the mesh boundary, which side of that face its circumsphere's centre lies on: beyond
the surface (a "lens": inside the domain the sphere is only as thick as its reach there,
so no point well off the slab can remove the tet; the surface points must change) or in
the domain (a free point inside the sphere removes it), with the sphere's reach into the
domain against the slab's half-thickness. The figures on attene_cdt/112544.off in
docs/112544.md come from this script. It needs numpy.
"""
import os
import sys

import numpy as np


def load_referee(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    dirs = [os.path.join(here, "..", "..", "shared", "tools"), "/work/shared/tools"]
    if "--tools" in argv:
        dirs.insert(0, argv[argv.index("--tools") + 1])
    for d in dirs:
        if os.path.isfile(os.path.join(d, "validate_mesh.py")):
            sys.path.insert(0, d)
            import validate_mesh

            return validate_mesh
    sys.exit("shim-report.py: validate_mesh.py not found (use --tools DIR)")


def read_input(vm, path):
    ext = path.rsplit(".", 1)[-1].lower()
    readers = {
        "poly": lambda p: vm.read_poly(p),
        "smesh": lambda p: vm.read_poly(p, smesh=True),
        "off": vm.read_off,
        "mesh": vm.read_medit,
    }
    if ext not in readers:
        sys.exit(f"shim-report.py: unsupported input {path}")
    pts, _raw, polys, facet_of, _holes = readers[ext](path)
    return pts, polys, facet_of


def group_slab(vm, P, gpolys, diag):
    """The referee's plane and slab for a merged group's polygons, computed as it computes
    them: the unit normal of the largest polygon, the group's vertices, their mean, and
    the slab's half-thickness."""
    normals = [vm.newell_normal(P[q]) for q in gpolys]
    nrm = normals[int(np.argmax([np.linalg.norm(n) for n in normals]))]
    nrm = nrm / np.linalg.norm(nrm)
    own = sorted({v for q in gpolys for v in q})
    mean = P[own].mean(0)
    tol = max(1e-10 * diag, 4 * np.abs((P[own] - mean) @ nrm).max())
    return nrm, own, mean, tol


def find_shims(vm, ipts, polys, facet_of, P, T):
    """The referee's shims in mesh (P, T) of the PLC (ipts, polys, facet_of): for each,
    its merged group's index, its four vertices, their kinds (I, S or F) and the heights
    of its foreign vertices as fractions of the slab's half-thickness."""
    where = {}
    for i, q in enumerate(map(tuple, P.tolist())):
        where.setdefault(q, i)
    to_out = np.array([where.get(tuple(q), -1) for q in ipts.tolist()])
    kept = {int(x) for x in to_out if x >= 0}
    polys = [vm.dedup_ring([int(to_out[v]) for v in poly]) for poly in polys]
    _s, det = vm.orient3d_signs(P, T[:, 0], T[:, 1], T[:, 2], T[:, 3])
    diag = float(np.linalg.norm(P.max(0) - P.min(0))) or 1.0
    steiner = np.array(sorted(set(range(len(P))) - kept), dtype=np.int64)
    tets_of_vertex = {}
    for t, tv in enumerate(T.tolist()):
        for v in tv:
            tets_of_vertex.setdefault(v, []).append(t)
    groups, _edges = vm.merge_coplanar(P, polys, facet_of)

    def on_edge(v, a, b):
        d = P[b] - P[a]
        length = np.linalg.norm(d)
        t = (P[v] - P[a]) @ d / length**2
        return 0 < t < 1 and np.linalg.norm(np.cross(P[v] - P[a], d)) / length < 1e-9 * diag

    found = []
    for gi, group in enumerate(groups):
        gpolys = [polys[i] for i in group if len(polys[i]) >= 3]
        if not gpolys:
            continue
        nrm, own, mean, tol = group_slab(vm, P, gpolys, diag)
        Q = P[own]
        lo, hi = Q.min(0) - tol, Q.max(0) + tol
        S = P[steiner]
        near = np.all((S >= lo) & (S <= hi), axis=1) & (np.abs((S - mean) @ nrm) <= tol)
        verts = set(own) | set(steiner[near].tolist())
        edges = {(min(q[k], q[(k + 1) % len(q)]), max(q[k], q[(k + 1) % len(q)]))
                 for q in gpolys for k in range(len(q))}
        for v in verts:
            for t in tets_of_vertex.get(v, ()):
                tv = [int(x) for x in T[t]]
                if min(tv) != v or not all(x in verts for x in tv):
                    continue
                longest = max(np.linalg.norm(P[tv[i]] - P[tv[j]]) for i in range(4) for j in range(i + 1, 4))
                if abs(det[t]) / 6.0 > 1e-3 * longest**3:
                    continue
                kind, heights = [], []
                for x in tv:
                    if x in own:
                        kind.append("I")
                    elif any(on_edge(x, a, b) for a, b in edges):
                        kind.append("S")
                    else:
                        kind.append("F")
                        heights.append(abs((P[x] - mean) @ nrm) / tol)
                found.append((gi, tv, "".join(kind), heights))
    return found


def sphere_sides(P, T, found):
    """For each shim of `found` with a face on the mesh boundary: whether its circumsphere's
    centre lies beyond that face (outside the domain), and how far the sphere reaches into
    the domain from the face's plane. None for shims without a boundary face."""
    faces = {}
    for t, tv in enumerate(T.tolist()):
        for k in range(4):
            key = tuple(sorted(tv[:k] + tv[k + 1:]))
            faces[key] = faces.get(key, 0) + 1
    out = []
    for _gi, tv, _kind, _h in found:
        side = None
        for k in range(4):
            f = sorted(tv[:k] + tv[k + 1:])
            if faces.get(tuple(f)) != 1:
                continue
            a, b, c = P[f]
            n = np.cross(b - a, c - a)
            n /= np.linalg.norm(n)
            if (P[tv[k]] - a) @ n < 0:
                n = -n  # towards the domain: the tet's own fourth vertex
            q = P[tv]
            try:
                centre = np.linalg.solve(2 * (q[1:] - q[0]), (q[1:] ** 2).sum(1) - (q[0] ** 2).sum())
            except np.linalg.LinAlgError:
                break
            radius = np.linalg.norm(centre - q[0])
            height = (centre - a) @ n
            side = (height < 0, radius + height)
            break
        out.append(side)
    return out


def main(argv):
    vm = load_referee(argv)
    args, skip = [], False
    for a in argv:
        if skip:
            skip = False
        elif a == "--tools":
            skip = True
        elif not a.startswith("--"):
            args.append(a)
    if len(args) != 2:
        sys.exit(__doc__)
    inp, prefix = args
    ipts, polys, facet_of = read_input(vm, inp)
    P, _raw, base, _ = vm.read_node(prefix + ".node")
    T = vm.read_ele(prefix + ".ele", base)
    kinds, heights = {}, []
    found = find_shims(vm, ipts, polys, facet_of, P, T)
    for gi, tv, kind, h in found:
        heights.extend(h)
        key = "".join(sorted(kind))
        kinds[key] = kinds.get(key, 0) + 1
        if "--list" in argv:
            print(f"group {gi} tet {tv} kinds {kind}")
    print(f"shims: {len(found)}")
    for key, n in sorted(kinds.items(), key=lambda x: -x[1]):
        print(f"  {key}: {n}")
    if heights:
        q = np.percentile(heights, [0, 25, 50, 75, 100])
        print(f"foreign vertices: {len(heights)}; height / slab half-thickness: "
              f"min {q[0]:.2f}, quartiles {q[1]:.2f} {q[2]:.2f} {q[3]:.2f}, max {q[4]:.2f}")
    if "--spheres" in argv:
        sides = sphere_sides(P, T, found)
        lens = [r for s in sides if s and s[0] for r in [s[1]]]
        inside = [r for s in sides if s and not s[0] for r in [s[1]]]
        print(f"with a boundary face: {len(lens) + len(inside)}; centre beyond the surface "
              f"(lens): {len(lens)}, in the domain: {len(inside)}")
        for name, rs in (("lens", lens), ("in the domain", inside)):
            if rs:
                q = np.percentile(rs, [0, 50, 100])
                print(f"  {name}: reach into the domain min {q[0]:.2e}, median {q[1]:.2e}, "
                      f"max {q[2]:.2e}")


if __name__ == "__main__":
    main(sys.argv[1:])
