#!/usr/bin/env python3
"""The Python package's cost against the command line's, on large models.

For each model and switches: the command line's whole process (`tetcdt -Q<switches>
MODEL -o PREFIX`: read, mesh, write), and in one Python process the call
`tetcdt.tetrahedralize(points, faces, switches)` on the model's arrays (conversion in and
out included; the arrays are read once, outside the timing). Medians of REPEAT runs,
taken in turns. Prints a Markdown table with the ratio call / command line.

usage: scripts/python-bench.py [--repeat N] [--binary PATH] [MODEL:SWITCHES ...]

Without models: a smooth closed surface of 82k triangles (scripts/gen-smooth-surface.py
6 1), the corpus bunny (-p and -pq1.414) and 300k random points (no -p). Needs the
package installed (`pip install ./python`) and `cargo build --release`.
"""
import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import tetcdt

REPO = Path(__file__).resolve().parents[1]
CORPUS = REPO.parent / "shared" / "corpus" / "files"


def default_models(tmp: Path) -> list[tuple[Path, str]]:
    surface = tmp / "smooth6.off"
    subprocess.run(
        [sys.executable, str(REPO / "scripts" / "gen-smooth-surface.py"), "6", "1", str(surface)],
        check=True,
    )
    points = tmp / "random300k.node"
    rng = np.random.default_rng(1)
    pts = rng.random((300_000, 3))
    with open(points, "w") as f:
        f.write(f"{len(pts)} 3 0 0\n")
        np.savetxt(f, np.column_stack([np.arange(len(pts)), pts]), fmt="%d %.17g %.17g %.17g")
    models = [(surface, "p"), (points, "")]
    bunny = CORPUS / "tetgentests_cgal" / "bunny00.off"
    if bunny.exists():
        models += [(bunny, "p"), (bunny, "pq1.414")]
    return models


def time_cli(binary: Path, model: Path, switches: str, prefix: Path) -> float:
    start = time.perf_counter()
    subprocess.run(
        [str(binary), "-Q" + switches, str(model), "-o", str(prefix)], check=True
    )
    return time.perf_counter() - start


def time_call(plc: tetcdt.PLC, switches: str) -> tuple[float, int]:
    faces = plc.faces if len(plc.facets) else None
    start = time.perf_counter()
    mesh = tetcdt.tetrahedralize(plc.points, faces, switches, holes=plc.holes, regions=plc.regions)
    return time.perf_counter() - start, len(mesh.tets)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--binary", type=Path, default=REPO / "target" / "release" / "tetcdt")
    ap.add_argument("models", nargs="*", help="MODEL:SWITCHES")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        if args.models:
            models = [(Path(m.rsplit(":", 1)[0]), m.rsplit(":", 1)[1]) for m in args.models]
        else:
            models = default_models(tmp)
        print("| model | switches | tets | command line s | Python call s | call / command line |")
        print("|---|---|---:|---:|---:|---:|")
        for model, switches in models:
            plc = tetcdt.read(model)
            cli_s, call_s, tets = [], [], 0
            for _ in range(args.repeat):
                cli_s.append(time_cli(args.binary, model, switches, tmp / "out"))
                secs, tets = time_call(plc, switches)
                call_s.append(secs)
            c, p = statistics.median(cli_s), statistics.median(call_s)
            print(
                f"| {model.name} | -{switches} | {tets:,} | {c:.3f} | {p:.3f} | {p / c:.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
