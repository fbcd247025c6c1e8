#!/usr/bin/env python3
"""Compares `tetcdt --certify` with the shared referee (validate_mesh.py) on the meshes of
every corpus model: ours (`tetcdt -pQ`), TetGen's plain CDT (`tetgen -pO0Q`) and TetGen's
optimized mesh (`tetgen -pQ`, no CDT: its flips break the Delaunay property).

usage: scripts/certify-vs-referee.py [--jobs N] [--keep DIR] [PATTERN...]

Models: the corpus files the referee reads (.off .poly .smesh .mesh .node) that TetGen
meshes with -pO0 (tetgen_p_O0.tsv), outside tetgen_stp/. Each mesh gets both verdicts;
the table lists every model, and the disagreements are listed at the end. Exits 1 when
a verdict could not be had (a crash, a timeout) or when the two disagree, except where
a disagreement was looked into and the referee found wrong (KNOWN, with the reason).

Environment: CORPUS (default ../shared/corpus), TETCDT (default target/release/tetcdt),
TETCDT_TOOLS (the directory of validate_mesh.py, default ../shared/tools), TIMEOUT
(seconds per command, default 600).
"""
import concurrent.futures
import csv
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.environ.get("CORPUS", os.path.join(ROOT, "..", "shared", "corpus"))
TETCDT = os.environ.get("TETCDT", os.path.join(ROOT, "target", "release", "tetcdt"))
TOOLS = os.environ.get("TETCDT_TOOLS", os.path.join(ROOT, "..", "shared", "tools"))
TIMEOUT = int(os.environ.get("TIMEOUT", "600"))
READABLE = (".off", ".poly", ".smesh", ".mesh", ".node")

# Disagreements looked into, where the referee is wrong, and why. anchor_dense: a Steiner
# point on the segment between two nearly coplanar facets that stay unmerged (more than
# 0.1 degree apart) lies within the thick slab of the merged facet beside them (its
# thickness is four times the facet's deviation from flat); the referee counts it on
# that facet, so it takes a flat tet between the two facets for a shim, then leaves the
# face beneath it out of the facet's cover. The point lies on no polygon of that facet.
KNOWN: dict = {}


def run(cmd, cwd):
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=TIMEOUT)
        return p.returncode, p.stdout + p.stderr
    except subprocess.TimeoutExpired:
        return None, "timeout"


def verdicts(work, name, prefix):
    """(certify, referee) for the mesh `prefix` of model `name`: True, False or None."""
    if not os.path.exists(os.path.join(work, prefix + ".ele")):
        return None, None, "no mesh"
    rc, out = run([TETCDT, "--certify", prefix, name], work)
    cert = {0: True, 1: False}.get(rc)
    first = [l for l in out.splitlines() if l.startswith("  ")][:1]
    rc2, out2 = run([sys.executable, os.path.join(TOOLS, "validate_mesh.py"), name, prefix], work)
    ref = {0: True, 1: False}.get(rc2)
    last = out2.strip().splitlines()[-1] if out2.strip() else ""
    if cert is None or ref is None:
        return cert, ref, f"no verdict: certify exit {rc}, referee exit {rc2}"
    note = (first[0].strip() if first else "") + (" | " + last if ref is False else "")
    return cert, ref, note


def one(rel):
    src = os.path.join(CORPUS, "files", rel)
    name = os.path.basename(src)
    stem = name.rsplit(".", 1)[0]
    with tempfile.TemporaryDirectory() as work:
        shutil.copy(src, work)
        rows = []
        jobs = [
            ("ours", [TETCDT, "-pQ", "-o", "ours", name], "ours"),
            ("tetgen -pO0", ["tetgen", "-pO0Q", name], stem + ".1"),
            ("tetgen -p", ["tetgen", "-pQ", name], stem + ".1"),
        ]
        for label, cmd, prefix in jobs:
            for ext in ("node", "ele", "face", "edge"):
                p = os.path.join(work, f"{stem}.1.{ext}")
                if os.path.exists(p):
                    os.remove(p)
            rc, out = run(cmd, work)
            if rc != 0:
                rows.append((rel, label, None, None, f"mesher exit {rc}"))
                continue
            cert, ref, note = verdicts(work, name, prefix)
            rows.append((rel, label, cert, ref, note))
        return rows


def main(argv):
    jobs = 2
    patterns = []
    it = iter(argv)
    for a in it:
        if a == "--jobs":
            jobs = int(next(it))
        elif a in ("-h", "--help"):
            print(__doc__)
            return 0
        else:
            patterns.append(a)
    with open(os.path.join(CORPUS, "tetgen_p_O0.tsv")) as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    models = sorted(
        r["file"] for r in rows
        if r["mode"] == "-pO0" and r["rc"].strip() == "0" and r["file"].endswith(READABLE)
        and not r["file"].startswith("tetgen_stp/")
        and (not patterns or any(p in r["file"] for p in patterns))
    )
    table = []
    with concurrent.futures.ThreadPoolExecutor(jobs) as ex:
        for rows_ in ex.map(one, models):
            for r in rows_:
                table.append(r)
                print(f"{r[0]}\t{r[1]}\tcertify={r[2]}\treferee={r[3]}\t{r[4]}", file=sys.stderr)
    show = {True: "valid", False: "INVALID", None: "–"}
    print("| model | mesh | --certify | referee | first problem |")
    print("|---|---|---|---|---|")
    for rel, label, cert, ref, note in table:
        print(f"| `{rel}` | {label} | {show[cert]} | {show[ref]} | {note.replace('|', '/')} |")
    disagree = [r for r in table if r[2] is not None and r[3] is not None and r[2] != r[3]
                and (r[0], r[1]) not in KNOWN]
    known = [r for r in table if r[2] is not None and r[3] is not None and r[2] != r[3]
             and (r[0], r[1]) in KNOWN]
    # A mesher may refuse a model or write an empty mesh (an open surface); a verdict
    # that could not be had is a failure.
    missing = [r for r in table if r[4].startswith("no verdict")]
    for r in missing:
        print(f"- `{r[0]}` ({r[1]}): {r[4]}")
    agree = sum(1 for r in table if r[2] is not None and r[2] == r[3])
    print()
    print(f"{agree} meshes with the same verdict, {len(known)} known disagreements, "
          f"{len(disagree)} others.")
    for r in known:
        print(f"- known: `{r[0]}` ({r[1]}): --certify {show[r[2]]}, referee {show[r[3]]}: "
              f"{KNOWN[(r[0], r[1])]}")
    for r in disagree:
        print(f"- `{r[0]}` ({r[1]}): --certify {show[r[2]]}, referee {show[r[3]]}: {r[4]}")
    return 1 if disagree or missing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
