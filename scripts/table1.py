#!/usr/bin/env python3
"""Si & Shewchuk's Table 1 and Table 2 for any folder of models, ours beside TetGen's.

For every model it runs

  tetcdt -pQV  --stats-json R -o TMP/out MODEL   (cavity retriangulation)
  tetcdt -pFQV --stats-json R -o TMP/out MODEL   (flips)
  tetgen -pO0V  MODEL                            (parsing its -V report)
  tetgen -pLO0V MODEL

(TetGen on a symbolic link in a temporary folder, so nothing is written beside the
models) and writes markdown:

- Table 1: the paper's rows (1)-(16), one "ours" and one "TetGen" column per model.
  As in the paper, a column mixes both algorithms: rows (8) and (15) come from the flip
  runs, every other row from the cavity run. TetGen's -V report has no figures for
  rows (6)-(11); those cells say "-".
- Table 2: the share of the CDT time spent in the Delaunay tetrahedralization, segment
  recovery, facet recovery and the rest, for each of the four runs.

A run that fails, times out or is refused is marked in its cells ("fail 3", "timeout",
"n/a") and explained under the tables. Standard library only.

Usage: scripts/table1.py [options] FOLDER_OR_MODEL...
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

# Inputs a folder contributes: PLC formats of tetcdt and TetGen (not .node point sets).
MODEL_EXTS = (".poly", ".smesh", ".off", ".obj", ".mesh", ".stl", ".ply")

# Table 1 rows: (label, key in our records or a function of (cavity, flip) records).
ROWS = [
    ("(1) input vertices", "input_points"),
    ("(2) input polygons", "input_polygons"),
    ("(3) Steiner points", "steiner_points"),
    ("(4) output tetrahedra", "output_tets"),
    ("(5) output subpolygons", "output_subfaces"),
    ("(6) recovered subpolygons", "recovered_subfaces"),
    ("(7) most recovered in one region", "max_region_subfaces"),
    ("(8) flips (flip algorithm)", "flips"),
    ("(9) crossing tetrahedra", "crossing_tets"),
    ("(10) most crossing in one region", "max_region_crossing_tets"),
    ("(11) mean crossing per region", "mean_crossing"),
    ("missing regions", "regions"),
    ("(12) Delaunay seconds", "delaunay_secs"),
    ("(13) segment recovery seconds", "segment_secs"),
    ("surface mesh seconds", "surface_secs"),
    ("(14) cavity retriangulation seconds", "facet_secs"),
    ("(15) flip algorithm seconds", "flip_facet_secs"),
    ("(16) total CDT seconds (cavity)", "total_secs"),
]

# TetGen's -V lines: (regular expression, key).
TETGEN_LINES = [
    (r"^Delaunay seconds:\s*(\S+)", "delaunay_secs"),
    (r"^Surface mesh seconds:\s*(\S+)", "surface_secs"),
    (r"^Constrained Delaunay seconds:\s*(\S+)", "cdt_secs"),
    (r"^\s*Segment recovery seconds:\s*(\S+)", "segment_secs"),
    (r"^\s*Facet recovery seconds:\s*(\S+)", "facet_secs"),
    (r"^Exterior tets removal seconds:\s*(\S+)", "carve_secs"),
    (r"^Total running seconds:\s*(\S+)", "wall_secs"),
    (r"^\s*Input points:\s*(\d+)", "input_points"),
    (r"^\s*Input facets:\s*(\d+)", "input_polygons"),
    (r"^\s*Mesh tetrahedra:\s*(\d+)", "output_tets"),
    (r"^\s*Mesh faces on facets:\s*(\d+)", "output_subfaces"),
    (r"^\s*Remeshed (\d+) regions", "regions"),
]


def models_of(args):
    """The model files named by the arguments (folders are listed, sorted)."""
    out = []
    for a in args:
        if os.path.isdir(a):
            for name in sorted(os.listdir(a)):
                p = os.path.join(a, name)
                if os.path.isfile(p) and name.lower().endswith(MODEL_EXTS):
                    out.append(p)
        elif os.path.isfile(a):
            out.append(a)
        else:
            sys.exit(f"table1.py: {a}: no such file or folder")
    if not out:
        sys.exit("table1.py: no models found")
    return out


def short_name(path, taken):
    """A column name: the file name up to its first dot, unless that is ambiguous."""
    base = os.path.basename(path)
    name = base.split(".")[0] or base
    return base if name in taken else name


def run(cmd, cwd, timeout):
    """Runs cmd; returns (exit code or None on timeout, stdout, stderr, seconds)."""
    t = time.monotonic()
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True,
                           errors="replace", timeout=timeout, stdin=subprocess.DEVNULL)
        return p.returncode, p.stdout, p.stderr, time.monotonic() - t
    except subprocess.TimeoutExpired:
        return None, "", "", time.monotonic() - t


def first_error(stderr, code):
    """The first line of an error message, for the notes."""
    for line in stderr.splitlines():
        if line.strip():
            line = line.strip()
            return line[len("tetcdt: "):] if line.startswith("tetcdt: ") else line
    return f"exit code {code}"


def run_ours(tetcdt, model, switches, timeout, work):
    """Runs tetcdt; returns (record or None, status text, note)."""
    stats = os.path.join(work, "stats.json")
    if os.path.exists(stats):
        os.remove(stats)
    cmd = [tetcdt, switches, "--stats-json", stats, "-o", os.path.join(work, "out"),
           os.path.abspath(model)]
    code, _, err, secs = run(cmd, work, timeout)
    if code is None:
        return None, "timeout", f"`tetcdt {switches}` timed out after {timeout:g} s"
    if code != 0:
        msg = first_error(err, code)
        if code == 2 and "not implemented" in msg:
            return None, "n/a", f"`tetcdt {switches}` is refused: {msg}"
        return None, f"fail {code}", f"`tetcdt {switches}`: {msg}"
    try:
        with open(stats) as f:
            rec = json.loads(f.readline())
    except (OSError, ValueError) as e:
        return None, "fail", f"`tetcdt {switches}`: no statistics record ({e})"
    rec["wall_secs"] = secs
    return rec, "ok", None


def link_model(model, work):
    """A symbolic link to the model (and its sibling .node) in work; returns the link."""
    for name in os.listdir(work):
        os.remove(os.path.join(work, name))
    src = os.path.abspath(model)
    link = os.path.join(work, os.path.basename(model))
    os.symlink(src, link)
    stem, ext = os.path.splitext(src)
    if ext in (".poly", ".smesh") and os.path.exists(stem + ".node"):
        os.symlink(stem + ".node", os.path.join(work, os.path.basename(stem) + ".node"))
    return link


def parse_tetgen(text):
    """The figures of TetGen's -V report."""
    rec = {}
    steiner = 0
    for line in text.splitlines():
        for pattern, key in TETGEN_LINES:
            m = re.match(pattern, line)
            if m:
                rec[key] = float(m.group(1)) if "secs" in key else int(m.group(1))
        # "Steiner points on segments:  69", "Steiner points in facets: ...", ...
        m = re.match(r"^\s*Steiner points [a-z ]+:\s*(\d+)", line)
        if m:
            steiner += int(m.group(1))
    if "output_tets" not in rec:
        return None
    rec["steiner_points"] = steiner
    rec.setdefault("regions", 0)
    parts = ("delaunay_secs", "surface_secs", "cdt_secs", "carve_secs")
    rec["total_secs"] = sum(rec.get(k, 0.0) for k in parts)
    return rec


def run_tetgen(tetgen, model, switches, timeout, work):
    """Runs TetGen on a link to the model; returns (record or None, status, note)."""
    if tetgen is None:
        return None, "n/a", "TetGen is not installed"
    link = link_model(model, work)
    code, out, err, secs = run([tetgen, switches, os.path.basename(link)], work, timeout)
    if code is None:
        return None, "timeout", f"`tetgen {switches}` timed out after {timeout:g} s"
    rec = parse_tetgen(out)
    if code != 0 or rec is None:
        lines = [l.strip() for l in (err + "\n" + out).splitlines() if l.strip()]
        why = next((l for l in lines if "rror" in l or "failed" in l.lower()),
                   lines[-1] if lines else f"exit code {code}")
        return None, f"fail {code}", f"`tetgen {switches}`: {why}"
    rec["wall_secs"] = secs
    return rec, "ok", None


def ours_value(key, cav, flip):
    """One cell of our column."""
    if key in ("flips", "flip_facet_secs"):
        rec, inner = flip, {"flips": "flips", "flip_facet_secs": "facet_secs"}[key]
    else:
        rec, inner = cav, key
    if rec["record"] is None:
        return rec["status"]
    r = rec["record"]
    if key == "flips":
        # Whatever the flip algorithm calls its count of flips.
        counts = [v for k, v in r.items() if "flip" in k and isinstance(v, int)
                  and not isinstance(v, bool)]
        return fmt(counts[0]) if counts else "-"
    if key == "mean_crossing":
        if "crossing_tets" not in r:
            return "-"
        n = r.get("regions", 0)
        return f"{r['crossing_tets'] / n:.1f}" if n else "0.0"
    return fmt(r.get(inner))


def tetgen_value(key, cav, flip):
    """One cell of TetGen's column ("-" where its report has no such figure)."""
    if key in ("flips", "flip_facet_secs"):
        rec, inner = flip, {"flips": "flips", "flip_facet_secs": "facet_secs"}[key]
    else:
        rec, inner = cav, key
    if rec["record"] is None:
        return rec["status"]
    return fmt(rec["record"].get(inner))


def fmt(v):
    """A figure as the paper prints it."""
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4f}"
    if isinstance(v, int) and not isinstance(v, bool):
        return f"{v:,}"
    return str(v)


def shares(rec):
    """Delaunay, segments, surface mesh, facets, other as percentages of the CDT time, or
    None."""
    if rec is None:
        return None
    total = rec.get("total_secs") or 0.0
    if total <= 0:
        return None
    d = rec.get("delaunay_secs", 0.0)
    s = rec.get("segment_secs", 0.0)
    m = rec.get("surface_secs", 0.0)
    f = rec.get("facet_secs", 0.0)
    other = max(total - d - s - m - f, 0.0)
    return [100.0 * x / total for x in (d, s, m, f, other)]


def markdown(results, args):
    """The report."""
    names = [r["name"] for r in results]
    out = ["# Table 1 and Table 2 (Si & Shewchuk), tetcdt beside TetGen", ""]
    out.append(f"Generated by `scripts/table1.py` on {time.strftime('%Y-%m-%d %H:%M')} "
               f"with `{args.tetcdt}` and `{args.tetgen or 'no TetGen'}`; "
               f"timeout {args.timeout:g} s per run.")
    out.append("")
    out.append("## Table 1: statistics for CDT construction")
    out.append("")
    out.append("Ours: `tetcdt -pQV` (cavity retriangulation), rows (8) and (15) from "
               "`tetcdt -pFQV` (flips). TetGen: `tetgen -pO0V`, row (15) from "
               "`tetgen -pLO0V`. `-`: not reported.")
    out.append("")
    head = ["row"]
    for n in names:
        head += [f"{n} ours", f"{n} TetGen"]
    out.append("| " + " | ".join(head) + " |")
    out.append("| :--- " + "| ---: " * (len(head) - 1) + "|")
    for label, key in ROWS:
        cells = [label]
        for r in results:
            cells.append(ours_value(key, r["ours"], r["ours_flip"]))
            cells.append(tetgen_value(key, r["tetgen"], r["tetgen_flip"]))
        out.append("| " + " | ".join(cells) + " |")
    out.append("")
    out.append("## Table 2: share of the CDT time per task")
    out.append("")
    out.append("The CDT time is ours `total_secs` (the meshing call, restarts included), "
               "TetGen's the sum of its Delaunay, surface mesh, constrained Delaunay and "
               "exterior removal seconds. \"other\" is the rest (facet merging, carving, "
               "restarts).")
    out.append("")
    runs = [("ours -p (cavity)", "ours"), ("ours -pF (flips)", "ours_flip"),
            ("TetGen -p", "tetgen"), ("TetGen -pL", "tetgen_flip")]
    tasks = ["Delaunay", "segment recovery", "surface mesh", "facet recovery", "other"]
    out.append("| run | task | " + " | ".join(names) + " |")
    out.append("| :--- | :--- " + "| ---: " * len(names) + "|")
    for label, which in runs:
        for i, task in enumerate(tasks):
            cells = [label if i == 0 else "", task]
            for r in results:
                s = shares(r[which]["record"])
                cells.append(f"{s[i]:.1f} %" if s else r[which]["status"])
            out.append("| " + " | ".join(cells) + " |")
    # The same note for several models (a refused switch, say) is listed once.
    notes = {}
    for r in results:
        for which in ("ours", "ours_flip", "tetgen", "tetgen_flip"):
            note = r[which]["note"]
            if note:
                note = note.replace(os.path.abspath(r["path"]), "MODEL")
                notes.setdefault(note.replace(r["path"], "MODEL"), []).append(r["name"])
    if notes:
        out.append("")
        out.append("## Notes")
        out.append("")
        for note, who in notes.items():
            whom = "all models" if len(who) == len(results) > 1 else ", ".join(who)
            out.append(f"- {whom}: {note}")
    out.append("")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("models", nargs="+", help="model files or folders of models")
    ap.add_argument("-o", "--output", default="-", help="markdown file (default: stdout)")
    ap.add_argument("--tetcdt", default=os.path.join(os.path.dirname(__file__), "..",
                                                    "target", "release", "tetcdt"),
                    help="the tetcdt binary (default: target/release/tetcdt)")
    ap.add_argument("--tetgen", default=shutil.which("tetgen"),
                    help="the TetGen binary (default: tetgen on PATH)")
    ap.add_argument("--timeout", type=float, default=300.0,
                    help="seconds per run before it is abandoned (default 300)")
    ap.add_argument("--records", help="also write every run's figures as JSON Lines here")
    args = ap.parse_args()
    args.tetcdt = os.path.abspath(args.tetcdt)
    if not os.access(args.tetcdt, os.X_OK):
        sys.exit(f"table1.py: {args.tetcdt}: not an executable (cargo build --release?)")

    results = []
    taken = set()
    with tempfile.TemporaryDirectory(prefix="table1-") as work:
        for path in models_of(args.models):
            name = short_name(path, taken)
            taken.add(name)
            r = {"name": name, "path": path}
            for which, run_one, prog, sw in (
                    ("ours", run_ours, args.tetcdt, "-pQV"),
                    ("ours_flip", run_ours, args.tetcdt, "-pFQV"),
                    ("tetgen", run_tetgen, args.tetgen, "-pO0V"),
                    ("tetgen_flip", run_tetgen, args.tetgen, "-pLO0V")):
                rec, status, note = run_one(prog, path, sw, args.timeout, work)
                r[which] = {"record": rec, "status": status, "note": note}
            print(f"{name}: ours {r['ours']['status']}, ours -F {r['ours_flip']['status']}, "
                  f"TetGen {r['tetgen']['status']}, TetGen -L {r['tetgen_flip']['status']}",
                  file=sys.stderr)
            results.append(r)
    text = markdown(results, args)
    if args.output == "-":
        sys.stdout.write(text)
    else:
        with open(args.output, "w") as f:
            f.write(text)
    if args.records:
        with open(args.records, "w") as f:
            for r in results:
                for which in ("ours", "ours_flip", "tetgen", "tetgen_flip"):
                    f.write(json.dumps({"model": r["path"], "run": which,
                                        "status": r[which]["status"],
                                        "note": r[which]["note"],
                                        "figures": r[which]["record"]}) + "\n")
    # Our own meshing failures (not refusals of invalid input, exit 3) make the table
    # wrong: exit 1. TetGen's are only reported.
    ours_failed = [f"{r['name']} ({w}): {r[w]['note']}" for r in results
                   for w in ("ours", "ours_flip")
                   if r[w]["status"] not in ("ok", "n/a", "fail 3")]
    for f in ours_failed:
        print(f"table1.py: failed: {f}", file=sys.stderr)
    sys.exit(1 if ours_failed else 0)


if __name__ == "__main__":
    main()
