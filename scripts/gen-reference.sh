#!/usr/bin/env bash
# Regenerates the committed TetGen reference outputs in data/ref/ (used by
# tests/tetgen_diff.rs). Idempotent: every run deletes and rewrites the same files,
# byte for byte.
#
# For each reference set NAME it writes
#   data/ref/NAME.node     the input points (TetGen .node format)
#   data/ref/NAME.1.ele    TetGen's tets, from `tetgen -O0 NAME.node` (numbered like the input)
#   data/ref/NAME.1.face   TetGen's convex hull faces, from the same run
# TetGen's NAME.1.node is deleted: for a point set it holds exactly the input points.
#
# The sets (first index = number of the first point in the .node file):
#   rand1k            1,000 random points in the unit cube, gen_points.py seed 1, 1-based
#   rand10k           10,000 random points in the unit cube, gen_points.py seed 2, 1-based
#   grid3             3x3x3 integer grid (coords 0..2), x fastest, 1-based
#   grid4             4x4x4 integer grid (coords 0..3), x fastest, 0-based
#   grid4_shuffled    the grid4 points in a shuffled order (Python random seed 4), 1-based
#   grid543_shuffled  5x4x3 integer grid, shuffled (seed 5), 0-based
#   cube_center       the 8 corners of the cube [0,2]^3 and its center (1,1,1), 0-based
#   lattice300        300 distinct random points of the 8x8x8 integer lattice (seed 6), 1-based
# The grids and lattices are degenerate everywhere (many cospherical and coplanar
# points); TetGen resolves ties by a symbolic perturbation ordered by point index,
# so the shuffled sets exercise a perturbation order that differs from the geometry.
#
# Needs: tetgen (Debian 1.5.0), python3, and gen_points.py from the shared tools
# (../shared/tools relative to the repository, or $TETCDT_TOOLS).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
REF="$ROOT/data/ref"

find_tool() {
    local name="$1" dir
    for dir in "${TETCDT_TOOLS:-}" "$ROOT/tools" "$ROOT/../shared/tools" /work/shared/tools; do
        if [[ -n "$dir" && -f "$dir/$name" ]]; then
            echo "$dir/$name"
            return 0
        fi
    done
    echo "error: $name not found (set TETCDT_TOOLS to the shared tools directory)" >&2
    return 1
}

GEN_POINTS="$(find_tool gen_points.py)"
command -v tetgen >/dev/null || { echo "error: tetgen not on PATH (apt-get install tetgen)" >&2; exit 1; }

mkdir -p "$REF"
# Remove whatever a previous run wrote (but keep README.md).
rm -f "$REF"/*.node "$REF"/*.ele "$REF"/*.face "$REF"/*.edge "$REF"/*.neigh

echo "generating inputs in $REF"
python3 "$GEN_POINTS" 1000 "$REF/rand1k.node" 1
python3 "$GEN_POINTS" 10000 "$REF/rand10k.node" 2

python3 - "$REF" <<'EOF'
import random, sys
ref = sys.argv[1]

def grid(nx, ny, nz):
    return [(x, y, z) for z in range(nz) for y in range(ny) for x in range(nx)]

def write(name, pts, first):
    with open(f"{ref}/{name}.node", "w") as f:
        f.write(f"{len(pts)} 3 0 0\n")
        for i, (x, y, z) in enumerate(pts):
            f.write(f"{i + first} {x} {y} {z}\n")

def shuffled(pts, seed):
    pts = list(pts)
    random.Random(seed).shuffle(pts)
    return pts

write("grid3", grid(3, 3, 3), 1)
write("grid4", grid(4, 4, 4), 0)
write("grid4_shuffled", shuffled(grid(4, 4, 4), 4), 1)
write("grid543_shuffled", shuffled(grid(5, 4, 3), 5), 0)
write("cube_center", [(2 * x, 2 * y, 2 * z) for (x, y, z) in grid(2, 2, 2)] + [(1, 1, 1)], 0)
write("lattice300", random.Random(6).sample(grid(8, 8, 8), 300), 1)
EOF

for node in "$REF"/*.node; do
    name="$(basename "$node" .node)"
    echo "tetgen -O0 $name.node"
    (cd "$REF" && tetgen -QO0 "$name.node")
    # For a point set TetGen's output nodes are the input points; check, then drop them.
    python3 - "$REF/$name.node" "$REF/$name.1.node" "$REF/$name.1.ele" <<'EOF'
import sys
def rows(path):
    with open(path) as f:
        lines = [l.split("#", 1)[0].split() for l in f]
    lines = [l for l in lines if l]
    n = int(lines[0][0])
    return lines[0], lines[1:1 + n]
_, a = rows(sys.argv[1])
_, b = rows(sys.argv[2])
if [r[0] for r in a] != [r[0] for r in b] or any(
        [float(v) for v in ra[1:4]] != [float(v) for v in rb[1:4]] for ra, rb in zip(a, b)):
    sys.exit(f"error: {sys.argv[2]} differs from the input points")
head, tets = rows(sys.argv[3])
first = int(a[0][0])
if int(tets[0][0]) != first:
    sys.exit(f"error: {sys.argv[3]} numbering does not start at {first}")
used = {int(v) for t in tets for v in t[1:5]}
if used != {int(r[0]) for r in a}:
    sys.exit(f"error: {sys.argv[3]} does not use every input point exactly")
print(f"  {len(a)} points (first index {first}), {len(tets)} tets")
EOF
    rm -f "$REF/$name.1.node"
done

echo "sizes:"
du -ch "$REF"/*.node "$REF"/*.ele "$REF"/*.face | tail -n 1
ls -l "$REF"
