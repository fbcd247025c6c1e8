#!/usr/bin/env python3
"""Quality refinement, ours against TetGen 1.5 in the same run.

For each model and each switch set (default -pq1.414 and -pq1.414/10), both programs
mesh their own copy of the model; the table gives output points, whole-process seconds
(best of --repeat runs), the tets over the ratio bound (and under the angle bound), the
smallest dihedral angle, and the referee's verdict on our mesh. TetGen runs with -O0
(without it, its optimisation moves the mesh off the constrained Delaunay one).

With --plot FILE it draws the dihedral-angle histograms, ours beside TetGen's, one
panel per model (matplotlib). --timeout S counts a run over S seconds as failed;
--no-referee skips the referee (slow on large meshes). A last line per switch set sums
points, seconds and bad tets over the models both programs finish. Needs numpy.

usage: scripts/quality-bench.py [--switches -pq1.414 ...] [--repeat N] [--plot FILE]
                                [--timeout S] [--no-referee] MODEL...
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


def shapes(pts, tets):
    """Radius-edge ratios (m,) and dihedral angles in degrees (m, 6) of the tets."""
    import numpy as np
    p = np.asarray(pts, dtype=float)[np.asarray(tets, dtype=np.int64).reshape(-1, 4)]
    a = p[:, 0]
    b, c, d = p[:, 1] - a, p[:, 2] - a, p[:, 3] - a
    cd, db, bc = np.cross(c, d), np.cross(d, b), np.cross(b, c)
    den = 2 * np.einsum("ij,ij->i", b, cd)
    num = (np.einsum("ij,ij->i", b, b)[:, None] * cd + np.einsum("ij,ij->i", c, c)[:, None] * db
           + np.einsum("ij,ij->i", d, d)[:, None] * bc)
    pairs = [(i, j) for i in range(4) for j in range(i + 1, 4)]
    edges = np.stack([np.linalg.norm(p[:, i] - p[:, j], axis=1) for i, j in pairs], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = np.linalg.norm(num / den[:, None], axis=1)
        ratio = np.where(den == 0, np.inf, radius / edges.min(axis=1))
    angles = []
    for i, j in pairs:
        k, l = [x for x in range(4) if x not in (i, j)]
        e = p[:, j] - p[:, i]
        e = e / np.linalg.norm(e, axis=1)[:, None]
        u = p[:, k] - p[:, i]
        v = p[:, l] - p[:, i]
        u = u - np.einsum("ij,ij->i", u, e)[:, None] * e
        v = v - np.einsum("ij,ij->i", v, e)[:, None] * e
        nn = np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            cos = np.where(nn > 0, np.einsum("ij,ij->i", u, v) / nn, 1.0)
        angles.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return ratio, np.stack(angles, axis=1)


def run(cmd, repeat, timeout):
    best = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        try:
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return None, f"over {timeout:g} s"
        best = min(best, time.perf_counter() - t)
        if r.returncode != 0:
            return None, f"exit {r.returncode}"
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
    ap.add_argument("--timeout", type=float, default=None,
                    help="seconds a run may take (reported as a failure past it)")
    ap.add_argument("--no-referee", action="store_true",
                    help="do not judge our meshes (the referee is slow on large ones)")
    args = ap.parse_args()
    if not shutil.which("tetgen"):
        sys.exit("tetgen is not installed (apt-get install -y tetgen)")
    hist = {}
    totals = {}
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
                    secs, code = run(cmd, args.repeat, args.timeout)
                    if secs is None:
                        figs[who] = (code, "", "", "", "")
                        continue
                    pts, tets = read_mesh(os.path.join(d, stem + ".1"))
                    ratios, dihedral = shapes(pts, tets)
                    smallest = dihedral.min(axis=1)
                    bad = int(((ratios > ratio) | (smallest < angle)).sum())
                    small = float(smallest.min()) if len(tets) else 180.0
                    angles = dihedral.ravel()
                    verdict = ""
                    if who == "ours" and os.path.exists(REFEREE) and not args.no_referee:
                        out = subprocess.run([sys.executable, REFEREE, m, os.path.join(d, stem + ".1")],
                                             capture_output=True, text=True).stdout.strip()
                        verdict = out.splitlines()[-1] if out else "?"
                    figs[who] = (len(pts), secs, bad, small, verdict)
                    hist[(name, sw, who)] = angles
                o, t = figs["ours"], figs["tetgen"]
                secs = [f"{x[1]:.3f}" if isinstance(x[1], float) else x[1] for x in (o, t)]
                speed = (f"{secs[0]} / {secs[1]} ({o[1] / t[1]:.2f})"
                         if isinstance(o[1], float) and isinstance(t[1], float)
                         else f"{secs[0]} / {secs[1]}")
                small = (f"{o[3]:.2f} / {t[3]:.2f}"
                         if isinstance(o[3], float) and isinstance(t[3], float) else "")
                print(f"| {name} | {sw} | {o[0]} / {t[0]} | {speed} | {o[2]} / {t[2]} | {small} | {o[4]} |",
                      flush=True)
                both = isinstance(o[1], float) and isinstance(t[1], float)
                tot = totals.setdefault(sw, {"models": 0, "points": [0, 0], "secs": [0.0, 0.0],
                                             "bad": [0, 0], "failed": [0, 0]})
                for k, fig in enumerate((o, t)):
                    tot["failed"][k] += not isinstance(fig[1], float)
                    if both:
                        tot["points"][k] += fig[0]
                        tot["secs"][k] += fig[1]
                        tot["bad"][k] += fig[2]
                tot["models"] += both
    for sw, tot in totals.items():
        (po, pt), (so, st), (bo, bt), (fo, ft) = (tot["points"], tot["secs"], tot["bad"],
                                                  tot["failed"])
        print(f"\n{sw}: {tot['models']} models both finish; points {po} / {pt} "
              f"({po / max(pt, 1):.2f}); seconds {so:.2f} / {st:.2f} "
              f"({so / max(st, 1e-9):.2f}); bad tets {bo} / {bt}; "
              f"failed or over time: ours {fo}, TetGen {ft}")
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
