#!/usr/bin/env python3
"""Meshes CSG parts (scripts/gen-csg-parts.py: cheese, flange, bricks) with tetcdt -pQ and
TetGen -pO0Q in turns, and sums up validity, Steiner points and time.

usage: scripts/csg-parts.py [--count N] [--kinds K,...] [--keep DIR]

For each kind and seed 1..N (default 12): the part is written as OFF, meshed by both
programs (each in its own directory, timeout 120 s), and each mesh that exits 0 is judged
by the shared referee (validate_mesh.py). Prints one row per part (exit code, referee's
verdict, output nodes, seconds for each program) and, per kind and in all: parts meshed
with exit 0, meshes the referee accepts, meshes it rejects, and the total time of each
program over the parts both mesh validly. --keep DIR keeps the work directory.
Needs manifold3d and numpy, and tetgen on PATH (its columns are empty without it).
Environment: TETCDT (the binary, default target/release/tetcdt), TETCDT_TOOLS (the
directory of validate_mesh.py, default ../shared/tools).
"""
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TETCDT = os.environ.get("TETCDT", os.path.join(ROOT, "target", "release", "tetcdt"))
TOOLS = os.environ.get("TETCDT_TOOLS", os.path.join(ROOT, "..", "shared", "tools"))


def timed(cmd, cwd):
    start = time.monotonic()
    try:
        rc = subprocess.run(cmd, cwd=cwd, capture_output=True, timeout=120).returncode
    except subprocess.TimeoutExpired:
        rc = "timeout"
    return rc, time.monotonic() - start


def verdict(inp, prefix):
    v = subprocess.run([sys.executable, os.path.join(TOOLS, "validate_mesh.py"), inp, prefix],
                       capture_output=True, text=True)
    last = (v.stdout.strip().splitlines() or ["?"])[-1]
    return "valid" if v.returncode == 0 else "rejected: " + last.removeprefix("INVALID: ")


def nodes(prefix):
    with open(prefix + ".node") as f:
        return int(f.readline().split()[0])


def main(argv):
    opts = {"--count": "12", "--kinds": "cheese,flange,bricks", "--keep": ""}
    args = list(argv[1:])
    while args:
        a = args.pop(0)
        if a in ("-h", "--help"):
            print(__doc__)
            return 0
        if a in opts and args:
            opts[a] = args.pop(0)
        else:
            print(f"csg-parts.py: unknown or incomplete option {a} (see --help)", file=sys.stderr)
            return 2
    tetgen = shutil.which("tetgen")
    work = opts["--keep"] or tempfile.mkdtemp()
    os.makedirs(os.path.join(work, "tg"), exist_ok=True)
    print("| part | input vertices | tetcdt exit | referee | nodes | s | TetGen exit | referee | nodes | s |")
    print("|---|---:|---:|---|---:|---:|---:|---|---:|---:|")
    totals = {}
    for kind in opts["--kinds"].split(","):
        t = totals.setdefault(kind, dict(parts=0, ours_ok=0, ours_valid=0, ours_rejected=0,
                                         tg_ok=0, tg_valid=0, tg_rejected=0,
                                         both=0, ours_s=0.0, tg_s=0.0))
        for seed in range(1, int(opts["--count"]) + 1):
            name = f"{kind}_{seed}"
            inp = os.path.join(work, name + ".off")
            subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "gen-csg-parts.py"),
                            kind, str(seed), inp], check=True)
            shutil.copy(inp, os.path.join(work, "tg"))
            with open(inp) as f:
                f.readline()
                n_in = int(f.readline().split()[0])
            t["parts"] += 1
            rc, secs = timed([TETCDT, "-pQ", "-o", "ours_" + name, name + ".off"], work)
            v = verdict(inp, os.path.join(work, "ours_" + name)) if rc == 0 else "-"
            n = nodes(os.path.join(work, "ours_" + name)) if rc == 0 else "-"
            t["ours_ok"] += rc == 0
            t["ours_valid"] += v == "valid"
            t["ours_rejected"] += v.startswith("rejected")
            trc, tsecs, tv, tn = "-", 0.0, "-", "-"
            if tetgen:
                trc, tsecs = timed([tetgen, "-pO0Q", name + ".off"], os.path.join(work, "tg"))
                if trc == 0:
                    tv = verdict(inp, os.path.join(work, "tg", name + ".1"))
                    tn = nodes(os.path.join(work, "tg", name + ".1"))
                t["tg_ok"] += trc == 0
                t["tg_valid"] += tv == "valid"
                t["tg_rejected"] += tv.startswith("rejected")
            if v == "valid" and tv == "valid":
                t["both"] += 1
                t["ours_s"] += secs
                t["tg_s"] += tsecs
            print(f"| {name} | {n_in} | {rc} | {v} | {n} | {secs:.2f} | {trc} | {tv} | {tn} "
                  f"| {tsecs:.2f} |")
    print()
    print("| kind | parts | tetcdt exit 0 | valid | rejected | TetGen exit 0 | valid | rejected "
          "| both valid: time ours / TetGen |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for kind, t in totals.items():
        ratio = f"{t['ours_s'] / t['tg_s']:.2f} ({t['both']} parts)" if t["tg_s"] > 0 else "-"
        print(f"| {kind} | {t['parts']} | {t['ours_ok']} | {t['ours_valid']} | "
              f"{t['ours_rejected']} | {t['tg_ok']} | {t['tg_valid']} | {t['tg_rejected']} | "
              f"{ratio} |")
    if not opts["--keep"]:
        shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
