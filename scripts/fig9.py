#!/usr/bin/env python3
"""Plots and summarizes scripts/fig9.sh's CSV (Figure 9 of Si & Shewchuk).

usage: fig9.py FIG9.CSV OUT.PNG

Left panel: every size; right panel: up to 2,000 crossing tets (the paper's range). The
y axis is scaled to the other three series: TetGen -L, far slower, is clipped at the top.
Time in milliseconds against crossing tets, for our -C and -F and TetGen's -pcO0 (cavity)
and -pcLO0 (flips), drawn with matplotlib (pip install matplotlib). Prints a summary: the
least-squares line of each series, the -F/-C ratios, and how we compare with TetGen's
counterparts. Exits 1 if any of our runs failed.
"""
import csv
import sys

SERIES = [
    ("ours -C", "cavity_secs", (31, 119, 180)),
    ("ours -F", "flip_secs", (214, 39, 40)),
    ("TetGen -C", "tetgen_cavity_secs", (44, 160, 44)),
    ("TetGen -L", "tetgen_flip_secs", (148, 103, 189)),
]


def load(path):
    rows = list(csv.DictReader(open(path)))
    data = {}
    for name, col, _ in SERIES:
        pts = []
        for r in rows:
            try:
                x, y = float(r["crossing_tets"]), 1000.0 * float(r[col])
            except (ValueError, KeyError):
                continue
            pts.append((x, y))
        data[name] = sorted(pts)
    return rows, data


def fit(pts):
    """Least-squares y = a + b x, and R^2."""
    n = len(pts)
    if n < 2:
        return None
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in pts)
    syy = sum((p[1] - my) ** 2 for p in pts)
    if sxx == 0:
        return None
    b = sxy / sxx
    a = my - b * mx
    r2 = (sxy * sxy) / (sxx * syy) if syy > 0 else 1.0
    return a, b, r2


def summary(rows, data):
    print("series          points  ms = a + b * crossing      us/tet   R^2")
    for name, _, _ in SERIES:
        f = fit(data[name])
        if f:
            a, b, r2 = f
            print(f"{name:14s} {len(data[name]):6d}  a={a:9.3f} b={b * 1000:9.4f}e-3  "
                  f"{b * 1000:7.3f}  {r2:.4f}")
    ratios, vs_tg_c, vs_tg_l, fallbacks, failed = [], [], [], 0, []
    for r in rows:
        try:
            c, f = float(r["cavity_secs"]), float(r["flip_secs"])
            ratios.append((int(r["points"]), f / c))
        except ValueError:
            pass
        for mine, theirs, out in (("cavity_secs", "tetgen_cavity_secs", vs_tg_c),
                                  ("flip_secs", "tetgen_flip_secs", vs_tg_l)):
            try:
                out.append((int(r["points"]), float(r[mine]) / float(r[theirs])))
            except ValueError:
                pass
        try:
            fallbacks += int(r["flip_fallbacks"] or 0)
        except ValueError:
            pass
        for st in ("cavity_status", "flip_status"):
            if r.get(st, "ok") != "ok":
                failed.append(f"{r['points']} points: {st.split('_')[0]}: {r[st]}")
    def show(label, pairs):
        if pairs:
            text = " ".join(f"{n}:{q:.2f}" for n, q in pairs)
            print(f"{label}: {text}")
    show("-F / -C time", ratios)
    show("ours -C / TetGen -C", vs_tg_c)
    show("ours -F / TetGen -L", vs_tg_l)
    print(f"flip fallbacks to cavity: {fallbacks}")
    for f in failed:
        print(f"failed: {f}")
    return failed


def plot(data, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for ax, limit in zip(axes, (None, 2000)):
        for name, _, color in SERIES:
            pts = [p for p in data[name] if limit is None or p[0] <= limit]
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=name,
                        color=tuple(c / 255 for c in color), markersize=3)
        others = [p[1] for name, _, _ in SERIES[:3] for p in data[name]
                  if limit is None or p[0] <= limit]
        if others:
            ax.set_ylim(0, 1.3 * max(others))
        ax.set_xlabel("crossing tetrahedra deleted")
        ax.set_ylabel("time to insert the rectangle (ms)")
        ax.grid(alpha=0.3)
        ax.legend()
    axes[0].set_title("Figure 9: all sizes")
    axes[1].set_title("up to 2,000 crossing tets")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rows, data = load(sys.argv[1])
    failed = summary(rows, data)
    plot(data, sys.argv[2])
    print(f"wrote {sys.argv[2]}")
    # A run that failed makes the figure incomplete: the caller must know.
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
