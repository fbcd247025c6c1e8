#!/usr/bin/env bash
# Live comparison with TetGen on fresh inputs: meshes new point sets with both
# `tetgen -O0` and our release binary, and requires the same Delaunay tetrahedralization
# (the same tets, with the same orientation up to an even permutation). Also runs the
# independent referee validate_mesh.py --hull on our output.
#
# The seed changes on every run and is printed; reproduce a failure with
#   TETCDT_LIVE_SEED=<seed> scripts/live-compare.sh
#
# Cases (all generated from the seed S):
#   random  N1 points in the unit cube (gen_points.py, seed S),   N1 = 2,000
#   random  N2 points in the unit cube (gen_points.py, seed S+1), N2 = 30,000
#   grid    a shuffled integer grid, 3..6 points per axis (seed S+2)
#   lattice 400 distinct random points of the 10x10x10 integer lattice (seed S+3)
# The grid and lattice are numbered from 0 or 1 (chosen by the seed).
#
# Environment:
#   TETCDT_LIVE_SEED   the seed (default: from the clock)
#   TETCDT_LIVE_SIZES  the random point counts (default "2000 30000")
#   TETCDT_BIN         our binary (default: cargo build --release, target/release/tetcdt)
#   TETCDT_TOOLS       directory of gen_points.py / validate_mesh.py (default ../shared/tools)
#   TETCDT_TIMEOUT     seconds allowed per program run (default 600)
# Exit status: 0 when every case matches, 1 on any mismatch or failure.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SEED="${TETCDT_LIVE_SEED:-$(( ($(date +%s) + RANDOM) % 1000000 ))}"
SIZES="${TETCDT_LIVE_SIZES:-2000 30000}"
TIMEOUT="${TETCDT_TIMEOUT:-600}"

echo "live-compare: seed $SEED (reproduce: TETCDT_LIVE_SEED=$SEED scripts/live-compare.sh)"

find_tool() {
    local name="$1" dir
    for dir in "${TETCDT_TOOLS:-}" "$ROOT/tools" "$ROOT/../shared/tools" /work/shared/tools; do
        if [[ -n "$dir" && -f "$dir/$name" ]]; then
            echo "$dir/$name"
            return 0
        fi
    done
    return 1
}

command -v tetgen >/dev/null || { echo "live-compare: FAIL: tetgen is not on PATH (apt-get install tetgen)" >&2; exit 1; }
command -v python3 >/dev/null || { echo "live-compare: FAIL: python3 is not on PATH" >&2; exit 1; }
GEN_POINTS="$(find_tool gen_points.py || true)"
VALIDATE="$(find_tool validate_mesh.py || true)"
if [[ -z "$VALIDATE" ]]; then
    echo "live-compare: FAIL: validate_mesh.py not found (set TETCDT_TOOLS)" >&2
    exit 1
fi

if [[ -n "${TETCDT_BIN:-}" ]]; then
    BIN="$TETCDT_BIN"
else
    echo "live-compare: cargo build --release"
    (cd "$ROOT" && cargo build --release --quiet)
    BIN="${CARGO_TARGET_DIR:-$ROOT/target}/release/tetcdt"
fi
if [[ "$BIN" != */* ]]; then BIN="$(command -v "$BIN" || echo "$BIN")"; fi
[[ -x "$BIN" ]] || { echo "live-compare: FAIL: no binary at $BIN" >&2; exit 1; }
BIN="$(cd "$(dirname "$BIN")" && pwd)/$(basename "$BIN")" # absolute: runs happen elsewhere

WORK="$(mktemp -d "${TMPDIR:-/tmp}/tetcdt-live.XXXXXX")"
FAILED=()
cleanup() {
    if [[ ${#FAILED[@]} -eq 0 ]]; then rm -rf "$WORK"; else echo "live-compare: files kept in $WORK"; fi
}
trap cleanup EXIT

# ---------------------------------------------------------------- inputs
random_points() { # N OUT SEED
    if [[ -n "$GEN_POINTS" ]]; then
        python3 "$GEN_POINTS" "$1" "$2" "$3"
    else # the same generator as gen_points.py
        python3 - "$@" <<'EOF'
import random, sys
n = int(sys.argv[1]); out = sys.argv[2]; seed = int(sys.argv[3])
rng = random.Random(seed)
with open(out, "w") as f:
    f.write(f"{n} 3 0 0\n")
    for i in range(n):
        f.write(f"{i+1} {rng.random():.17g} {rng.random():.17g} {rng.random():.17g}\n")
EOF
    fi
}

integer_points() { # KIND OUT SEED   (KIND: grid | lattice)
    python3 - "$@" <<'EOF'
import random, sys
kind, out, seed = sys.argv[1], sys.argv[2], int(sys.argv[3])
rng = random.Random(seed)
if kind == "grid":
    nx, ny, nz = (rng.randint(3, 6) for _ in range(3))
    pts = [(x, y, z) for z in range(nz) for y in range(ny) for x in range(nx)]
    rng.shuffle(pts)
else:
    pts = rng.sample([(x, y, z) for z in range(10) for y in range(10) for x in range(10)], 400)
first = rng.randint(0, 1)
with open(out, "w") as f:
    f.write(f"{len(pts)} 3 0 0\n")
    for i, (x, y, z) in enumerate(pts):
        f.write(f"{i + first} {x} {y} {z}\n")
EOF
}

# ---------------------------------------------------------------- comparison
cat >"$WORK/compare.py" <<'EOF'
"""compare.py INPUT.node TETGEN_PREFIX OUR_PREFIX: same tets, same orientation."""
import sys

def rows(path):
    out = []
    with open(path) as f:
        for line in f:
            t = line.split("#", 1)[0].split()
            if t:
                out.append(t)
    n = int(out[0][0])
    if len(out) - 1 < n:
        sys.exit(f"{path}: header says {n} rows, found {len(out) - 1}")
    return out[1 : 1 + n]

def nodes(path):
    r = rows(path)
    return int(r[0][0]) if r else 0, [tuple(float(v) for v in x[1:4]) for x in r]

def tets(prefix):
    base, pts = nodes(prefix + ".node")
    out = {}
    for r in rows(prefix + ".ele"):
        t = [int(v) - base for v in r[1:5]]
        if min(t) < 0 or max(t) >= len(pts):
            sys.exit(f"{prefix}.ele: tet {r[0]} names a node that does not exist")
        s = sorted(t)
        # parity of the permutation that sorts t
        inv = sum(1 for i in range(4) for j in range(i + 1, 4) if t[i] > t[j])
        if tuple(s) in out:
            sys.exit(f"{prefix}.ele: tet {s} appears twice")
        out[tuple(s)] = inv % 2
    return base, pts, out

inp, tg, us = sys.argv[1:4]
_, ipts = nodes(inp)
_, tpts, T = tets(tg)
_, upts, U = tets(us)
problems = []
if tpts != ipts:
    sys.exit(f"TetGen's output points differ from the input ({len(tpts)} vs {len(ipts)}); case unusable")
if upts != ipts:
    problems.append(f"our output points differ from the input ({len(upts)} vs {len(ipts)} points)")
only_us = sorted(set(U) - set(T))
only_tg = sorted(set(T) - set(U))
flipped = sorted(k for k in set(U) & set(T) if U[k] != T[k])
print(f"    tets: ours {len(U)}, TetGen {len(T)}; only ours {len(only_us)}, only TetGen {len(only_tg)}, "
      f"orientation flipped {len(flipped)}")
for label, lst in (("only ours", only_us), ("only TetGen", only_tg), ("flipped", flipped)):
    for k in lst[:5]:
        print(f"    {label}: {list(k)} (0-based) at {[ipts[v] for v in k]}")
    if len(lst) > 5:
        print(f"    {label}: ... {len(lst) - 5} more")
if only_us or only_tg:
    problems.append("the tet sets differ")
if flipped:
    problems.append("tet orientations differ")
for p in problems:
    print(f"    problem: {p}")
sys.exit(1 if problems else 0)
EOF

# ---------------------------------------------------------------- cases
run_case() { # NAME
    local name="$1" dir="$WORK/$1"
    echo "== case $name: $(head -n 1 "$dir/in.node" | awk '{print $1}') points"
    if ! (cd "$dir" && timeout "$TIMEOUT" tetgen -QO0 in.node >tetgen.log 2>&1); then
        echo "    TetGen failed on this input (see $dir/tetgen.log); case skipped"
        return 0
    fi
    local t0 t1
    t0=$(date +%s.%N)
    if ! timeout "$TIMEOUT" "$BIN" -Q -o "$dir/ours" "$dir/in.node" >"$dir/ours.log" 2>&1; then
        echo "    FAIL: tetcdt exited with an error:"
        sed 's/^/      /' "$dir/ours.log" | tail -n 20
        FAILED+=("$name (tetcdt error)")
        return 0
    fi
    t1=$(date +%s.%N)
    echo "    tetcdt took $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }') s"
    if ! python3 "$WORK/compare.py" "$dir/in.node" "$dir/in.1" "$dir/ours"; then
        echo "    FAIL: $name differs from TetGen"
        FAILED+=("$name (differs from TetGen)")
    fi
    if python3 "$VALIDATE" "$dir/in.node" "$dir/ours" --hull --ref "$dir/in.1" >"$dir/validate.log" 2>&1; then
        echo "    validate_mesh.py: $(tail -n 1 "$dir/validate.log")"
    else
        echo "    FAIL: validate_mesh.py rejects our mesh:"
        sed 's/^/      /' "$dir/validate.log" | tail -n 20
        FAILED+=("$name (validate_mesh.py)")
    fi
}

k=0
for n in $SIZES; do
    name="random$n"
    mkdir -p "$WORK/$name"
    random_points "$n" "$WORK/$name/in.node" $((SEED + k))
    run_case "$name"
    k=$((k + 1))
done
mkdir -p "$WORK/grid" "$WORK/lattice"
integer_points grid "$WORK/grid/in.node" $((SEED + 2))
run_case grid
integer_points lattice "$WORK/lattice/in.node" $((SEED + 3))
run_case lattice

if [[ ${#FAILED[@]} -gt 0 ]]; then
    echo "live-compare: FAILED (seed $SEED): ${FAILED[*]}"
    echo "live-compare: reproduce with TETCDT_LIVE_SEED=$SEED scripts/live-compare.sh"
    exit 1
fi
echo "live-compare: OK, all cases match TetGen (seed $SEED)"
