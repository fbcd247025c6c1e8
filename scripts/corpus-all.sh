#!/usr/bin/env bash
# Runs `tetcdt -pQ` on every file of the shared corpus, whatever its format, and prints one
# line per model: its outcome and, for a refusal, the exit code and the first line of the
# message, next to the corpus notes (MANIFEST.tsv) and TetGen's own -d verdict.
#
# usage: scripts/corpus-all.sh [--no-build] [--validate] [PATTERN...]
#
#   --no-build   do not run `cargo build --release` first
#   --validate   also run validate_mesh.py on each written mesh (slower)
#   PATTERN      only models whose corpus path contains one of the patterns
#
# Environment: CORPUS (default ../shared/corpus relative to the repository), TETCDT (the
# binary, default target/release/tetcdt), TETCDT_TOOLS (the directory of validate_mesh.py,
# default ../shared/tools), TIMEOUT (seconds per run, default 120).
#
# Outcomes: "valid" (exit 0; with --validate, the referee agrees), "invalid" (exit 0 but
# the referee disagrees), "refused N" (exit N with a message), "crash" (killed by a
# signal, or an internal error), "timeout". Formats this build cannot read show as
# "refused 3: ... unknown input format". Exits 1 if any model crashed or timed out.
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD=1
VALIDATE=0
PATTERNS=()
for a in "$@"; do
    case "$a" in
        --no-build) BUILD=0 ;;
        --validate) VALIDATE=1 ;;
        -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
        -*) echo "corpus-all.sh: unknown option $a" >&2; exit 2 ;;
        *) PATTERNS+=("$a") ;;
    esac
done
CORPUS="${CORPUS:-$ROOT/../shared/corpus}"
TETCDT="${TETCDT:-$ROOT/target/release/tetcdt}"
TOOLS="${TETCDT_TOOLS:-$ROOT/../shared/tools}"
TIMEOUT="${TIMEOUT:-120}"
[ -d "$CORPUS/files" ] || { echo "corpus-all.sh: no $CORPUS/files" >&2; exit 2; }
if [ "$BUILD" = 1 ]; then
    (cd "$ROOT" && cargo build --release --quiet) || exit 2
fi
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

# A column of a tsv row for a model, or "".
field() { awk -F'\t' -v f="$1" -v m="$3" '$1 == f && (m == "" || $2 == m) { print $'"$2"'; exit }' "$4"; }

bad=0
total=0
declare -A count
printf '%-45s %-8s %-12s %s\n' model secs outcome "message | manifest notes | TetGen -d"
while IFS= read -r rel; do
    if [ "${#PATTERNS[@]}" -gt 0 ]; then
        keep=0
        for p in "${PATTERNS[@]}"; do [[ "$rel" == *"$p"* ]] && keep=1; done
        [ "$keep" = 1 ] || continue
    fi
    total=$((total + 1))
    in="$CORPUS/files/$rel"
    start=$(date +%s.%N)
    timeout "$TIMEOUT" "$TETCDT" -pQ -o "$WORK/out" "$in" >"$WORK/stdout" 2>"$WORK/stderr"
    rc=$?
    secs=$(echo "$(date +%s.%N) - $start" | bc)
    msg="$(head -c 2000 "$WORK/stderr" | head -1 | sed "s|$CORPUS/files/||; s|^tetcdt: ||" | cut -c1-150)"
    if [ "$rc" = 124 ]; then
        outcome=timeout; bad=$((bad + 1))
    elif [ "$rc" -gt 128 ] || grep -q "internal error" "$WORK/stderr"; then
        outcome=crash; bad=$((bad + 1))
    elif [ "$rc" = 0 ]; then
        outcome=valid
        msg=""
        if [ "$VALIDATE" = 1 ] && [[ "$rel" =~ \.(off|poly|smesh|node|mesh)$ ]]; then
            if ! python3 "$TOOLS/validate_mesh.py" "$in" "$WORK/out" >"$WORK/val" 2>&1; then
                outcome=invalid; msg="$(tail -1 "$WORK/val")"
            fi
        fi
    else
        outcome="refused $rc"
    fi
    count["$outcome"]=$(( ${count["$outcome"]:-0} + 1 ))
    notes="$(field "$rel" 13 "" "$CORPUS/MANIFEST.tsv")"
    tgd="$(field "$rel" 8 "-d" "$CORPUS/tetgen_results.tsv" | cut -c1-60)"
    printf '%-45s %-8.2f %-12s %s | %s | %s\n' "$rel" "$secs" "$outcome" "$msg" "$notes" "$tgd"
    rm -f "$WORK"/out.*
done < <(cd "$CORPUS/files" && find . -type f ! -name '*.md' | sed 's|^\./||' | sort)

echo
echo "Summary over $total models:"
for k in "${!count[@]}"; do echo "  $k: ${count[$k]}"; done | sort
[ "$bad" = 0 ]
