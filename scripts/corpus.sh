#!/usr/bin/env bash
# Meshes the shared PLC corpus with `tetcdt -pQ` and compares with TetGen's plain CDT.
#
# usage: scripts/corpus.sh [--all] [--keep] [--no-build] [--no-tetgen] [PATTERN...]
#
#   --all        also mesh tetgen_stp/ (large CAD parts; skipped by default)
#   --keep       keep the work directory (printed on stderr) instead of deleting it
#   --no-build   do not run `cargo build --release` first
#   --no-tetgen  do not run TetGen even if installed: use tetgen_p_O0.tsv's figures
#   --no-flip    do not run facet insertion by flips (-F) for the -F column
#   PATTERN      only models whose corpus path contains one of the patterns
#
# Environment: CORPUS (default ../shared/corpus relative to the repository: the directory
# holding files/ and tetgen_p_O0.tsv; a files/ directory itself is accepted too),
# TETCDT (the binary, default target/release/tetcdt), TETCDT_TOOLS (the directory of
# validate_mesh.py, default ../shared/tools), TIMEOUT (seconds per run, default 300),
# REPEAT (runs of each timed command, TetGen's and ours alike, the fastest kept, the two
# programs taking turns: the machine's noise is about 10% from run to run; default 3).
#
# Models: every file under $CORPUS/files that TetGen meshes with -pO0 according to
# tetgen_p_O0.tsv (rc 0). For each, in a temporary work directory:
#   - `timeout 300 tetcdt -pQ -o ours INPUT`, timed;
#   - `validate_mesh.py INPUT ours` (for inputs the validator cannot read, .stl .ply .obj,
#     `tetcdt --certify` instead);
#   - `timeout 300 tetgen -pO0Q INPUT` if tetgen is installed (else the tsv's time, node
#     and tet counts);
#   - Steiner points: output nodes whose coordinates are no input vertex (this is the
#     output node count minus the input's distinct vertex count when every input vertex
#     is kept); the tsv fallback uses the node count minus the distinct vertex count;
#   - where neither mesh has Steiner points, the two tet sets are compared exactly, nodes
#     mapped by coordinates; when they differ, TetGen's own mesh is validated too. An STL
#     file repeats every corner, and TetGen numbers each welded point as the copy it
#     happened to keep (its insertion order decides), which changes how the symbolic
#     perturbation breaks ties among cospherical points. When an STL mesh differs, the
#     model is written again as a .smesh with TetGen's output numbering, meshed, and
#     compared: identical then counts as identical, with a note.
#   - the -F column: `tetcdt -pQF`, timed and validated the same way, its Steiner points,
#     whether its tets equal -C's (where neither adds Steiner points) and how many regions
#     fell back from flips to cavity retriangulation (from --stats-json).
# Where TetGen's mesh is empty (an open surface: everything carved away) we must exit 3.
# Formats tetcdt does not read (exit 3, "unknown input format") get a row saying so.
#
# Prints a markdown table and a summary on stdout (progress on stderr). Exits 1 if any
# supported model fails with -C or -F: an invalid mesh, refused, crashed, timed out, or a
# wrong exit code on an open surface; if -F and -C differ where neither adds Steiner
# points; or if our tets differ from TetGen's where neither adds Steiner points and
# TetGen's own mesh is valid.
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ALL=0
KEEP=0
BUILD=1
USE_TETGEN=1
USE_FLIP=1
PATTERNS=()
for arg in "$@"; do
    case "$arg" in
        --all) ALL=1 ;;
        --keep) KEEP=1 ;;
        --no-build) BUILD=0 ;;
        --no-tetgen) USE_TETGEN=0 ;;
        --no-flip) USE_FLIP=0 ;;
        -h|--help) sed -n '2,/^set -uo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        -*) echo "corpus.sh: unknown option $arg" >&2; exit 2 ;;
        *) PATTERNS+=("$arg") ;;
    esac
done

CORPUS="${CORPUS:-$ROOT/../shared/corpus}"
if [[ -d "$CORPUS/files" ]]; then
    FILES="$CORPUS/files"
elif [[ "$(basename "$CORPUS")" == files && -d "$CORPUS" ]]; then
    FILES="$CORPUS"
    CORPUS="$(dirname "$CORPUS")"
else
    echo "corpus.sh: no corpus at $CORPUS (set CORPUS=/path/to/corpus)" >&2
    exit 2
fi
CORPUS="$(cd "$CORPUS" && pwd)"
FILES="$(cd "$FILES" && pwd)"
TSV="$CORPUS/tetgen_p_O0.tsv"
[[ -f "$TSV" ]] || { echo "corpus.sh: $TSV not found" >&2; exit 2; }

VALIDATOR=""
for dir in "${TETCDT_TOOLS:-}" "$ROOT/../shared/tools" "$CORPUS/../tools"; do
    if [[ -n "$dir" && -f "$dir/validate_mesh.py" ]]; then
        VALIDATOR="$(cd "$dir" && pwd)/validate_mesh.py"
        break
    fi
done
if [[ -z "$VALIDATOR" ]] || ! python3 -c 'import numpy' 2>/dev/null; then
    echo "corpus.sh: needs python3 with numpy and validate_mesh.py (set TETCDT_TOOLS)" >&2
    exit 2
fi

if [[ -n "${TETCDT:-}" ]]; then
    BUILD=0 # a binary given by the caller is used as it is
else
    TETCDT="$ROOT/target/release/tetcdt"
fi
if [[ $BUILD == 1 ]]; then
    echo "building: cargo build --release" >&2
    if ! (cd "$ROOT" && cargo build --release --quiet) >&2; then
        echo "corpus.sh: warning: cargo build --release failed; using the existing binary" >&2
    fi
fi
[[ -x "$TETCDT" ]] || { echo "corpus.sh: $TETCDT not found (cargo build --release)" >&2; exit 2; }
TETCDT="$(cd "$(dirname "$TETCDT")" && pwd)/$(basename "$TETCDT")"
TIMEOUT="${TIMEOUT:-300}"
HAVE_TETGEN=0
[[ $USE_TETGEN == 1 ]] && command -v tetgen >/dev/null 2>&1 && HAVE_TETGEN=1

WORK="$(mktemp -d "${TMPDIR:-/tmp}/tetcdt-corpus.XXXXXX")"
if [[ $KEEP == 1 ]]; then
    echo "work directory: $WORK" >&2
else
    trap 'rm -rf "$WORK"' EXIT
fi

# ---------------------------------------------------------------------------------------
# The helper: input vertices, Steiner counts, tet-set comparison by coordinates.
HELPER="$WORK/helper.py"
echo "SCRIPTS = '$ROOT/scripts'" >"$HELPER"
cat >>"$HELPER" <<'EOF'
import sys
sys.path.insert(0, SCRIPTS)
from stl_tetgen_numbering import corners as stl_corners

def lines_of(path):
    out = []
    with open(path, errors="replace") as f:
        for line in f:
            line = line.split("#", 1)[0].split()
            if line:
                out.append(line)
    return out

def read_node_file(path):
    rows = lines_of(path)
    if not rows:
        return []
    n = int(rows[0][0])
    return [tuple(float(c) for c in r[1:4]) for r in rows[1:1 + n]]

def input_vertices(path):
    ext = path.rsplit(".", 1)[-1].lower()
    if ext in ("node", "poly", "smesh"):
        pts = read_node_file(path)
        if not pts and ext != "node":
            pts = read_node_file(path.rsplit(".", 1)[0] + ".node")
        return pts
    if ext == "off":
        rows = lines_of(path)
        head = rows[0]
        if head[0].upper().endswith("OFF"):
            counts, body = (head[1:], rows[1:]) if len(head) > 1 else (rows[1], rows[2:])
        else:
            counts, body = head, rows[1:]
        return [tuple(float(c) for c in r[:3]) for r in body[:int(counts[0])]]
    if ext == "mesh":
        words = [w for r in lines_of(path) for w in r]
        for i, w in enumerate(words):
            if w.lower() == "vertices":
                n = int(words[i + 1])
                return [tuple(float(c) for c in words[i + 2 + 4 * j: i + 5 + 4 * j]) for j in range(n)]
        return []
    if ext == "stl":
        return stl_corners(path)
    if ext == "ply":
        with open(path, "rb") as f:
            data = f.read()
        head_end = data.index(b"end_header")
        head = data[:head_end].decode(errors="replace").split("\n")
        if not any(l.startswith("format ascii") for l in head):
            return None
        nv = next(int(l.split()[2]) for l in head if l.startswith("element vertex"))
        body = data[head_end:].decode(errors="replace").split("\n")[1:]
        rows = [l.split() for l in body if l.strip()]
        return [tuple(float(c) for c in r[:3]) for r in rows[:nv]]
    if ext == "obj":
        return [tuple(float(c) for c in r[1:4]) for r in lines_of(path) if r[0] == "v"]
    return None

def read_mesh(prefix):
    """(points, tets) of PREFIX.node/.ele, or None when absent."""
    try:
        pts_rows = lines_of(prefix + ".node")
        ele_rows = lines_of(prefix + ".ele")
    except OSError:
        return None
    n = int(pts_rows[0][0]) if pts_rows else 0
    rows = pts_rows[1:1 + n]
    base = int(rows[0][0]) if rows else 0
    pts = [tuple(float(c) for c in r[1:4]) for r in rows]
    m = int(ele_rows[0][0]) if ele_rows else 0
    tets = [tuple(int(v) - base for v in r[1:5]) for r in ele_rows[1:1 + m]]
    return pts, tets

def main():
    inp, ours, tg = sys.argv[1:4]
    verts = input_vertices(inp)
    distinct = set(verts) if verts is not None else None
    out = {"distinct": len(distinct) if distinct is not None else ""}
    meshes = {}
    for key, prefix in (("ours", ours), ("tg", tg)):
        m = read_mesh(prefix) if prefix != "-" else None
        meshes[key] = m
        if m is None:
            out[key + "_nodes"] = out[key + "_tets"] = out[key + "_steiner"] = ""
            continue
        pts, tets = m
        out[key + "_nodes"] = len(pts)
        out[key + "_tets"] = len(tets)
        out[key + "_steiner"] = sum(1 for p in pts if p not in distinct) if distinct is not None else ""
    ident, note = "n.a.", ""
    if (meshes["ours"] and meshes["tg"] and out["ours_steiner"] == 0 and out["tg_steiner"] == 0
            and out["ours_tets"] and out["tg_tets"]):
        keys = []
        for pts, tets in (meshes["ours"], meshes["tg"]):
            keys.append({frozenset(pts[v] for v in t) for t in tets})
        ident = "yes" if keys[0] == keys[1] else "no"
        if ident == "no":
            note = f"{len(keys[0] - keys[1])} of our tets not in TetGen's, {len(keys[1] - keys[0])} of TetGen's not in ours"
    out["identical"] = ident
    out["note"] = note
    print("\x1f".join(str(out[k]) for k in ("distinct", "ours_nodes", "ours_tets", "ours_steiner",
                                           "tg_nodes", "tg_tets", "tg_steiner", "identical", "note")))

main()
EOF

# ---------------------------------------------------------------------------------------
# The model list: TetGen -pO0 rc 0 in the tsv.
declare -A TSV_RC TSV_TIME TSV_NODES TSV_TETS
# (tab is whitespace to `read`, which would merge empty fields: split on \x1f instead)
while IFS=$'\x1f' read -r file mode rc wall nodes tets _; do
    [[ "$mode" == "-pO0" ]] || continue
    TSV_RC["$file"]="$rc"
    TSV_TIME["$file"]="$wall"
    TSV_NODES["$file"]="$nodes"
    TSV_TETS["$file"]="$tets"
done < <(tail -n +2 "$TSV" | tr '\t' '\037')

MODELS=()
SKIPPED_NO_TSV=()
while IFS= read -r rel; do
    [[ "$rel" == tetgen_stp/* && $ALL == 0 ]] && continue
    if [[ ${#PATTERNS[@]} -gt 0 ]]; then
        hit=0
        for p in "${PATTERNS[@]}"; do [[ "$rel" == *"$p"* ]] && hit=1; done
        [[ $hit == 1 ]] || continue
    fi
    if [[ -z "${TSV_RC[$rel]+x}" ]]; then
        SKIPPED_NO_TSV+=("$rel")
        continue
    fi
    [[ "${TSV_RC[$rel]}" == 0 ]] && MODELS+=("$rel")
done < <(cd "$FILES" && find . -type f | sed 's|^\./||' | LC_ALL=C sort)

# Inputs the validator reads.
validator_reads() {
    case "${1,,}" in *.off|*.poly|*.smesh|*.mesh|*.node) return 0 ;; *) return 1 ;; esac
}

# A one-line, table-safe version of a message.
oneline() {
    tr '\n' ' ' | sed 's/|/\\|/g; s/  */ /g; s/^ //; s/ $//' | cut -c1-300
}

elapsed() { # start end -> seconds with 3 decimals
    awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", b - a }'
}

REPEAT="${REPEAT:-3}"
# Runs a command once; sets ONCE_RC to its exit code and ONCE_TIME to its seconds.
run_once() {
    local t0 t1
    t0=$EPOCHREALTIME
    "$@"
    ONCE_RC=$?
    t1=$EPOCHREALTIME
    ONCE_TIME="$(elapsed "$t0" "$t1")"
}

# The smaller of two times, either of which may be empty (none yet).
fastest() {
    if [[ -z "$2" ]] || awk -v a="$1" -v b="$2" 'BEGIN { exit !(a < b) }'; then
        echo "$1"
    else
        echo "$2"
    fi
}

# A timeout or a crash is not repeated (a refusal is: it is the answer).
ends_runs() {
    [[ $1 == 124 || $1 -gt 128 ]]
}

# Runs a command REPEAT times (output redirections inside it apply to every run); sets
# RUN_RC to the last run's exit code and RUN_TIME to the fastest run's seconds.
timed() {
    local k best=""
    for ((k = 0; k < REPEAT; k++)); do
        run_once "$@"
        RUN_RC=$ONCE_RC
        best="$(fastest "$ONCE_TIME" "$best")"
        ends_runs "$RUN_RC" && break
    done
    RUN_TIME="$best"
}

# Runs two commands REPEAT times each, taking turns (the machine's speed drifts over
# seconds: turns keep a slow spell from falling on one of them only); sets RUN_RC and
# RUN_TIME for the first as `timed` does, and RUN_RC2 and RUN_TIME2 for the second.
timed_pair() {
    local k b1="" b2="" stop1=0 stop2=0
    for ((k = 0; k < REPEAT; k++)); do
        if [[ $stop1 == 0 ]]; then
            run_once "$1"
            RUN_RC=$ONCE_RC
            b1="$(fastest "$ONCE_TIME" "$b1")"
            ends_runs "$RUN_RC" && stop1=1
        fi
        if [[ $stop2 == 0 ]]; then
            run_once "$2"
            RUN_RC2=$ONCE_RC
            b2="$(fastest "$ONCE_TIME" "$b2")"
            ends_runs "$RUN_RC2" && stop2=1
        fi
    done
    RUN_TIME="$b1"
    RUN_TIME2="$b2"
}

ROWS=()
FAILURES=()
DIFFERENCES=()
UNEXPLAINED=()
RENUMBERED=()
n_supported=0 n_valid=0 n_unsupported=0 n_open=0
n_ident_cases=0 n_ident=0
sum_st_ours=0 sum_st_tg=0 sum_t_ours=0 sum_t_tg=0 n_both=0
UNSUPPORTED_LIST=()
MORE_STEINER=()

n_flip=0 n_flip_valid=0 n_flip_ident_cases=0 n_flip_ident=0 n_flip_fallbacks=0 sum_t_flip=0
sum_t_cav=0
FLIP_PROBLEMS=()

# Sets FCOL, the -F column of the current model: Steiner points, valid, equal to -C,
# fallbacks, time.
flip_column() {
    FCOL="–"
    [[ $USE_FLIP == 1 ]] || return 0
    n_flip=$((n_flip + 1))
    local frc ftime fst fval fident fb vrc
    run_flip() {
        timeout "$TIMEOUT" "$TETCDT" -pQF --stats-json "$dir/flip.json" -o "$dir/flip" \
            "$input" >"$dir/flip.out" 2>"$dir/flip.err"
    }
    timed run_flip
    frc=$RUN_RC
    ftime=$RUN_TIME
    if [[ $frc != 0 ]]; then
        FCOL="**failed** (exit $frc) / $ftime"
        FLIP_PROBLEMS+=("$rel: \`tetcdt -pQF\` exit $frc: $(oneline <"$dir/flip.err")")
        return 0
    fi
    sum_t_flip="$(awk -v a="$sum_t_flip" -v b="$ftime" 'BEGIN { printf "%.3f", a + b }')"
    sum_t_cav="$(awk -v a="$sum_t_cav" -v b="$our_time" 'BEGIN { printf "%.3f", a + b }')"
    if validator_reads "$name"; then
        python3 "$VALIDATOR" "$input" "$dir/flip" >"$dir/validate_flip.out" 2>&1
    else
        "$TETCDT" --certify "$dir/flip" "$input" >"$dir/validate_flip.out" 2>&1
    fi
    vrc=$?
    if [[ $vrc == 0 ]]; then
        fval=valid
        n_flip_valid=$((n_flip_valid + 1))
    else
        fval="**INVALID**"
        FLIP_PROBLEMS+=("$rel: \`tetcdt -pQF\` gives an invalid mesh: $(tail -n 1 "$dir/validate_flip.out" | oneline)")
    fi
    local fstats
    fstats="$(python3 "$HELPER" "$input" "$dir/ours" "$dir/flip" 2>/dev/null)"
    IFS=$'\x1f' read -r _ _ _ _ _ _ fst fident _ <<<"$fstats"
    case "$fident" in
        yes) n_flip_ident_cases=$((n_flip_ident_cases + 1)); n_flip_ident=$((n_flip_ident + 1)); fident="= -C" ;;
        no) n_flip_ident_cases=$((n_flip_ident_cases + 1)); fident="**≠ -C**"
            FLIP_PROBLEMS+=("$rel: -F and -C add no Steiner points but their tets differ") ;;
        *) fident="n.a." ;;
    esac
    fb="$(python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get('flip_fallbacks', '?'))" "$dir/flip.json" 2>/dev/null)"
    [[ "$fb" =~ ^[0-9]+$ ]] && n_flip_fallbacks=$((n_flip_fallbacks + fb))
    FCOL="${fst:-?} / $fval / $fident / ${fb:-?} / $ftime"
}

# Sets distinct o_nodes o_tets o_st tg_nodes tg_tets tg_st ident note for the current
# model, given our output prefix (or - for none); TetGen's figures from the tsv when it
# was not run.
model_stats() {
    local stats
    stats="$(python3 "$HELPER" "$input" "$1" "$tg_prefix" 2>"$dir/helper.err")" ||
        stats=$'\x1f\x1f\x1f\x1f\x1f\x1f\x1fn.a.\x1fhelper failed: '"$(oneline <"$dir/helper.err")"
    IFS=$'\x1f' read -r distinct o_nodes o_tets o_st tg_nodes tg_tets tg_st ident note <<<"$stats"
    if [[ "$tg_prefix" == "-" && $HAVE_TETGEN == 0 ]]; then
        tg_tets="${TSV_TETS[$rel]}"
        tg_st=""
        [[ -n "$distinct" && -n "${TSV_NODES[$rel]}" && "${TSV_NODES[$rel]}" != 0 ]] &&
            tg_st=$(( TSV_NODES[$rel] - distinct ))
    fi
    return 0
}

i=0
for rel in "${MODELS[@]}"; do
    i=$((i + 1))
    name="$(basename "$rel")"
    stem="${name%.*}"
    ext="${name##*.}"
    dir="$WORK/$i"
    mkdir -p "$dir"
    # the input, and a separate .node it may refer to
    cp "$FILES/$rel" "$dir/"
    src_dir="$(dirname "$FILES/$rel")"
    if [[ "$ext" == poly || "$ext" == smesh ]] && [[ -f "$src_dir/$stem.node" ]]; then
        cp "$src_dir/$stem.node" "$dir/"
    fi
    input="$dir/$name"
    echo "[$i/${#MODELS[@]}] $rel" >&2

    empty_expected=0
    [[ "${TSV_NODES[$rel]}" == 0 ]] && empty_expected=1

    # --- TetGen
    tg_prefix="-"
    tg_time="${TSV_TIME[$rel]}"
    tg_note=""
    run_ours() {
        timeout "$TIMEOUT" "$TETCDT" -pQ -o "$dir/ours" "$input" >"$dir/ours.out" 2>"$dir/ours.err"
    }
    if [[ $HAVE_TETGEN == 1 ]]; then
        run_tetgen() {
            (cd "$dir" && timeout "$TIMEOUT" tetgen -pO0Q "$name" >"$dir/tetgen.out" 2>&1)
        }
        # Timed in turns with ours (see `timed_pair`).
        timed_pair run_tetgen run_ours
        tg_rc=$RUN_RC
        tg_time=$RUN_TIME
        rc=$RUN_RC2
        our_time=$RUN_TIME2
        if [[ $tg_rc == 0 && -f "$dir/$stem.1.node" && -f "$dir/$stem.1.ele" ]]; then
            tg_prefix="$dir/$stem.1"
            tg_tets_now="$(awk 'NF && $1 !~ /^#/ { print $1; exit }' "$dir/$stem.1.ele")"
            [[ "$tg_tets_now" == 0 ]] && empty_expected=1 || empty_expected=0
        else
            tg_note="TetGen rc $tg_rc now (tsv: 0)"
        fi
    fi

    # --- ours (already run in turns with TetGen when it is installed)
    if [[ $HAVE_TETGEN != 1 ]]; then
        timed run_ours
        rc=$RUN_RC
        our_time=$RUN_TIME
    fi
    msg="$(oneline <"$dir/ours.err")"
    cmd="tetcdt -pQ $rel"

    if [[ $rc == 3 ]] && grep -qi 'unknown input format' "$dir/ours.err"; then
        n_unsupported=$((n_unsupported + 1))
        UNSUPPORTED_LIST+=("$rel")
        model_stats -
        [[ $empty_expected == 1 ]] && tg_tets="0 (open surface)" tg_st="–"
        ROWS+=("| $rel | unsupported format (.$ext) | – / ${tg_st:-?} | – / ${tg_tets:-?} | n.a. | – / $tg_time | – |")
        continue
    fi
    n_supported=$((n_supported + 1))

    if [[ $empty_expected == 1 ]]; then
        n_open=$((n_open + 1))
        if [[ $rc == 3 ]]; then
            n_valid=$((n_valid + 1))
            valid="yes (exit 3: open surface, as TetGen's empty mesh)"
        else
            valid="**NO**: exit $rc, expected 3 (TetGen's mesh is empty)"
            FAILURES+=("$rel: \`$cmd\` exited $rc, expected 3 (open surface: TetGen's mesh is empty). ${msg:+stderr: $msg}")
        fi
        ROWS+=("| $rel | $valid | – / – | – / 0 | n.a. | $our_time / $tg_time | – |")
        continue
    fi

    if [[ $rc != 0 ]]; then
        case $rc in
            124) what="timed out after ${TIMEOUT}s" ;;
            1) what="meshing failed (exit 1)" ;;
            2) what="usage error (exit 2)" ;;
            3) what="refused as invalid input (exit 3)" ;;
            4) what="I/O error (exit 4)" ;;
            *) if (( rc > 128 )); then what="crashed (signal $((rc - 128)))"; else what="exit $rc"; fi ;;
        esac
        FAILURES+=("$rel: \`$cmd\` $what. ${msg:+stderr: $msg}")
        model_stats -
        flip_column
        ROWS+=("| $rel | **NO**: $what: ${msg:-no message} | – / ${tg_st:-?} | – / ${tg_tets:-?} | n.a. | $our_time / $tg_time | $FCOL |")
        continue
    fi

    # --- validity
    if validator_reads "$name"; then
        python3 "$VALIDATOR" "$input" "$dir/ours" >"$dir/validate.out" 2>&1
        vrc=$?
        verdict="$(tail -n 1 "$dir/validate.out" | oneline)"
        vcmd="validate_mesh.py $rel OUT"
    else
        "$TETCDT" --certify "$dir/ours" "$input" >"$dir/validate.out" 2>&1
        vrc=$?
        verdict="$(oneline <"$dir/validate.out")"
        vcmd="tetcdt --certify OUT $rel (the validator does not read .$ext)"
    fi
    if [[ $vrc == 0 ]]; then
        n_valid=$((n_valid + 1))
        valid="yes"
        validator_reads "$name" || valid="yes (--certify)"
    else
        valid="**NO**: ${verdict:-validator exit $vrc}"
        FAILURES+=("$rel: \`$cmd\` gives an invalid mesh: \`$vcmd\`: ${verdict:-exit $vrc}")
    fi

    # --- statistics and identity
    model_stats "$dir/ours"
    if [[ "$ident" == yes || "$ident" == no ]]; then
        n_ident_cases=$((n_ident_cases + 1))
        renumbered=0
        if [[ "$ident" == no && "$ext" == stl ]] &&
            python3 "$ROOT/scripts/stl_tetgen_numbering.py" "$input" "$tg_prefix.node" \
                "$dir/tg_numbering.smesh" 2>/dev/null &&
            "$TETCDT" -pQ -o "$dir/renumbered" "$dir/tg_numbering.smesh" >/dev/null 2>&1; then
            # The same PLC with TetGen's numbering of the welded points: the same tets?
            rstats="$(python3 "$HELPER" "$dir/tg_numbering.smesh" "$dir/renumbered" "$tg_prefix" 2>/dev/null)"
            IFS=$'\x1f' read -r _ _ _ _ _ _ _ rident _ <<<"$rstats"
            if [[ "$rident" == yes ]]; then
                renumbered=1
                ident="yes, with TetGen's numbering of the STL's points (with the file's order: $note)"
                RENUMBERED+=("$rel")
            fi
        fi
        if [[ "$ident" == yes || $renumbered == 1 ]]; then
            n_ident=$((n_ident + 1))
        else
            # Is TetGen's own mesh valid? If not, the difference is TetGen's flaw.
            tgv="not validated"
            if validator_reads "$name"; then
                python3 "$VALIDATOR" "$input" "$tg_prefix" >"$dir/validate_tg.out" 2>&1
                tgv="$(tail -n 1 "$dir/validate_tg.out" | oneline)"
            fi
            ident="no ($note; TetGen's mesh: $tgv)"
            DIFFERENCES+=("$rel: neither adds Steiner points but the tets differ: $note. TetGen's own mesh per the validator: $tgv")
            # A difference is explained only where TetGen's own mesh is no CDT.
            [[ "$tgv" == INVALID* ]] || UNEXPLAINED+=("$rel")
        fi
    fi
    if [[ -n "$o_st" && -n "$tg_st" && "$o_st" =~ ^[0-9]+$ && "$tg_st" =~ ^-?[0-9]+$ ]]; then
        sum_st_ours=$((sum_st_ours + o_st))
        sum_st_tg=$((sum_st_tg + tg_st))
        (( o_st > 0 && tg_st == 0 )) && MORE_STEINER+=("$rel ($o_st)")
    fi
    if [[ -n "$tg_time" && ( $HAVE_TETGEN == 0 || "$tg_prefix" != "-" ) ]]; then
        sum_t_ours="$(awk -v a="$sum_t_ours" -v b="$our_time" 'BEGIN { printf "%.3f", a + b }')"
        sum_t_tg="$(awk -v a="$sum_t_tg" -v b="$tg_time" 'BEGIN { printf "%.3f", a + b }')"
        n_both=$((n_both + 1))
    fi
    [[ -n "$tg_note" ]] && ident="$ident ($tg_note)"
    flip_column
    ROWS+=("| $rel | $valid | ${o_st:-?} / ${tg_st:-?} | ${o_tets:-?} / ${tg_tets:-?} | $ident | $our_time / $tg_time | $FCOL |")
done

# ---------------------------------------------------------------------------------------
src="TetGen 1.5 run now (\`tetgen -pO0Q\`)"
if [[ $HAVE_TETGEN == 0 ]]; then
    src="TetGen not run: TetGen's figures from tetgen_p_O0.tsv"
    [[ $USE_TETGEN == 1 ]] && src="TetGen not installed: TetGen's figures from tetgen_p_O0.tsv"
fi
echo "## tetcdt -pQ on the corpus ($(date -u +%Y-%m-%d), $src)"
echo
echo "| model | ours valid? | Steiner (ours / TetGen) | tets (ours / TetGen) | identical to TetGen | time ours / TetGen (s) | -F: Steiner / valid / vs -C / fallbacks / time (s) |"
echo "|---|---|---|---|---|---|---|"
printf '%s\n' "${ROWS[@]}"
echo
echo "### Summary"
echo
echo "- valid: **$n_valid / $n_supported** supported models (of which $n_open open surfaces, where exit 3 is expected); $n_unsupported with a format tetcdt does not read yet$( [[ $n_unsupported -gt 0 ]] && printf ' (%s)' "$(printf '%s\n' "${UNSUPPORTED_LIST[@]}" | sed 's/.*\.//' | sort | uniq -c | awk '{printf "%s%d .%s", (NR>1?", ":""), $1, $2}')")"
echo "- identical to TetGen where neither adds Steiner points: **$n_ident / $n_ident_cases**$( [[ ${#RENUMBERED[@]} -gt 0 ]] && echo " (of which ${#RENUMBERED[@]} STL files once their points are numbered as TetGen numbers them: ${RENUMBERED[*]})" )"
echo "- Steiner points, total over the $( [[ $HAVE_TETGEN == 1 ]] && echo "models both meshed" || echo "models meshed" ): ours **$sum_st_ours**, TetGen **$sum_st_tg**"
if [[ $n_both -gt 0 ]]; then
    ratio="$(awk -v a="$sum_t_ours" -v b="$sum_t_tg" 'BEGIN { if (b > 0) printf "%.2f", a / b; else print "n.a." }')"
    echo "- time, total over $n_both models: ours **${sum_t_ours} s**, TetGen **${sum_t_tg} s**, ratio ours/TetGen **$ratio** (wall time, including reading and writing)"
fi
[[ ${#MORE_STEINER[@]} -gt 0 ]] && echo "- we add Steiner points where TetGen adds none: ${MORE_STEINER[*]}"
if [[ $USE_FLIP == 1 ]]; then
    echo "- -F (flips): valid **$n_flip_valid / $n_flip**; tets equal to -C where neither adds Steiner points **$n_flip_ident / $n_flip_ident_cases**; regions that fell back to cavities **$n_flip_fallbacks**; wall time over the models -F meshed: -F **${sum_t_flip} s**, -C **${sum_t_cav} s**"
fi
[[ ${#SKIPPED_NO_TSV[@]} -gt 0 ]] && echo "- not in tetgen_p_O0.tsv (TetGen cannot read them), skipped: ${SKIPPED_NO_TSV[*]}"
[[ $ALL == 0 && ${#PATTERNS[@]} == 0 ]] && echo "- tetgen_stp/ skipped (use --all)"
if [[ ${#FAILURES[@]} -gt 0 ]]; then
    echo
    echo "### Failures (${#FAILURES[@]})"
    echo
    printf -- '- %s\n' "${FAILURES[@]}"
fi
if [[ ${#FLIP_PROBLEMS[@]} -gt 0 ]]; then
    echo
    echo "### -F problems (${#FLIP_PROBLEMS[@]})"
    echo
    printf -- '- %s\n' "${FLIP_PROBLEMS[@]}"
fi
if [[ ${#DIFFERENCES[@]} -gt 0 ]]; then
    echo
    echo "### Not identical to TetGen (${#DIFFERENCES[@]})"
    echo
    printf -- '- %s\n' "${DIFFERENCES[@]}"
fi
[[ ${#FAILURES[@]} -eq 0 && ${#FLIP_PROBLEMS[@]} -eq 0 && ${#UNEXPLAINED[@]} -eq 0 ]]
