#!/usr/bin/env bash
# Delaunay benchmark against TetGen on the same machine, in the same run.
#
#   scripts/bench-delaunay.sh [N] [RUNS]      (defaults: N = 1000000, RUNS = 3)
#
# Generates N random points in the unit cube (gen_points.py, seed $TETCDT_BENCH_SEED,
# default 7) once into a cache directory, builds `cargo build --release`, then runs RUNS
# times, alternately,
#   /usr/bin/time -v tetcdt -Q points.node
#   /usr/bin/time -v tetgen -QO0 points.node
# (both write their .node/.ele/.face output), and prints the best and median wall times,
# the peak resident set sizes and the ratios ours/TetGen as a markdown table for the
# README. Targets: time ratio <= 0.5, memory ratio <= 1.0 (reported, not enforced).
# Exits non-zero if a program fails or the two sets of tets differ.
#
# Environment:
#   TETCDT_BENCH_SEED  point seed (default 7)
#   TETCDT_BENCH_DIR   cache/work directory (default target/bench-data)
#   TETCDT_BIN         our binary (default: cargo build --release, target/release/tetcdt)
#   TETCDT_TOOLS       directory of gen_points.py (default ../shared/tools)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
N="${1:-1000000}"
RUNS="${2:-3}"
SEED="${TETCDT_BENCH_SEED:-7}"
TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target}"
CACHE="${TETCDT_BENCH_DIR:-$TARGET_DIR/bench-data}"

[[ "$N" =~ ^[0-9]+$ && "$RUNS" =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [N] [RUNS]" >&2; exit 2; }
[[ -x /usr/bin/time ]] || { echo "bench: /usr/bin/time missing (apt-get install -y time)" >&2; exit 1; }
command -v tetgen >/dev/null || { echo "bench: tetgen missing (apt-get install -y tetgen)" >&2; exit 1; }

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

# ---------------------------------------------------------------- points (cached)
mkdir -p "$CACHE"
POINTS="$CACHE/points-$N-s$SEED.node"
if [[ ! -s "$POINTS" ]]; then
    echo "bench: generating $N points (seed $SEED) into $POINTS"
    if GEN_POINTS="$(find_tool gen_points.py)"; then
        python3 "$GEN_POINTS" "$N" "$POINTS.tmp" "$SEED"
    else # the same generator as gen_points.py
        python3 - "$N" "$POINTS.tmp" "$SEED" <<'EOF'
import random, sys
n = int(sys.argv[1]); out = sys.argv[2]; seed = int(sys.argv[3])
rng = random.Random(seed)
with open(out, "w") as f:
    f.write(f"{n} 3 0 0\n")
    for i in range(n):
        f.write(f"{i+1} {rng.random():.17g} {rng.random():.17g} {rng.random():.17g}\n")
EOF
    fi
    mv "$POINTS.tmp" "$POINTS"
fi

# ---------------------------------------------------------------- binary
if [[ -n "${TETCDT_BIN:-}" ]]; then
    BIN="$TETCDT_BIN"
else
    echo "bench: cargo build --release"
    (cd "$ROOT" && cargo build --release --quiet)
    BIN="$TARGET_DIR/release/tetcdt"
fi
if [[ "$BIN" != */* ]]; then BIN="$(command -v "$BIN" || echo "$BIN")"; fi
[[ -x "$BIN" ]] || { echo "bench: no binary at $BIN" >&2; exit 1; }
BIN="$(cd "$(dirname "$BIN")" && pwd)/$(basename "$BIN")" # absolute: runs happen elsewhere

# ---------------------------------------------------------------- runs
# Each program gets its own directory holding a link to the input, so their outputs
# (points.1.node/.ele/.face, written next to the input) do not collide.
RUN="$CACHE/run-$N-s$SEED"
rm -rf "$RUN"
mkdir -p "$RUN/tetcdt" "$RUN/tetgen"
ln -s "$POINTS" "$RUN/tetcdt/points.node"
ln -s "$POINTS" "$RUN/tetgen/points.node"
RESULTS="$RUN/results.txt"
: >"$RESULTS"

measure() { # LABEL DIR CMD...  -> appends "LABEL wall_s rss_kb" to $RESULTS
    local label="$1" dir="$2"
    shift 2
    local t0 t1 rss
    t0=$(date +%s.%N)
    if ! (cd "$dir" && /usr/bin/time -v -o time.log "$@" >run.log 2>&1); then
        echo "bench: FAIL: $label exited with an error:" >&2
        tail -n 20 "$dir/run.log" "$dir/time.log" >&2
        exit 1
    fi
    t1=$(date +%s.%N)
    rss=$(awk -F: '/Maximum resident set size/ { gsub(/ /, "", $2); print $2 }' "$dir/time.log")
    echo "$label $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }') $rss" >>"$RESULTS"
    echo "bench:   $label: $(tail -n 1 "$RESULTS" | awk '{ printf "%s s, %.1f MiB", $2, $3 / 1024 }')"
}

echo "bench: $N points, $RUNS runs each, $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')"
for ((r = 1; r <= RUNS; r++)); do
    echo "bench: run $r/$RUNS"
    measure tetcdt "$RUN/tetcdt" "$BIN" -Q points.node
    measure tetgen "$RUN/tetgen" tetgen -QO0 points.node
done

ele_count() { head -n 1 "$1" | awk '{ print $1 }'; }
OURS_TETS=$(ele_count "$RUN/tetcdt/points.1.ele")
TG_TETS=$(ele_count "$RUN/tetgen/points.1.ele")
# The same tets, not only as many: both number the nodes as the input does.
SAME_TETS=yes
python3 - "$RUN/tetcdt/points.1.ele" "$RUN/tetgen/points.1.ele" <<'EOF' || SAME_TETS=no
import sys
import numpy as np
def tets(path):
    t = np.loadtxt(path, dtype=np.int64, comments="#", skiprows=1, usecols=(1, 2, 3, 4))
    t.sort(axis=1)
    return t[np.lexsort(t.T[::-1])]
a, b = tets(sys.argv[1]), tets(sys.argv[2])
sys.exit(0 if a.shape == b.shape and (a == b).all() else 1)
EOF
# The outputs are large (hundreds of MB at 1M points); keep only the logs.
rm -f "$RUN"/*/points.1.*

python3 - "$RESULTS" "$N" "$SEED" "$RUNS" "$OURS_TETS" "$TG_TETS" <<'EOF'
import statistics, sys
path, n, seed, runs, ours_tets, tg_tets = sys.argv[1:]
wall, rss = {"tetcdt": [], "tetgen": []}, {"tetcdt": [], "tetgen": []}
for line in open(path):
    label, w, m = line.split()
    wall[label].append(float(w)); rss[label].append(int(m) / 1024)
best = {k: min(v) for k, v in wall.items()}
med = {k: statistics.median(v) for k, v in wall.items()}
mem = {k: max(v) for k, v in rss.items()}
ratio = lambda d: d["tetcdt"] / d["tetgen"] if d["tetgen"] > 0 else float("inf")
ok = lambda r, t: "met" if r <= t else "NOT met"
print()
print(f"| {int(n):,} random points (seed {seed}) | tetcdt `-Q` | TetGen 1.5.0 `-QO0` | tetcdt / TetGen | target |")
print("|---|---:|---:|---:|---:|")
print(f"| wall time, best of {runs} (s) | {best['tetcdt']:.2f} | {best['tetgen']:.2f} | {ratio(best):.2f} | ≤ 0.5 ({ok(ratio(best), 0.5)}) |")
print(f"| wall time, median of {runs} (s) | {med['tetcdt']:.2f} | {med['tetgen']:.2f} | {ratio(med):.2f} | |")
print(f"| peak RSS (MiB) | {mem['tetcdt']:.1f} | {mem['tetgen']:.1f} | {ratio(mem):.2f} | ≤ 1.0 ({ok(ratio(mem), 1.0)}) |")
print(f"| tets | {int(ours_tets):,} | {int(tg_tets):,} | | |")
print()
EOF

if [[ "$OURS_TETS" != "$TG_TETS" || $SAME_TETS != yes ]]; then
    echo "bench: FAIL: the tets differ (tetcdt $OURS_TETS, TetGen $TG_TETS)" >&2
    exit 1
fi
