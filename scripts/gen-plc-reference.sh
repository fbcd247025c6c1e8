#!/usr/bin/env bash
# Regenerates data/plc/ref/: TetGen's plain CDT (`tetgen -pO0Q`) of the models in
# data/plc/ on which TetGen adds no Steiner points and whose mesh the independent
# validator accepts. tests/plc.rs checks that our tets are exactly TetGen's there
# (nodes matched by coordinates).
#
# For each model NAME.{off,poly,smesh,stl,ply} it runs, in a temporary directory,
#   tetgen -pO0Q NAME.ext
# and keeps NAME.1.node and NAME.1.ele as data/plc/ref/NAME.1.node / NAME.1.ele when
#   - TetGen exits 0 with a non-empty mesh,
#   - every output node is an input vertex (no Steiner points), and
#   - validate_mesh.py NAME.ext NAME.1 says VALID (TetGen's output is sometimes flawed:
#     shim tets, uncovered facets; there "the same as TetGen" would be wrong); for .stl
#     and .ply, which the referee does not read, `tetcdt --certify NAME.1 NAME.ext`.
# It also rewrites data/plc/ref/README.md with the verdict on every model.
# Idempotent: the same TetGen gives the same files, byte for byte.
#
# Needs: tetgen (Debian 1.5.0-5), python3 with numpy, and validate_mesh.py from the
# shared tools (../shared/tools relative to the repository, or $TETCDT_TOOLS).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PLC="$ROOT/data/plc"
REF="$PLC/ref"

VALIDATOR=""
for dir in "${TETCDT_TOOLS:-}" "$ROOT/../shared/tools" /work/shared/tools; do
    if [[ -n "$dir" && -f "$dir/validate_mesh.py" ]]; then
        VALIDATOR="$dir/validate_mesh.py"
        break
    fi
done
[[ -n "$VALIDATOR" ]] || { echo "error: validate_mesh.py not found (set TETCDT_TOOLS)" >&2; exit 1; }
command -v tetgen >/dev/null || { echo "error: tetgen not on PATH (apt-get install tetgen)" >&2; exit 1; }
TETCDT="${TETCDT:-$ROOT/target/release/tetcdt}"
[[ -x "$TETCDT" ]] || { echo "error: $TETCDT not built (cargo build --release)" >&2; exit 1; }
python3 -c 'import numpy' || { echo "error: python3 with numpy needed" >&2; exit 1; }
VERSION="$(dpkg-query -W -f='${Version}' tetgen 2>/dev/null || echo unknown)"

WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

mkdir -p "$REF"
rm -f "$REF"/*.node "$REF"/*.ele

# Counts the output nodes that are no input vertex (by coordinates): the Steiner points.
cat >"$WORK/steiner.py" <<'EOF'
import sys
def rows(path):
    out = []
    for line in open(path):
        line = line.split("#", 1)[0].split()
        if line:
            out.append(line)
    return out
def stl_vertices(path):
    import struct
    data = open(path, "rb").read()
    if len(data) >= 84 and 84 + 50 * struct.unpack_from("<I", data, 80)[0] == len(data):
        n = struct.unpack_from("<I", data, 80)[0]
        out = set()
        for k in range(n):
            for c in range(3):
                out.add(struct.unpack_from("<3f", data, 84 + 50 * k + 12 + 12 * c))
        return out
    return {tuple(float(c) for c in l.split()[1:4]) for l in data.decode().splitlines()
            if l.strip().startswith("vertex")}
def ply_vertices(path):
    lines = open(path).read().splitlines()
    n = next(int(l.split()[2]) for l in lines if l.startswith("element vertex"))
    start = lines.index("end_header") + 1
    return {tuple(float(c) for c in l.split()[:3]) for l in lines[start:start + n]}
def input_vertices(path):
    if path.endswith(".stl"):
        return stl_vertices(path)
    if path.endswith(".ply"):
        return ply_vertices(path)
    r = rows(path)
    if path.endswith(".off"):
        head = r[0]
        if head[0].upper().endswith("OFF"):
            counts, body = (head[1:], r[1:]) if len(head) > 1 else (r[1], r[2:])
        else:
            counts, body = head, r[1:]
        return {tuple(float(c) for c in x[:3]) for x in body[:int(counts[0])]}
    n = int(r[0][0])
    return {tuple(float(c) for c in x[1:4]) for x in r[1:1 + n]}
inp = input_vertices(sys.argv[1])
out = rows(sys.argv[2])
n = int(out[0][0])
print(sum(1 for x in out[1:1 + n] if tuple(float(c) for c in x[1:4]) not in inp))
EOF

TABLE=()
kept=0
for model in "$PLC"/*.off "$PLC"/*.poly "$PLC"/*.smesh "$PLC"/*.stl "$PLC"/*.ply; do
    [[ -f "$model" ]] || continue
    name="$(basename "$model")"
    stem="${name%.*}"
    d="$WORK/$stem"
    mkdir -p "$d"
    cp "$model" "$d/"
    set +e
    (cd "$d" && tetgen -pO0Q "$name" >"$d/tetgen.out" 2>&1)
    rc=$?
    set -e
    if [[ $rc != 0 || ! -s "$d/$stem.1.ele" ]]; then
        case $rc in
            134) why="TetGen aborts (exit 134)" ;;
            139) why="TetGen crashes (segmentation fault, exit 139)" ;;
            *) why="TetGen exits $rc" ;;
        esac
        TABLE+=("| \`$name\` | – | – | no: $why |")
        echo "$name: $why" >&2
        continue
    fi
    tets="$(awk 'NF && $1 !~ /^#/ { print $1; exit }' "$d/$stem.1.ele")"
    steiner="$(python3 "$WORK/steiner.py" "$d/$name" "$d/$stem.1.node")"
    case "$name" in
        # The referee reads neither; our own certifier judges those.
        *.stl|*.ply)
            if "$TETCDT" --certify "$d/$stem.1" "$d/$name" >/dev/null 2>&1; then
                verdict=VALID
            else
                verdict="INVALID (tetcdt --certify)"
            fi ;;
        *) verdict="$(python3 "$VALIDATOR" "$d/$name" "$d/$stem.1" 2>&1 | tail -n 1 || true)" ;;
    esac
    if [[ "$tets" == 0 ]]; then
        TABLE+=("| \`$name\` | $steiner | 0 | no: empty mesh |")
    elif [[ "$steiner" != 0 ]]; then
        TABLE+=("| \`$name\` | $steiner | $tets | no: TetGen adds Steiner points |")
    elif [[ "$verdict" != VALID ]]; then
        TABLE+=("| \`$name\` | 0 | $tets | no: TetGen's mesh is invalid ($verdict) |")
    else
        cp "$d/$stem.1.node" "$d/$stem.1.ele" "$REF/"
        TABLE+=("| \`$name\` | 0 | $tets | **yes** |")
        kept=$((kept + 1))
    fi
    echo "$name: steiner $steiner, tets $tets, $verdict" >&2
done

{
    cat <<EOF
# TetGen reference CDTs of the PLC test models

Everything in this directory except this README's prose is written by
\`scripts/gen-plc-reference.sh\`; do not edit the files by hand.

- TetGen $VERSION (Debian package \`tetgen\`), command \`tetgen -pO0Q NAME.ext\` run on a copy of
  \`data/plc/NAME.ext\` (\`-O0\`: no mesh optimization, so the output is TetGen's constrained
  Delaunay tetrahedralization itself).
- Kept: \`NAME.1.node\` and \`NAME.1.ele\`, unchanged, for the models where TetGen adds no Steiner
  point (every output node is an input vertex) and \`validate_mesh.py\` accepts TetGen's mesh.
  Without Steiner points the CDT is unique up to the symbolic perturbation, so
  \`tests/plc.rs\` requires our tets to be exactly these (nodes matched by coordinates).

| model | TetGen Steiner points | TetGen tets | reference kept |
|---|---:|---:|---|
EOF
    printf '%s\n' "${TABLE[@]}"
    echo
    echo "$kept references."
} >"$REF/README.md"
echo "wrote $kept references to $REF" >&2
