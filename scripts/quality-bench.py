#!/usr/bin/env python3
"""Quality refinement, ours against TetGen 1.5 in the same run.

For each model and each switch set (default -pq1.414 and -pq1.414/10), both programs
mesh their own copy of the model; the table gives output points, whole-process seconds
(best of --repeat runs), the tets over the ratio bound (and under the angle bound), the
smallest dihedral angle, and the referee's verdict on our mesh. TetGen runs with -O0
(without it, its optimisation moves the mesh off the constrained Delaunay one).

With --plot FILE it draws the dihedral-angle histograms, ours beside TetGen's, one
panel per model (matplotlib).

usage: scripts/quality-bench.py [--switches -pq1.414 ...] [--repeat N] [--plot FILE]
                                MODEL...
"""
import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
TETCDT = os.path.join(ROOT, "target", "release", "tetcdt")
REFEREE = os.path.join(ROOT, "..", "shared", "tools", "validate_mesh.py")


def read_mesh(prefix):
    """Points and tets (0-based) of PREFIX.node / PREFIX.ele."""
    def rows(path):
        with open(path) as f:
            return [l.split('#')[0].split() for l in f if l.split('#')[0].strip()]
    node = rows(prefix + ".node")
    n = int(node[0][0])
    first = int(node[1][0])
    pts = [tuple(float(x) for x in r[1:4]) for r in node[1:n + 1]]
    ele = rows(prefix + ".ele")
    m = int(ele[0][0])
    tets = [tuple(int(x) - first for x in r[1:5]) for r in ele[1:m + 1]]
    return pts, tets


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def shape(p):
    """Radius-edge ratio and the six dihedral angles (degrees) of tet p."""
    b, c, d = sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])
    den = 2 * dot(b, cross(c, d))
    edges = [math.dist(p[i], p[j]) for i in range(4) for j in range(i + 1, 4)]
    if den == 0:
        ratio = math.inf
    else:
        cd, db, bc = cross(c, d), cross(d, b), cross(b, c)
        o = [(dot(b, b) * cd[k] + dot(c, c) * db[k] + dot(d, d) * bc[k]) / den for k in range(3)]
        ratio = math.sqrt(dot(o, o)) / min(edges)
    normals = []
    for k in range(4):
        f = [i for i in range(4) if i != k]
        n = cross(sub(p[f[1]], p[f[0]]), sub(p[f[2]], p[f[0]]))
        if dot(n, sub(p[k], p[f[0]])) > 0:
            n = (-n[0], -n[1], -n[2])
        normals.append(n)
    angles = []
    for i in range(4):
        for j in range(i + 1, 4):
            k, l = [x for x in range(4) if x not in (i, j)]
            nn = math.sqrt(dot(normals[k], normals[k]) * dot(normals[l], normals[l]))
            cos = -dot(normals[k], normals[l]) / nn if nn > 0 else 1.0
            angles.append(math.degrees(math.acos(max(-1.0, min(1.0, cos)))))
    return ratio, angles


def run(cmd, repeat):
    best = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, text=True)
        best = min(best, time.perf_counter() - t)
        if r.returncode != 0:
            return None, r.returncode
    return best, 0


def bounds(switches):
    q = switches.split('q', 1)[1] if 'q' in switches else ''
    num = ''
    for ch in q:
        if ch.isdigit() or ch in './':
            num += ch
        else:
            break
    parts = num.split('/')
    ratio = float(parts[0]) if parts[0] else 2.0
    angle = float(parts[1]) if len(parts) > 1 and parts[1] else 0.0
    return ratio, angle


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("models", nargs="+")
    ap.add_argument("--switches", nargs="+", default=["-pq1.414", "-pq1.414/10"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--plot")
    args = ap.parse_args()
    if not shutil.which("tetgen"):
        sys.exit("tetgen is not installed (apt-get install -y tetgen)")
    hist = {}
    print("| model | switches | points ours / TetGen | seconds ours / TetGen (ratio) "
          "| bad tets ours / TetGen | smallest dihedral ours / TetGen | referee |")
    print("|---|---|---|---|---|---|---|")
    for model in args.models:
        name = os.path.basename(model)
        stem = os.path.splitext(name)[0]
        for sw in args.switches:
            ratio, angle = bounds(sw)
            with tempfile.TemporaryDirectory() as tmp:
                figs = {}
                for who in ("ours", "tetgen"):
                    d = os.path.join(tmp, who)
                    os.mkdir(d)
                    m = os.path.join(d, name)
                    shutil.copy(model, m)
                    cmd = ([TETCDT, sw + "Q", m] if who == "ours"
                           else ["tetgen", sw + "O0Q", m])
                    secs, code = run(cmd, args.repeat)
                    if secs is None:
                        figs[who] = (f"exit {code}", "", "", "", None)
                        continue
                    pts, tets = read_mesh(os.path.join(d, stem + ".1"))
                    bad, small, angles = 0, 180.0, []
                    for t in tets:
                        r, a = shape([pts[v] for v in t])
                        angles.extend(a)
                        small = min(small, min(a))
                        bad += r > ratio or min(a) < angle
                    verdict = ""
                    if who == "ours" and os.path.exists(REFEREE):
                        out = subprocess.run([sys.executable, REFEREE, m, os.path.join(d, stem + ".1")],
                                             capture_output=True, text=True).stdout.strip()
                        verdict = out.splitlines()[-1] if out else "?"
                    figs[who] = (len(pts), secs, bad, small, verdict)
                    hist[(name, sw, who)] = angles
                o, t = figs["ours"], figs["tetgen"]
                speed = (f"{o[1]:.3f} / {t[1]:.3f} ({o[1] / t[1]:.2f})"
                         if isinstance(o[1], float) and isinstance(t[1], float) else f"{o[1]} / {t[1]}")
                small = (f"{o[3]:.2f} / {t[3]:.2f}"
                         if isinstance(o[3], float) and isinstance(t[3], float) else "")
                print(f"| {name} | {sw} | {o[0]} / {t[0]} | {speed} | {o[2]} / {t[2]} | {small} | {o[4]} |",
                      flush=True)
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        keys = sorted({(n, s) for (n, s, _) in hist})
        fig, axes = plt.subplots(len(keys), 1, figsize=(7, 2.2 * len(keys)), squeeze=False)
        bins = list(range(0, 181, 5))
        for ax, (n, s) in zip(axes[:, 0], keys):
            for who, colour in (("ours", "tab:blue"), ("tetgen", "tab:orange")):
                if (n, s, who) in hist:
                    ax.hist(hist[(n, s, who)], bins=bins, histtype="step", color=colour,
                            label="tetcdt" if who == "ours" else "TetGen -O0", density=True)
            ax.set_title(f"{n} {s}", fontsize=9)
            ax.set_xlabel("dihedral angle (degrees)", fontsize=8)
            ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)


if __name__ == "__main__":
    main()
