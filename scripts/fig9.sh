#!/usr/bin/env bash
# Reproduces Figure 9 of Si & Shewchuk: the time to insert one rectangle into the Delaunay
# tetrahedralization of random points near its plane, against the number of crossing tets
# deleted, for our cavity (-C) and flip (-F) insertion and TetGen's (-pcO0 and -pcLO0).
#
# usage: scripts/fig9.sh [OUTDIR]        (default OUTDIR: fig9/ in the repository)
#
# Environment: SIZES (point counts, default 100 ... 40000), SEED (default 1), REPEAT (runs
# per size of ours and of TetGen's, the fastest kept; default 3), TETGEN_TIMEOUT (seconds per TetGen run,
# default 300), TETGEN_L_MAX (largest point count for TetGen's flips, which are far
# slower; default 30000), TETCDT_TOOLS (directory of gen_fig9.py, default ../shared/tools).
#
# Inputs come from gen_fig9.py (points in [-1,1]^2 x [-0.1,0.1], the rectangle
# [-2,2]^2 x {0}); meshes keep the hull (-c) since one rectangle encloses no volume.
# Times: ours are `facet_secs` from --stats-json (facet recovery; like TetGen, without the
# facets' 2D triangulation, which both report apart), TetGen's its -V line
# "Facet recovery seconds". Crossing tets: ours (the tets of the initial Delaunay
# tetrahedralization crossing the rectangle, the same for both of our algorithms).
# Writes OUTDIR/fig9.csv, then runs scripts/fig9.py for OUTDIR/fig9.png and OUTDIR/summary.txt.
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-$ROOT/fig9}"
SIZES="${SIZES:-100 150 200 300 400 500 700 1000 1500 2000 3000 5000 7000 10000 15000 20000 30000 40000}"
SEED="${SEED:-1}"
REPEAT="${REPEAT:-3}"
TETGEN_TIMEOUT="${TETGEN_TIMEOUT:-300}"
TETGEN_L_MAX="${TETGEN_L_MAX:-30000}"
GEN=""
for dir in "${TETCDT_TOOLS:-}" "$ROOT/../shared/tools" /work/shared/tools; do
    if [[ -n "$dir" && -f "$dir/gen_fig9.py" ]]; then
        GEN="$dir/gen_fig9.py"
        break
    fi
done
[[ -n "$GEN" ]] || { echo "fig9.sh: gen_fig9.py not found (set TETCDT_TOOLS)" >&2; exit 2; }
(cd "$ROOT" && cargo build --release --quiet) || { echo "fig9.sh: build failed" >&2; exit 2; }
TETCDT="$ROOT/target/release/tetcdt"
HAVE_TETGEN=0
command -v tetgen >/dev/null 2>&1 && HAVE_TETGEN=1
[[ $HAVE_TETGEN == 1 ]] || echo "fig9.sh: tetgen not installed: its columns stay empty" >&2

mkdir -p "$OUT"
WORK="$(mktemp -d "${TMPDIR:-/tmp}/tetcdt-fig9.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT
CSV="$OUT/fig9.csv"
echo "points,crossing_tets,cavity_secs,cavity_status,flip_secs,flip_status,flips,flip_fallbacks,tetgen_cavity_secs,tetgen_flip_secs" >"$CSV"

# A field of a --stats-json file.
field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get(sys.argv[2], ''))" "$1" "$2"; }

# Runs ours REPEAT times with switch $1; sets SECS (fastest facet_secs) and STATUS.
ours() {
    SECS=""
    STATUS=ok
    for ((r = 0; r < REPEAT; r++)); do
        if ! "$TETCDT" "-pcQ$1" --stats-json "$WORK/s$1.json" -o "$WORK/o$1" "$WORK/in.poly" \
            2>"$WORK/err$1"; then
            STATUS="failed: $(tr ',\n' ';  ' <"$WORK/err$1")"
            SECS=""
            return
        fi
        local s
        s=$(field "$WORK/s$1.json" facet_secs)
        if [[ -z "$SECS" ]] || python3 -c "import sys; sys.exit(0 if $s < $SECS else 1)"; then
            SECS=$s
        fi
    done
}

# TetGen's facet recovery time with switches $1 (the fastest of REPEAT runs, as for ours;
# one run once a run takes over a second, where the noise is small against it), or empty.
tetgen_secs() {
    [[ $HAVE_TETGEN == 1 ]] || return
    local best="" s
    for ((r = 0; r < REPEAT; r++)); do
        s=$( (cd "$WORK" && timeout "$TETGEN_TIMEOUT" tetgen "$1" in.poly 2>/dev/null) |
            sed -n 's/^ *Facet recovery seconds: *//p' | head -1)
        [[ -n "$s" ]] || break
        if [[ -z "$best" ]] || python3 -c "import sys; sys.exit(0 if $s < $best else 1)"; then
            best=$s
        fi
        python3 -c "import sys; sys.exit(0 if $s > 1 else 1)" && break
    done
    echo "$best"
}

for n in $SIZES; do
    python3 "$GEN" "$n" "$WORK/in.poly" "$SEED" >/dev/null
    ours C
    c_secs=$SECS c_status=$STATUS
    ours F
    f_secs=$SECS f_status=$STATUS
    crossing="" flips="" fallbacks=""
    if [[ $f_status == ok ]]; then
        crossing=$(field "$WORK/sF.json" crossing_tets)
        flips=$(field "$WORK/sF.json" flips)
        fallbacks=$(field "$WORK/sF.json" flip_fallbacks)
    elif [[ $c_status == ok ]]; then
        crossing=$(field "$WORK/sC.json" crossing_tets)
    fi
    tc=$(tetgen_secs -pcO0V)
    tl=""
    ((n <= TETGEN_L_MAX)) && tl=$(tetgen_secs -pcLO0V)
    echo "$n,$crossing,$c_secs,$c_status,$f_secs,$f_status,$flips,$fallbacks,$tc,$tl" >>"$CSV"
    echo "n=$n crossing=$crossing -C=${c_secs:-$c_status} -F=${f_secs:-$f_status} tetgen=$tc tetgen-L=$tl" >&2
done
python3 "$ROOT/scripts/fig9.py" "$CSV" "$OUT/fig9.png" | tee "$OUT/summary.txt"
# fig9.py exits 1 when one of our runs failed: so does this script.
exit "${PIPESTATUS[0]}"
