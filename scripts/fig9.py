#!/usr/bin/env python3
"""Plots and summarizes scripts/fig9.sh's CSV (Figure 9 of Si & Shewchuk).

usage: fig9.py FIG9.CSV OUT.PNG

Left panel: every size; right panel: up to 2,000 crossing tets (the paper's range). The
y axis is scaled to the other three series: TetGen -L, far slower, is clipped at the top.
Time in milliseconds against crossing tets, for our -C and -F and TetGen's -pcO0 (cavity)
and -pcLO0 (flips). Uses matplotlib when it is installed, else draws the PNG itself (a
plain raster with a small built-in font). Prints a summary: the least-squares line of
each series, the -F/-C ratios, and how we compare with TetGen's counterparts.
"""
import csv
import struct
import sys
import zlib

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


def plot_matplotlib(data, out):
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


# A 3x5 font: each glyph is five rows of three bits.
FONT = {
    "0": "111101101101111", "1": "010110010010111", "2": "111001111100111",
    "3": "111001111001111", "4": "101101111001001", "5": "111100111001111",
    "6": "111100111101111", "7": "111001001010010", "8": "111101111101111",
    "9": "111101111001111", ".": "000000000000010", "-": "000000111000000",
    " ": "000000000000000", ",": "000000000010100", "(": "010100100100010",
    ")": "010001001001010", "/": "001001010100100", ":": "000010000010000",
    "A": "010101111101101", "C": "111100100100111", "D": "110101101101110",
    "E": "111100111100111", "F": "111100111100100", "G": "111100101101111",
    "H": "101101111101101", "I": "111010010010111", "K": "101101110101101",
    "L": "100100100100111", "M": "101111111101101", "N": "110101101101101",
    "O": "111101101101111", "P": "111101111100100", "R": "110101110101101",
    "S": "111100111001111", "T": "111010010010010", "U": "101101101101111",
    "W": "101101111111101", "X": "101101010101101", "Y": "101101010010010",
    "Z": "111001010100111", "B": "110101110101110", "V": "101101101101010",
}


class Canvas:
    def __init__(self, w, h):
        self.w, self.h = w, h
        self.px = bytearray(b"\xff" * (w * h * 3))

    def set(self, x, y, c):
        if 0 <= x < self.w and 0 <= y < self.h:
            i = 3 * (y * self.w + x)
            self.px[i:i + 3] = bytes(c)

    def rect(self, x0, y0, x1, y1, c):
        for y in range(min(y0, y1), max(y0, y1) + 1):
            for x in range(min(x0, x1), max(x0, x1) + 1):
                self.set(x, y, c)

    def line(self, x0, y0, x1, y1, c):
        n = max(abs(x1 - x0), abs(y1 - y0), 1)
        for k in range(n + 1):
            self.set(round(x0 + (x1 - x0) * k / n), round(y0 + (y1 - y0) * k / n), c)

    def text(self, x, y, s, c=(0, 0, 0), scale=2):
        for ch in s.upper():
            g = FONT.get(ch, FONT[" "])
            for r in range(5):
                for q in range(3):
                    if g[3 * r + q] == "1":
                        self.rect(x + q * scale, y + r * scale,
                                  x + q * scale + scale - 1, y + r * scale + scale - 1, c)
            x += 4 * scale

    def save(self, path):
        raw = b"".join(b"\x00" + bytes(self.px[3 * self.w * y:3 * self.w * (y + 1)])
                       for y in range(self.h))
        def chunk(kind, body):
            return (struct.pack(">I", len(body)) + kind + body
                    + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))
        png = (b"\x89PNG\r\n\x1a\n"
               + chunk(b"IHDR", struct.pack(">IIBBBBB", self.w, self.h, 8, 2, 0, 0, 0))
               + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
        open(path, "wb").write(png)


def nice_ticks(hi, n=5):
    if hi <= 0:
        return [0]
    raw = hi / n
    mag = 10 ** len(str(int(raw))) / 10 if raw >= 1 else 10 ** -len(str(int(1 / raw)))
    step = min((m * mag for m in (1, 2, 5, 10) if m * mag >= raw), default=raw)
    return [k * step for k in range(int(hi / step) + 1)]


def fmt(v):
    return f"{v:.0f}" if v >= 10 or v == 0 else f"{v:.2g}"


def panel(cv, data, x0, y0, w, h, limit, title):
    pts_all = [p for name, _, _ in SERIES for p in data[name] if limit is None or p[0] <= limit]
    if not pts_all:
        return
    xmax = max(p[0] for p in pts_all) * 1.05
    # Scaled to ours and TetGen -C; TetGen -L is clipped at the top.
    others = [p[1] for name, _, _ in SERIES[:3] for p in data[name]
              if limit is None or p[0] <= limit] or [p[1] for p in pts_all]
    ymax = max(others) * 1.3
    def tx(x):
        return round(x0 + x / xmax * w)
    def ty(y):
        return round(y0 + h - min(y, ymax) / ymax * h)
    for t in nice_ticks(xmax):
        cv.line(tx(t), y0, tx(t), y0 + h, (230, 230, 230))
        cv.text(tx(t) - 8, y0 + h + 8, fmt(t))
    for t in nice_ticks(ymax):
        cv.line(x0, ty(t), x0 + w, ty(t), (230, 230, 230))
        cv.text(x0 - 8 * len(fmt(t)) - 6, ty(t) - 5, fmt(t))
    cv.line(x0, y0 + h, x0 + w, y0 + h, (0, 0, 0))
    cv.line(x0, y0, x0, y0 + h, (0, 0, 0))
    cv.text(x0, y0 - 22, title)
    cv.text(x0 + w // 2 - 100, y0 + h + 28, "CROSSING TETS")
    cv.text(x0 - 60, y0 - 40, "MS")
    for k, (name, _, color) in enumerate(SERIES):
        pts = [p for p in data[name] if limit is None or p[0] <= limit]
        for a, b in zip(pts, pts[1:]):
            cv.line(tx(a[0]), ty(a[1]), tx(b[0]), ty(b[1]), color)
        for p in pts:
            cv.rect(tx(p[0]) - 2, ty(p[1]) - 2, tx(p[0]) + 2, ty(p[1]) + 2, color)
        cv.rect(x0 + 12, y0 + 10 + 16 * k, x0 + 24, y0 + 20 + 16 * k, color)
        cv.text(x0 + 30, y0 + 10 + 16 * k, name)


def plot_raster(data, out):
    cv = Canvas(1200, 520)
    panel(cv, data, 90, 60, 460, 380, None, "FIGURE 9: ALL SIZES (TETGEN -L CLIPPED)")
    panel(cv, data, 690, 60, 460, 380, 2000, "UP TO 2000 CROSSING TETS")
    cv.save(out)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    rows, data = load(sys.argv[1])
    summary(rows, data)
    try:
        plot_matplotlib(data, sys.argv[2])
    except ImportError:
        plot_raster(data, sys.argv[2])
    print(f"wrote {sys.argv[2]}")


if __name__ == "__main__":
    main()
