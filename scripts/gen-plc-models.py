#!/usr/bin/env python3
"""Writes the small PLC test models in data/plc/ (used by tests/plc.rs).

Deterministic: running it again rewrites the same files byte for byte. Coordinates are
printed with repr(), the shortest text that reads back as the same double.

  python3 scripts/gen-plc-models.py [--corpus DIR]

It writes two kinds of files:

1. Hand-made models (project license), described in data/plc/README.md:
   a. prism_n{8,40}_d{1e-5,1e-8}_s{1,1000}.poly: prisms whose top and bottom are single
      n-gons with vertices off their plane by d*size, and whose side quads are bent (one
      vertex of each moved off the quad's plane by d*size);
   b. fig4_*.poly: the configuration of Figure 4 of the polygon-insertion paper: a nearly
      flat quadrilateral facet abcd (cocircular in projection, a and b raised by e, c and
      d lowered by e) with p just above and q just below it, inside the circumsphere of
      abcd;
   c. cosph_*.poly: 32 exactly cospherical integer points (a cube's corners and 24 more
      points on its circumsphere): their convex hull, and the hull with the cube inside as
      internal facets (two regions);
   d. gridbox_*.smesh: boxes whose faces are split into grids of coplanar quads;
   e. box_internal_facet.poly (two regions with attributes), box_cavity.poly (a cavity
      carved by a hole point), ushape.poly (non-convex; its hull is a box, for -c);
   f. window_wall.poly, windows.poly: walls with windows (hole polygons with hole points)
      that other facets fill, with markers of their own or the wall's;
   g. degenerate_tris.off, degenerate_tris_{obj,ply,ascii,binary}.*: one closed
      surface whose files add triangles with a repeated corner (a literal repeat, and two
      corners at one point after welding), which the readers drop;
   h. flat_grid_{6,8}.poly: cubes of quads a little off their plane with points inside
      (scripts/gen-flat-grids.py), which need no Steiner point.
2. Copies of small corpus models (unmodified), with data/plc/LICENSES.md built from the
   corpus MANIFEST.tsv. Skipped, keeping the copies already present, when the corpus is
   not found ($CORPUS, --corpus DIR, or ../shared/corpus relative to the repository).
"""
import hashlib
import math
import os
import random
import shutil
import struct
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "data", "plc")

# Small corpus models copied into data/plc (corpus path -> file name here).
CORPUS_COPIES = [
    "cgal/cube_quad.off",
    "cgal/schonhardt.off",
    "tetgentests/slit-1.smesh",
    "tetgentests/wedge-1.smesh",
    "tetgentests/spike-5-7.smesh",
    "tetgentests_cgal/star.off",
    "tetgentests_cgal/hole.off",
    "tetgentests_cgal/sphere.off",
    "tetgentests_cgal/blob-closed.off",
    "tetgentests_cgal/eight.off",
    "attene_cdt/flat_cavity_face.off",
    # Facets meeting at a 0.0012 step: valid only with a point found by another
    # construction (retries for thick tets on facets, src/constrained/mod.rs).
    "tetgentests_cgal/mpi.off",
    # Refinement once split its facet x = -0.5 ever finer around one point, far below
    # the insertion floor (tests/quality.rs).
    "tetgentests_cgal/handle.off",
    # Refinement once went round a cycle of splits (a subface split moved to an edge
    # already waiting) on femur.off, and on boeing.off joined split points to vertices
    # nearer than the floor by its flips (tests/quality.rs).
    "tetgentests_cgal/femur.off",
    "tetgentests_cgal/boeing.off",
]


def fmt(x):
    """Shortest round-trip text of a coordinate; integers without '.0'."""
    if isinstance(x, int):
        return str(x)
    if x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return repr(float(x))


def write_poly(name, comment, pts, facets, holes=(), regions=(), first=0, markers=True):
    """facets: list of (list of polygons (vertex index lists, 0-based), facet holes, marker)."""
    lines = [f"# {l}" for l in comment.strip().splitlines()]
    lines.append(f"# Written by scripts/gen-plc-models.py; do not edit.")
    lines.append(f"{len(pts)} 3 0 0")
    for i, p in enumerate(pts):
        lines.append(f"{i + first} {fmt(p[0])} {fmt(p[1])} {fmt(p[2])}")
    lines.append(f"{len(facets)} {1 if markers else 0}")
    for polys, fholes, marker in facets:
        head = f"{len(polys)} {len(fholes)}"
        if markers:
            head += f" {marker}"
        lines.append(head)
        for poly in polys:
            lines.append(f"{len(poly)} " + " ".join(str(v + first) for v in poly))
        for j, h in enumerate(fholes):
            lines.append(f"{j + first} {fmt(h[0])} {fmt(h[1])} {fmt(h[2])}")
    lines.append(f"{len(holes)}")
    for j, h in enumerate(holes):
        lines.append(f"{j + first} {fmt(h[0])} {fmt(h[1])} {fmt(h[2])}")
    lines.append(f"{len(regions)}")
    for j, r in enumerate(regions):
        # x y z attribute volume-bound (-1: none)
        lines.append(f"{j + first} {fmt(r[0])} {fmt(r[1])} {fmt(r[2])} {fmt(r[3])} -1")
    with open(os.path.join(OUT, name), "w") as f:
        f.write("\n".join(lines) + "\n")


def write_smesh(name, comment, pts, polys, first=1):
    lines = [f"# {l}" for l in comment.strip().splitlines()]
    lines.append(f"# Written by scripts/gen-plc-models.py; do not edit.")
    lines.append(f"{len(pts)} 3 0 0")
    for i, p in enumerate(pts):
        lines.append(f"{i + first} {fmt(p[0])} {fmt(p[1])} {fmt(p[2])}")
    lines.append(f"{len(polys)} 1")
    for poly, marker in polys:
        lines.append(f"{len(poly)} " + " ".join(str(v + first) for v in poly) + f" {marker}")
    lines.append("0")  # holes
    lines.append("0")  # regions
    with open(os.path.join(OUT, name), "w") as f:
        f.write("\n".join(lines) + "\n")


def single(poly, marker):
    return ([poly], [], marker)


def box_facets(v, marker=1):
    """The six quads of a box given its 8 corner indices v[x][y][z] (x, y, z in 0/1)."""
    return [
        single([v[0][0][0], v[0][1][0], v[1][1][0], v[1][0][0]], marker),  # z = lo
        single([v[0][0][1], v[1][0][1], v[1][1][1], v[0][1][1]], marker),  # z = hi
        single([v[0][0][0], v[1][0][0], v[1][0][1], v[0][0][1]], marker),  # y = lo
        single([v[0][1][0], v[0][1][1], v[1][1][1], v[1][1][0]], marker),  # y = hi
        single([v[0][0][0], v[0][0][1], v[0][1][1], v[0][1][0]], marker),  # x = lo
        single([v[1][0][0], v[1][1][0], v[1][1][1], v[1][0][1]], marker),  # x = hi
    ]


def add_box(pts, lo, hi):
    v = [[[0, 0], [0, 0]], [[0, 0], [0, 0]]]
    for x in (0, 1):
        for y in (0, 1):
            for z in (0, 1):
                v[x][y][z] = len(pts)
                pts.append((hi[0] if x else lo[0], hi[1] if y else lo[1], hi[2] if z else lo[2]))
    return v


# ---------- a. prisms with non-flat n-gon top and bottom, bent side quads ----------

def prism(n, d, size, center, tag):
    rng = random.Random(1000 * n + int(round(-math.log10(d))) + int(size))
    r = 0.5 * size
    dev = d * size
    cx, cy, cz = center
    bottom, top = [], []
    for i in range(n):
        t = 2 * math.pi * i / n
        x, y = math.cos(t), math.sin(t)
        x, y = (0.0 if abs(x) < 1e-12 else x), (0.0 if abs(y) < 1e-12 else y)
        # bottom and top: off their planes by up to dev, alternating in sign
        zb = cz - 0.5 * size + dev * (1 if i % 2 else -1) * rng.uniform(0.5, 1.0)
        zt = cz + 0.5 * size + dev * (-1 if i % 2 else 1) * rng.uniform(0.5, 1.0)
        # side quads bent: every other top vertex moved radially by dev, so each side quad
        # (b_i, b_i+1, t_i+1, t_i) has exactly one vertex off its (vertical) plane
        rt = r + (dev * (1 if i % 4 == 0 else -1) if i % 2 == 0 else 0.0)
        bottom.append((cx + r * x, cy + r * y, zb))
        top.append((cx + rt * x, cy + rt * y, zt))
    pts = bottom + top
    facets = [single(list(range(n - 1, -1, -1)), 1), single(list(range(n, 2 * n)), 2)]
    for i in range(n):
        j = (i + 1) % n
        facets.append(single([i, j, n + j, n + i], 3))
    comment = (f"Prism over a regular {n}-gon of circumradius {fmt(r)} and height {fmt(size)}, centred at "
               f"{center}.\nTop and bottom are single {n}-gons whose vertices are off their plane by "
               f"{fmt(dev)} ({d:g} x size),\nalternating up and down; every other top vertex is moved "
               f"radially by {fmt(dev)}, so each side quad is bent.")
    write_poly(f"prism_{tag}.poly", comment, pts, facets)


# ---------- b. Figure 4 of the paper ----------

def fig4_inner(tag, with_p, with_q, e=1e-5):
    """Box [-1,1]^3 with a floating internal quad a c b d (diagonals ab, cd) at z ~ 0."""
    pts = []
    v = add_box(pts, (-1, -1, -1), (1, 1, 1))
    r = 0.5
    a = len(pts); pts.append((r, 0, e))
    b = len(pts); pts.append((-r, 0, e))
    c = len(pts); pts.append((0, r, -e))
    d = len(pts); pts.append((0, -r, -e))
    facets = box_facets(v) + [single([a, c, b, d], 2)]
    extra = []
    if with_p:
        pts.append((0.013, 0.007, 0.1)); extra.append("p = (0.013, 0.007, 0.1) above")
    if with_q:
        pts.append((-0.011, 0.005, -0.09)); extra.append("q = (-0.011, 0.005, -0.09) below")
    comment = ("Figure 4 of the polygon-insertion paper. Box [-1,1]^3 with a floating internal facet:\n"
               f"the quad a c b d, a = ({r}, 0, {e:g}), b = (-{r}, 0, {e:g}), c = (0, {r}, -{e:g}), "
               f"d = (0, -{r}, -{e:g});\nabcd is cocircular in projection, its circumsphere has radius "
               f"about {r} around the origin.\n" + ("Isolated vertices: " + "; ".join(extra) if extra
                                                   else "No vertex inside the circumsphere: abcd is a shim."))
    write_poly(f"fig4_{tag}.poly", comment, pts, facets)


def fig4_split(e=1e-5):
    """Box [-1,1]^3 cut in two by a facet whose four corners are slightly off z = 0."""
    pts = []
    lo = [(x, y, -1) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    mid = [(-1, -1, e), (1, -1, -e), (1, 1, e), (-1, 1, -e)]
    hi = [(x, y, 1) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    pts = lo + mid + hi
    L, M, H = 0, 4, 8
    facets = [single([L + 3, L + 2, L + 1, L + 0], 1), single([H + 0, H + 1, H + 2, H + 3], 1),
              single([M + 0, M + 1, M + 2, M + 3], 2)]
    for i in range(4):
        j = (i + 1) % 4
        facets.append(single([L + i, L + j, M + j, M + i], 1))
        facets.append(single([M + i, M + j, H + j, H + i], 1))
    pts.append((0.013, 0.007, 0.1))
    pts.append((-0.011, 0.005, -0.09))
    comment = ("Figure 4 of the polygon-insertion paper, variant: box [-1,1]^3 cut by the facet of its four\n"
               f"mid-height corners, lifted alternately by +-{e:g} (a, b up; c, d down); p = (0.013, 0.007, 0.1)\n"
               "and q = (-0.011, 0.005, -0.09) lie inside the circumsphere of the four corners.\n"
               "Two regions: attribute 1 above, 2 below.")
    write_poly("fig4_split.poly", comment, pts, facets,
               regions=[(0.5, 0.5, 0.5, 1), (0.5, 0.5, -0.5, 2)])


# ---------- c. cospherical vertices ----------

def cospherical_points():
    pts = [(x, y, z) for x in (-3, 3) for y in (-3, 3) for z in (-3, 3)]
    for axis in range(3):
        for s in (-5, 5):
            for u in (-1, 1):
                for w in (-1, 1):
                    p = [0, 0, 0]
                    p[axis] = s
                    p[(axis + 1) % 3] = u
                    p[(axis + 2) % 3] = w
                    pts.append(tuple(p))
    assert all(x * x + y * y + z * z == 27 for x, y, z in pts)
    return pts


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def hull_facets(pts):
    """Convex hull facets of integer points (exact), each as a polygon ordered
    counter-clockwise seen from outside."""
    n = len(pts)
    planes = {}
    for i in range(n):
        for j in range(i + 1, n):
            for k in range(j + 1, n):
                nrm = cross(sub(pts[j], pts[i]), sub(pts[k], pts[i]))
                if nrm == (0, 0, 0):
                    continue
                g = math.gcd(math.gcd(abs(nrm[0]), abs(nrm[1])), abs(nrm[2]))
                nrm = tuple(c // g for c in nrm)
                off = dot(nrm, pts[i])
                side = [dot(nrm, p) - off for p in pts]
                if all(s <= 0 for s in side):
                    pass
                elif all(s >= 0 for s in side):
                    nrm, off = tuple(-c for c in nrm), -off
                else:
                    continue
                planes[nrm] = off
    facets = []
    for nrm, off in sorted(planes.items()):
        on = [i for i, p in enumerate(pts) if dot(nrm, p) == off]
        cx = sum(pts[i][0] for i in on) / len(on)
        cy = sum(pts[i][1] for i in on) / len(on)
        cz = sum(pts[i][2] for i in on) / len(on)
        # a basis of the plane
        ref = sub(pts[on[0]], (cx, cy, cz))
        other = cross(nrm, ref)
        on.sort(key=lambda i: math.atan2(dot(sub(pts[i], (cx, cy, cz)), other),
                                         dot(sub(pts[i], (cx, cy, cz)), ref)))
        facets.append(on)
    return facets


def cospherical():
    pts = cospherical_points()
    hull = hull_facets(pts)
    comment = ("32 exactly cospherical integer points (x^2 + y^2 + z^2 = 27): the corners (+-3, +-3, +-3) of a\n"
               "cube and the 24 permutations of (+-5, +-1, +-1). The model is their convex hull, one facet per\n"
               f"hull plane ({len(hull)} facets, polygons with 3 to 4 vertices).")
    write_poly("cosph_hull.poly", comment, pts, [single(f, 1) for f in hull])
    v = [[[0, 0], [0, 0]], [[0, 0], [0, 0]]]
    for i, (x, y, z) in enumerate(pts[:8]):
        v[x > 0][y > 0][z > 0] = i
    comment = ("The convex hull of cosph_hull.poly (32 cospherical points) with the inscribed cube [-3,3]^3,\n"
               "whose corners are hull vertices, as internal facets. Two regions: attribute 1 inside the\n"
               "cube, 2 between the cube and the hull.")
    write_poly("cosph_cube.poly", comment, pts, [single(f, 1) for f in hull] + box_facets(v, 2),
               regions=[(0, 0, 0, 1), (4, 0, 0, 2)], first=1)


# ---------- d. boxes whose faces are grids of coplanar quads ----------

def gridbox(nx, ny, nz, name):
    idx = {}
    pts = []

    def vid(x, y, z):
        if (x, y, z) not in idx:
            idx[(x, y, z)] = len(pts)
            pts.append((x, y, z))
        return idx[(x, y, z)]

    quads = []
    dims = (nx, ny, nz)
    for axis in range(3):
        u_ax, w_ax = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, dims[axis]):
            for i in range(dims[u_ax]):
                for j in range(dims[w_ax]):
                    corners = []
                    for du, dw in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis] = side
                        p[u_ax] = i + du
                        p[w_ax] = j + dw
                        corners.append(vid(*p))
                    if side == 0:
                        corners.reverse()
                    quads.append((corners, axis + 1))
    comment = (f"Box [0,{nx}]x[0,{ny}]x[0,{nz}] whose faces are split into unit quads, each its own facet\n"
               f"({len(quads)} quads; marker = 1 + the face's normal axis). Coplanar neighbours merge unless -M.")
    write_smesh(name, comment, pts, quads)


# ---------- e. regions, holes, hull ----------

def box_internal_facet():
    pts = []
    # x = 0, 1, 2 slices of the box [0,2]x[0,1]x[0,1]
    grid = {}
    for x in (0, 1, 2):
        for y in (0, 1):
            for z in (0, 1):
                grid[(x, y, z)] = len(pts)
                pts.append((x, y, z))
    g = grid
    facets = [
        single([g[(0, 0, 0)], g[(0, 0, 1)], g[(0, 1, 1)], g[(0, 1, 0)]], 1),
        single([g[(2, 0, 0)], g[(2, 1, 0)], g[(2, 1, 1)], g[(2, 0, 1)]], 1),
        single([g[(1, 0, 0)], g[(1, 1, 0)], g[(1, 1, 1)], g[(1, 0, 1)]], 2),  # internal
    ]
    for a, b in ((0, 1), (1, 2)):
        facets.append(single([g[(a, 0, 0)], g[(a, 1, 0)], g[(b, 1, 0)], g[(b, 0, 0)]], 1))
        facets.append(single([g[(a, 0, 1)], g[(b, 0, 1)], g[(b, 1, 1)], g[(a, 1, 1)]], 1))
        facets.append(single([g[(a, 0, 0)], g[(b, 0, 0)], g[(b, 0, 1)], g[(a, 0, 1)]], 1))
        facets.append(single([g[(a, 1, 0)], g[(a, 1, 1)], g[(b, 1, 1)], g[(b, 1, 0)]], 1))
    comment = ("Box [0,2]x[0,1]x[0,1] cut by the internal facet x = 1 (marker 2) into two regions:\n"
               "attribute 10 for x < 1, 20 for x > 1.")
    write_poly("box_internal_facet.poly", comment, pts, facets,
               regions=[(0.5, 0.5, 0.5, 10), (1.5, 0.5, 0.5, 20)])


def box_cavity():
    pts = []
    outer = add_box(pts, (0, 0, 0), (4, 4, 4))
    inner = add_box(pts, (1, 1, 1.5), (2.5, 3, 3))
    comment = ("Box [0,4]^3 (volume 64) with the cavity [1,2.5]x[1,3]x[1.5,3] (volume 4.5), carved by the\n"
               "hole point (2, 2, 2); the meshed volume is 59.5. Region attribute 5 for the rest.")
    write_poly("box_cavity.poly", comment, pts, box_facets(outer, 1) + box_facets(inner, 2),
               holes=[(2, 2, 2)], regions=[(0.5, 0.5, 0.5, 5)], first=1)


def ushape():
    # profile in the xz plane (counter-clockwise), extruded along y from 0 to 1
    prof = [(0, 0), (3, 0), (3, 1), (2, 1), (2, 0.5), (1, 0.5), (1, 1), (0, 1)]
    n = len(prof)
    pts = [(x, 0, z) for x, z in prof] + [(x, 1, z) for x, z in prof]
    facets = [single(list(range(n)), 1), single(list(range(2 * n - 1, n - 1, -1)), 1)]
    for i in range(n):
        j = (i + 1) % n
        facets.append(single([i, n + i, n + j, j], 2))
    comment = ("U-shaped prism: the profile (0,0) (3,0) (3,1) (2,1) (2,0.5) (1,0.5) (1,1) (0,1) in the xz plane,\n"
               "extruded along y over [0,1]. Volume 2.5; its convex hull is the box [0,3]x[0,1]x[0,1], volume 3.")
    write_poly("ushape.poly", comment, pts, facets)


# ---------- f. windows: facets with holes filled by other facets ----------

def window_wall():
    pts = []
    v = add_box(pts, (0, 0, 0), (4, 2, 3))
    win = [len(pts) + k for k in range(4)]
    pts += [(1, 0, 1), (3, 0, 1), (3, 0, 2), (1, 0, 2)]
    facets = [f for k, f in enumerate(box_facets(v, 1)) if k != 2]
    wall = [v[0][0][0], v[1][0][0], v[1][0][1], v[0][0][1]]
    facets.append(([wall, win], [(2, 0, 1.5)], 1))
    facets.append(single(win, 5))
    comment = ("Box [0,4]x[0,2]x[0,3] whose wall y = 0 (marker 1) has a window [1,3]x[1,2] (a hole polygon with\n"
               "a hole point) filled by a facet of its own, marker 5: the window's two triangles carry 5.")
    write_poly("window_wall.poly", comment, pts, facets, first=1)


def windows():
    pts = []
    def add(*ps):
        out = []
        for q in ps:
            out.append(len(pts))
            pts.append(q)
        return out
    c = add((0, 0, 0), (6, 0, 0), (6, 4, 0), (0, 4, 0), (0, 0, 3), (6, 0, 3), (6, 4, 3), (0, 4, 3))
    mid = add((3, 4, 0), (3, 4, 3))
    a = add((1, 0, 1), (2, 0, 1), (2, 0, 2), (1, 0, 2))
    b = add((3.5, 0, 0.5), (5, 0, 0.5), (5, 0, 2.5), (3.5, 0, 2.5))
    e = add((6, 1, 1), (6, 3, 1), (6, 3, 2), (6, 1, 2))
    l = add((1, 4, 1), (1, 4, 2), (2, 4, 2), (2, 4, 1))
    r = add((4, 4, 1), (4, 4, 2), (5, 4, 2), (5, 4, 1))
    facets = [
        single([c[0], c[3], mid[0], c[2], c[1]], 1),  # z = 0
        single([c[4], c[5], c[6], mid[1], c[7]], 1),  # z = 3
        single([c[0], c[4], c[7], c[3]], 1),  # x = 0
        # y = 0: two windows, one filled by a quad (marker 5), one by two triangles (6)
        ([[c[0], c[1], c[5], c[4]], a, b], [(1.5, 0, 1.5), (4.25, 0, 1.5)], 1),
        single(a, 5),
        ([[b[0], b[1], b[2]], [b[0], b[2], b[3]]], [], 6),
        # x = 6: one window (marker 7)
        ([[c[1], c[2], c[6], c[5]], e], [(6, 2, 1.5)], 1),
        single(e, 7),
        # y = 4: two coplanar quads of one marker, merged; the left one's window is filled
        # by a facet of the same marker (it merges too), the right one's by marker 8
        ([[c[3], c[7], mid[1], mid[0]], l], [(1.5, 4, 1.5)], 1),
        single(l, 1),
        ([[mid[0], mid[1], c[6], c[2]], r], [(4.5, 4, 1.5)], 1),
        single(r, 8),
    ]
    comment = ("Box [0,6]x[0,4]x[0,3] with windows: two in the wall y = 0 (filled by a quad of marker 5 and by\n"
               "two triangles of marker 6), one in the wall x = 6 (marker 7), and one in each of the two\n"
               "coplanar quads of the wall y = 4, which merge: the left window is filled by a facet of the\n"
               "wall's own marker 1, the right one by marker 8.")
    write_poly("windows.poly", comment, pts, facets)


# ---------- g. surface meshes with triangles that have a repeated corner ----------

def degenerate_tris():
    # A pentagonal bipyramid with irregular coordinates, and a copy of vertex 2 (index 7).
    pts = [(0.05, -0.1, 1.3), (1.0, 0.0, 0.02), (0.3, 0.95, -0.03), (-0.8, 0.6, 0.01),
           (-0.75, -0.6, 0.0), (0.35, -0.9, -0.02), (-0.02, 0.07, -1.1), (0.3, 0.95, -0.03)]
    ring = [1, 2, 3, 4, 5]
    tris = []
    for k in range(5):
        a, b = ring[k], ring[(k + 1) % 5]
        tris.append((0, a, b))
        tris.append((6, b, a))
    # The upper triangle over 2-3 uses the copy of vertex 2: welding makes it whole again.
    tris[2] = (0, 7, 3)
    # Triangles with a repeated corner: two corners at one point after welding (2 and its
    # copy 7), and a literal repeat.
    degenerate = [(2, 7, 3), (4, 4, 5)]
    allt = tris[:5] + [degenerate[0]] + tris[5:] + [degenerate[1]]
    comment = ("Pentagonal bipyramid (10 triangles) with two more triangles that have a repeated corner:\n"
               "(2, 7, 3), where point 7 is a copy of point 2, and (4, 4, 5). Both are dropped on reading.")
    head = [f"# {l}" for l in comment.splitlines()] + ["# Written by scripts/gen-plc-models.py; do not edit."]
    with open(os.path.join(OUT, "degenerate_tris.off"), "w") as f:
        f.write("OFF\n" + "\n".join(head) + f"\n{len(pts)} {len(allt)} 0\n")
        f.writelines(f"{fmt(x)} {fmt(y)} {fmt(z)}\n" for x, y, z in pts)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in allt)
    with open(os.path.join(OUT, "degenerate_tris_obj.obj"), "w") as f:
        f.write("\n".join(head) + "\n")
        f.writelines(f"v {fmt(x)} {fmt(y)} {fmt(z)}\n" for x, y, z in pts)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in allt)
    with open(os.path.join(OUT, "degenerate_tris_ply.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\n" + "".join(f"comment {l[2:]}\n" for l in head) +
                f"element vertex {len(pts)}\nproperty double x\nproperty double y\nproperty double z\n"
                f"element face {len(allt)}\nproperty list uchar int vertex_indices\nend_header\n")
        f.writelines(f"{fmt(x)} {fmt(y)} {fmt(z)}\n" for x, y, z in pts)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in allt)
    # STL has no indices: the repeated corner is two equal corners. Coordinates are
    # written as floats in the binary file, so both STL files use float32 values.
    f32 = [tuple(struct.unpack("<f", struct.pack("<f", c))[0] for c in p) for p in pts]
    with open(os.path.join(OUT, "degenerate_tris_ascii.stl"), "w") as f:
        f.write("solid degenerate\n")
        for t in allt:
            f.write("  facet normal 0 0 0\n    outer loop\n")
            f.writelines(f"      vertex {fmt(f32[v][0])} {fmt(f32[v][1])} {fmt(f32[v][2])}\n" for v in t)
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid degenerate\n")
    with open(os.path.join(OUT, "degenerate_tris_binary.stl"), "wb") as f:
        f.write(b"binary STL with two triangles that have a repeated corner".ljust(80, b" "))
        f.write(struct.pack("<I", len(allt)))
        for t in allt:
            f.write(struct.pack("<3f", 0, 0, 0))
            for v in t:
                f.write(struct.pack("<3f", *pts[v]))
            f.write(b"\0\0")


# ---------- h. nearly flat quad grids ----------

def flat_grids():
    # Cubes whose sides are grids of quads a little off their plane (merged into one facet
    # per side), with points inside near them: TetGen meshes them with no Steiner point.
    gen = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gen-flat-grids.py")
    for k, d, n, seed in ((6, "1e-12", 400, 1), (8, "1e-8", 600, 2)):
        subprocess.run([sys.executable, gen, str(k), d, str(n), str(seed),
                        os.path.join(OUT, f"flat_grid_{k}.poly")], check=True)


# ---------- copies of corpus models ----------

def find_corpus(argv):
    if "--corpus" in argv:
        return argv[argv.index("--corpus") + 1]
    if os.environ.get("CORPUS"):
        return os.environ["CORPUS"]
    for d in (os.path.join(ROOT, "..", "shared", "corpus"), "/work/shared/corpus"):
        if os.path.isfile(os.path.join(d, "MANIFEST.tsv")):
            return d
    return None


def copy_corpus(corpus):
    rows = {}
    with open(os.path.join(corpus, "MANIFEST.tsv")) as f:
        head = f.readline().rstrip("\n").split("\t")
        for line in f:
            r = dict(zip(head, line.rstrip("\n").split("\t")))
            rows[r["file"]] = r
    out = ["# Licenses of the models in data/plc",
           "",
           "## Copies of corpus models",
           "",
           "Unmodified copies of small public models from the shared test corpus "
           "(`../shared/corpus/files/`, see its `MANIFEST.tsv`), copied by `scripts/gen-plc-models.py`.",
           "",
           "| file here | corpus file | source repository | path in the repository | commit | license | sha256 |",
           "|---|---|---|---|---|---|---|"]
    for rel in CORPUS_COPIES:
        r = rows[rel]
        assert not rel.startswith(("libigl/", "tetgen_stp/")), rel
        src = os.path.join(corpus, "files", rel)
        dst = os.path.join(OUT, os.path.basename(rel))
        shutil.copyfile(src, dst)
        digest = hashlib.sha256(open(dst, "rb").read()).hexdigest()
        assert digest == r["sha256"], f"{rel}: sha256 differs from MANIFEST.tsv"
        out.append(f"| `{os.path.basename(rel)}` | `{rel}` | {r['source_repo']} | `{r['source_path']}` | "
                   f"`{r['commit_or_version']}` | {r['license']} | `{digest[:16]}…` |")
    out += ["",
            "License notes from the corpus README: CGAL data (`cgal/`, `tetgentests_cgal/`) is free to use "
            "(CGAL LICENSE.FREE_USE / CC0-1.0); the TetGenTests drafts (`tetgentests/`) are CC0-1.0; "
            "`attene_cdt/` (MarcoAttene/CDT) is GPL-3.0 / LGPL-3.0.",
            "",
            "## Hand-made models",
            "",
            "Every other model file in this directory (`prism_*`, `fig4_*`, `cosph_*`, `gridbox_*`, `box_*`, "
            "`ushape.poly`, `window*.poly`, `degenerate_tris*`, `flat_grid_*`) is written by `scripts/gen-plc-models.py` and is part of this project, under its "
            "license (MIT OR Apache-2.0).",
            "",
            "## Reference meshes",
            "",
            "`ref/` holds TetGen 1.5.0's output on some of these models, written by "
            "`scripts/gen-plc-reference.sh` (see `ref/README.md`).",
            ""]
    with open(os.path.join(OUT, "LICENSES.md"), "w") as f:
        f.write("\n".join(out))


def main(argv):
    os.makedirs(OUT, exist_ok=True)
    for n in (8, 40):
        for d, dtag in ((1e-5, "1e-5"), (1e-8, "1e-8")):
            prism(n, d, 1.0, (0.0, 0.0, 0.0), f"n{n}_d{dtag}_s1")
            prism(n, d, 1000.0, (1000.0, -500.0, 250.0), f"n{n}_d{dtag}_s1000")
    fig4_inner("pq", True, True)
    fig4_inner("p", True, False)
    fig4_inner("none", False, False)
    fig4_split()
    cospherical()
    gridbox(3, 3, 3, "gridbox_3.smesh")
    gridbox(4, 3, 2, "gridbox_432.smesh")
    box_internal_facet()
    box_cavity()
    ushape()
    window_wall()
    windows()
    degenerate_tris()
    flat_grids()
    corpus = find_corpus(argv)
    if corpus:
        copy_corpus(corpus)
    else:
        print("corpus not found: keeping the copies already in data/plc", file=sys.stderr)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main(sys.argv[1:])
