#!/usr/bin/env python3
"""Meshes random prisms whose polygons are not flat, and sums up what happened.

usage: scripts/bent-prisms.py [--count N] [--dev D,...] [--seed S] [--switches SW,...]
                              [--keep DIR] [--no-validate] [--polygons]

Each prism has an n-gon (n from 6 to 80) for its bottom and top, of random size and
place; every cap vertex is moved off its plane, and every top vertex radially, by up to
D times the prism's height, so the caps and the side quads are bent; up to 39 random
points inside are added as isolated vertices. For each prism and each switch set
(default -pQ,-pQF) it runs `tetcdt SW --stats-json`, then the shared validator where
numpy is found (../shared/tools/validate_mesh.py, or $TETCDT_TOOLS). Prints, per
deviation and switch set: failed runs (exit code not 0), regions that fell back from
flips to cavities, regions stuck on polygons not flat (flips taken back; of these, how
many got the point the cavity code placed), the Steiner points in all, meshes the
validator rejects, and the slowest run. --keep DIR keeps the inputs of rejected meshes.

--polygons meshes, instead of prisms, one K-gon (K from 3 to 32) off its plane by up to
D among N random points near it (N from 50 to 2,000), written by
scripts/gen-bent-polygon.py (default switches -pcQ,-pcQF).
Environment: TETCDT (the binary, default target/release/tetcdt).
"""
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def write_prism(path, n, dev_rel, rng, extra):
    """A bent prism over a regular n-gon, with `extra` isolated points inside."""
    size = 10 ** rng.uniform(0, 3)
    r, dev = 0.5 * size, dev_rel * size
    cx, cy, cz = (rng.uniform(-100, 100) for _ in range(3))
    phase = rng.uniform(0, 2 * math.pi)
    bottom, top = [], []
    for i in range(n):
        t = phase + 2 * math.pi * i / n
        x, y = math.cos(t), math.sin(t)
        zb = cz - 0.5 * size + dev * rng.uniform(-1, 1)
        zt = cz + 0.5 * size + dev * rng.uniform(-1, 1)
        rt = r + dev * rng.uniform(-1, 1)
        bottom.append((cx + r * x, cy + r * y, zb))
        top.append((cx + rt * x, cy + rt * y, zt))
    pts = bottom + top
    for _ in range(extra):
        a, rr = rng.uniform(0, 2 * math.pi), r * math.sqrt(rng.uniform(0, 0.8))
        pts.append((cx + rr * math.cos(a), cy + rr * math.sin(a),
                    cz + size * rng.uniform(-0.49, 0.49)))
    facets = [list(range(n - 1, -1, -1)), list(range(n, 2 * n))]
    facets += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    with open(path, "w") as f:
        f.write(f"{len(pts)} 3 0 0\n")
        for k, p in enumerate(pts):
            f.write(f"{k} {p[0]!r} {p[1]!r} {p[2]!r}\n")
        f.write(f"{len(facets)} 0\n")
        for fc in facets:
            f.write(f"1\n{len(fc)} {' '.join(map(str, fc))}\n")
        f.write("0\n0\n")


def validator():
    """The shared validator's path, if it and numpy are found."""
    for d in (os.environ.get("TETCDT_TOOLS"), os.path.join(ROOT, "..", "shared", "tools"),
              "/work/shared/tools"):
        if d and os.path.isfile(os.path.join(d, "validate_mesh.py")):
            ok = subprocess.run([sys.executable, "-c", "import numpy"],
                                capture_output=True).returncode == 0
            return os.path.join(d, "validate_mesh.py") if ok else None
    return None


def main(argv):
    opts = {"--count": "100", "--dev": "1e-5,1e-4,1e-3", "--seed": "1",
            "--switches": "-pQ,-pQF", "--keep": ""}
    validate = True
    polygons = False
    args = list(argv[1:])
    while args:
        a = args.pop(0)
        if a in ("-h", "--help"):
            print(__doc__)
            return 0
        if a == "--no-validate":
            validate = False
        elif a == "--polygons":
            polygons = True
            if opts["--switches"] == "-pQ,-pQF":
                opts["--switches"] = "-pcQ,-pcQF"
        elif a in opts and args:
            opts[a] = args.pop(0)
        else:
            print(f"bent-prisms.py: unknown or incomplete option {a} (see --help)", file=sys.stderr)
            return 2
    tetcdt = os.environ.get("TETCDT", os.path.join(ROOT, "target", "release", "tetcdt"))
    if not os.path.isfile(tetcdt):
        print(f"bent-prisms.py: {tetcdt} not found (cargo build --release)", file=sys.stderr)
        return 2
    check = validator() if validate else None
    if validate and not check:
        print("bent-prisms.py: validator or numpy not found: meshes are not validated",
              file=sys.stderr)
    switches = opts["--switches"].split(",")
    with tempfile.TemporaryDirectory() as work:
        for dev in map(float, opts["--dev"].split(",")):
            rng = random.Random(f"{opts['--seed']}/{dev}")
            tally = {sw: dict(failed=0, fallbacks=0, stuck=0, cavity_points=0, points=0,
                              rejected=0, slowest=0.0)
                     for sw in switches}
            for case in range(int(opts["--count"])):
                inp = os.path.join(work, "prism.poly")
                n, extra = rng.randint(6, 80), rng.randint(0, 39)
                if polygons:
                    gen = os.path.join(ROOT, "scripts", "gen-bent-polygon.py")
                    n, extra = rng.randint(3, 32), rng.randint(50, 2000)
                    subprocess.run([sys.executable, gen, str(extra), inp,
                                    str(rng.randrange(1 << 30)), repr(dev), str(n)], check=True)
                else:
                    write_prism(inp, n, dev, rng, extra)
                for sw in switches:
                    t = tally[sw]
                    out, stats = os.path.join(work, "out"), os.path.join(work, "s.json")
                    start = time.monotonic()
                    run = subprocess.run([tetcdt, sw, "--stats-json", stats, "-o", out, inp],
                                         capture_output=True, timeout=300)
                    t["slowest"] = max(t["slowest"], time.monotonic() - start)
                    if run.returncode != 0:
                        t["failed"] += 1
                        continue
                    js = json.load(open(stats))
                    t["fallbacks"] += int(js.get("flip_fallbacks", 0))
                    t["stuck"] += int(js.get("flip_not_flat_stuck", 0))
                    t["cavity_points"] += int(js.get("flip_not_flat_cavity_points", 0))
                    t["points"] += int(js.get("steiner_points", 0))
                    if not check:
                        continue
                    hull = ["--hull"] if polygons else []
                    v = subprocess.run([sys.executable, check, inp, out] + hull,
                                       capture_output=True, text=True)
                    if v.returncode != 0:
                        t["rejected"] += 1
                        last = (v.stdout.strip().splitlines() or ["?"])[-1]
                        print(f"dev {dev:g} case {case} (n={n}, {extra} more) {sw}: {last}")
                        if opts["--keep"]:
                            os.makedirs(opts["--keep"], exist_ok=True)
                            name = f"prism_{dev:g}_{case}.poly"
                            with open(inp) as src, open(os.path.join(opts["--keep"], name), "w") as dst:
                                dst.write(src.read())
            for sw, t in tally.items():
                what = "polygons" if polygons else "prisms"
                print(f"dev {dev:g} {sw}: {opts['--count']} {what}, failed {t['failed']}, "
                      f"fallbacks {t['fallbacks']}, stuck {t['stuck']} "
                      f"({t['cavity_points']} points by the cavity code), "
                      f"Steiner points {t['points']}, "
                      f"rejected {t['rejected'] if check else 'n.a.'}, slowest {t['slowest']:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
