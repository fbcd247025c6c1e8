#!/usr/bin/env python3
"""Live comparison with TetGen on fresh random PLCs.

usage: scripts/live-compare-plc.py [--cases N] [--seed S] [--keep DIR] [--big | --medium]

Each case is a closed star-shaped surface: a latitude-longitude grid of 2 to 8 rings of
3 to 14 points around the z axis, each point moved along its ray by up to 5%, 20% or
40%, with random diagonals in its quads and the two poles as fans; 0 to 400 isolated
points inside its kernel; in half of the cases every coordinate is rounded to a grid of
1/30, which makes points repeat and makes cospherical and coplanar ties. The seed
changes on every run (from the clock) and is printed; `--seed S` repeats a run.
--big draws finer surfaces instead (20 to 60 rings of 30 to 120 points, 0, 2,000 or
20,000 points inside, no grid) and prints each program's wall time.
--medium draws the sharpest of those at a middle size (20 to 36 rings of 40 to 90
points, every point moved by up to 40%, 0 or 2,000 points inside, no grid), and prints
the times too.

For each case it runs `tetgen -pO0Q` (Debian TetGen 1.5), then `tetcdt -pQ` and
`tetcdt -pQF`, and asks:
  - both of our runs exit 0 and the shared validator (validate_mesh.py) accepts both
    meshes, whatever TetGen did (the surfaces are valid PLCs by construction);
  - where TetGen meshes the case with no Steiner point, its mesh passes the validator,
    and ours has no Steiner point either: our tets are TetGen's, tet for tet (matched by
    coordinates), with both algorithms.
Prints a line per case and a summary; exits 1 if any case fails (keeping its files in
--keep DIR, default a temporary directory that is then kept).

Environment: TETCDT (our binary, default target/release/tetcdt), TETCDT_TOOLS (the
directory of validate_mesh.py, else ../shared/tools), TETCDT_TIMEOUT (seconds per run,
default 300).
"""
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def star(rng, size="small"):
    """(points, triangles) of a random star-shaped closed surface with points inside."""
    big = size != "small"
    if size == "big":
        nlat, nlon = rng.randint(20, 60), rng.randint(30, 120)
    elif size == "medium":
        nlat, nlon = rng.randint(20, 36), rng.randint(40, 90)
    else:
        nlat, nlon = rng.randint(2, 8), rng.randint(3, 14)
    amp = 0.4 if size == "medium" else rng.choice([0.05, 0.2, 0.4])
    scale = 0 if big else rng.choice([0, 30])
    pts, seen = [], set()

    def put(d, r):
        """The new point's index, or None if rounding made it repeat an earlier one."""
        p = [r * x for x in d]
        if scale:
            p = [round(scale * x) / scale for x in p]
        if tuple(p) in seen:
            return None
        seen.add(tuple(p))
        pts.append(p)
        return len(pts) - 1

    def surface(d, r):
        i = put(d, r)
        assert i is not None, "surface points are farther apart than the grid"
        return i

    def radius():
        return 1 + amp * (2 * rng.random() - 1)

    # Repeated points are left out (a surface point is never one: the grid is finer
    # than the rings), since TetGen numbers a repeated point by whichever copy its
    # randomized insertion reaches first, which changes how ties are broken.
    north = surface((0, 0, 1), radius())
    rings = []
    for i in range(nlat):
        th = math.pi * (i + 1) / (nlat + 1)
        # A twist of at most a quarter cell keeps every quad's cone apart from the others.
        ph0 = rng.uniform(-0.25, 0.25) * 2 * math.pi / nlon
        ring = []
        for j in range(nlon):
            ph = ph0 + 2 * math.pi * j / nlon
            ring.append(surface((math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph),
                             math.cos(th)), radius()))
        rings.append(ring)
    south = surface((0, 0, -1), radius())
    tris = []
    for j in range(nlon):
        k = (j + 1) % nlon
        tris.append((north, rings[0][j], rings[0][k]))
        tris.append((south, rings[-1][k], rings[-1][j]))
    for i in range(nlat - 1):
        for j in range(nlon):
            k = (j + 1) % nlon
            a, b, c, d = rings[i][j], rings[i][k], rings[i + 1][j], rings[i + 1][k]
            if rng.random() < 0.5:
                tris += [(a, c, d), (a, d, b)]
            else:
                tris += [(a, c, b), (b, c, d)]
    inner = {"big": [0, 2000, 20000], "medium": [0, 2000], "small": [0, 20, 100, 400]}[size]
    for _ in range(rng.choice(inner)):
        while True:
            q = [rng.uniform(-1, 1) for _ in range(3)]
            if sum(x * x for x in q) < 1:
                break
        # Inside the kernel: every face's plane is farther from the origin.
        put([0.3 * (1 - amp) * x for x in q], 1)
    return pts, tris


def write_poly(path, pts, tris):
    with open(path, "w") as f:
        f.write(f"{len(pts)} 3 0 0\n")
        for i, p in enumerate(pts):
            f.write(f"{i} {p[0]!r} {p[1]!r} {p[2]!r}\n")
        f.write(f"{len(tris)} 0\n")
        for t in tris:
            f.write(f"1\n3 {t[0]} {t[1]} {t[2]}\n")
        f.write("0\n0\n")


def rows(path):
    with open(path) as f:
        return [r for r in (l.split("#", 1)[0].split() for l in f) if r]


def mesh(prefix):
    """(points as tuples, tets as frozensets of points) of PREFIX.node/.ele."""
    node, ele = rows(prefix + ".node"), rows(prefix + ".ele")
    n = int(node[0][0])
    base = int(node[1][0])
    pts = [tuple(float(c) for c in r[1:4]) for r in node[1:1 + n]]
    tets = {frozenset(pts[int(v) - base] for v in r[1:5]) for r in ele[1:1 + int(ele[0][0])]}
    return pts, tets


def run(cmd, cwd, timeout, times=None):
    """The command's exit code (or "timeout"); its wall time appended to `times`."""
    start = time.monotonic()
    try:
        rc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True,
                            timeout=timeout).returncode
    except subprocess.TimeoutExpired:
        rc = "timeout"
    if times is not None:
        times.append(time.monotonic() - start)
    return rc


def intersecting(work, name):
    """Does TetGen's -d find intersecting facets in NAME.poly?"""
    r = subprocess.run(["tetgen", "-d", name + ".poly"], cwd=work, capture_output=True, text=True)
    return " intersects facet " in r.stdout


def main():
    args = sys.argv[1:]
    if "-h" in args or "--help" in args:
        print(__doc__)
        return 0
    opts = {"--cases": "12", "--seed": None, "--keep": None}
    size = "big" if "--big" in args else "medium" if "--medium" in args else "small"
    if "--big" in args and "--medium" in args:
        sys.exit("live-compare-plc.py: --big and --medium exclude each other")
    big = size != "small"
    args = [a for a in args if a not in ("--big", "--medium")]
    while args:
        k = args.pop(0)
        if k not in opts or not args:
            sys.exit(f"live-compare-plc.py: bad argument {k!r} (see --help)")
        opts[k] = args.pop(0)
    seed = int(opts["--seed"]) if opts["--seed"] else int(time.time()) % 1000000
    tetcdt = os.path.abspath(os.environ.get("TETCDT", os.path.join(ROOT, "target/release/tetcdt")))
    candidates = [os.environ.get("TETCDT_TOOLS", ""), os.path.join(ROOT, "tools"),
                  os.path.join(ROOT, "..", "shared", "tools"), "/work/shared/tools"]
    validate = next((os.path.join(d, "validate_mesh.py") for d in candidates
                     if d and os.path.exists(os.path.join(d, "validate_mesh.py"))),
                    os.path.join(ROOT, "..", "shared", "tools", "validate_mesh.py"))
    timeout = float(os.environ.get("TETCDT_TIMEOUT", "300"))
    for what, path in (("our binary", tetcdt), ("validate_mesh.py", validate)):
        if not os.path.exists(path):
            sys.exit(f"live-compare-plc.py: FAIL: {what} not found at {path}")
    if shutil.which("tetgen") is None:
        sys.exit("live-compare-plc.py: FAIL: tetgen is not on PATH (apt-get install tetgen)")
    print(f"live-compare-plc: seed {seed} (repeat: scripts/live-compare-plc.py --seed {seed} "
          f"--cases {opts['--cases']}{'' if size == 'small' else ' --' + size})")
    work = opts["--keep"] or tempfile.mkdtemp(prefix="tetcdt-live-plc.")
    os.makedirs(work, exist_ok=True)
    rng = random.Random(seed)
    failed, identical, tg_failed, refused = [], 0, 0, 0
    for case in range(int(opts["--cases"])):
        name = f"star{case}"
        pts, tris = star(rng, size)
        inp = os.path.join(work, name + ".poly")
        write_poly(inp, pts, tris)
        distinct = {tuple(float(c) for c in p) for p in pts}
        problems, notes = [], []
        times = []
        tg = run(["tetgen", "-pO0Q", name + ".poly"], work, timeout, times)
        tg_mesh = None
        if tg == 0:
            tg_mesh = mesh(os.path.join(work, name + ".1"))
            tg_steiner = sum(1 for p in tg_mesh[0] if p not in distinct)
            tg_valid = subprocess.run([sys.executable, validate, inp, os.path.join(work, name + ".1")],
                                      capture_output=True, text=True).returncode == 0
            notes.append(f"TetGen {tg_steiner} Steiner points" + ("" if tg_valid else ", rejected"))
        else:
            tg_failed += 1
            notes.append(f"TetGen exit {tg}")
        for sw, tag in (("-pQ", "C"), ("-pQF", "F")):
            prefix = os.path.join(work, f"{name}.{tag}")
            rc = run([tetcdt, sw, "-o", prefix, inp], work, timeout, times)
            if rc == 3 and intersecting(work, name):
                # Rounding to the grid folded a thin triangle through another: the
                # input is invalid, as TetGen's -d confirms, and refusing it is right.
                notes.append(f"{tag} refused (facets intersect, as tetgen -d finds)")
                refused += 1
                continue
            if rc != 0:
                problems.append(f"tetcdt {sw} exit {rc}")
                continue
            v = subprocess.run([sys.executable, validate, inp, prefix], capture_output=True, text=True)
            if v.returncode != 0:
                last = (v.stdout.strip().splitlines() or ["?"])[-1]
                problems.append(f"validator rejects tetcdt {sw}: {last}")
            ours = mesh(prefix)
            steiner = sum(1 for p in ours[0] if p not in distinct)
            notes.append(f"{tag} {steiner}")
            if tg_mesh and tg_steiner == 0 and tg_valid and steiner == 0:
                if ours[1] == tg_mesh[1]:
                    identical += 1
                else:
                    problems.append(f"tetcdt {sw}: {len(ours[1] - tg_mesh[1])} tets not TetGen's, "
                                    f"{len(tg_mesh[1] - ours[1])} of TetGen's missing")
        if big:
            names = ["TetGen", "C", "F"][-len(times):] if tg == 0 else ["TetGen", "C", "F"]
            notes.append("seconds: " + ", ".join(f"{n} {t:.2f}" for n, t in zip(names, times)))
        status = "FAIL" if problems else "ok"
        print(f"  {name}: {len(pts)} points, {len(tris)} triangles; {', '.join(notes)}: {status}")
        for p in problems:
            print(f"    problem: {p}")
        if problems:
            failed.append(name)
    print(f"live-compare-plc: {int(opts['--cases']) - len(failed)} of {opts['--cases']} cases passed; "
          f"{identical} runs identical to TetGen tet for tet; TetGen failed on {tg_failed}; "
          f"{refused} runs refused an input whose facets intersect")
    if failed:
        print(f"live-compare-plc: FAIL: {', '.join(failed)} (files kept in {work})")
        return 1
    if not opts["--keep"]:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
