#!/usr/bin/env bash
# Regenerates data/certify/: meshes made by Debian's TetGen 1.5 that the certifier must
# judge (tests/certify.rs), so that `cargo test` needs no TetGen:
#   NAME.pO0.{node,ele}: `tetgen -pO0Q` of data/nonflat/NAME.off for anchor, fandisk and
#     mpi: TetGen's plain CDT, which leaves shim tets there (the referee agrees);
#   rotor_small.p.{node,ele}: `tetgen -pQ` (optimized): its flips leave faces that are
#     not locally Delaunay, so it is no CDT.
# Idempotent: the same TetGen gives the same files (the comment lines are stripped).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$ROOT/data/certify"
command -v tetgen >/dev/null || { echo "error: tetgen not on PATH (apt-get install tetgen)" >&2; exit 1; }
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$OUT"
keep() { # model tag switches
    cp "$ROOT/data/nonflat/$1.off" "$WORK/"
    (cd "$WORK" && tetgen "$3" "$1.off" >/dev/null 2>&1)
    for ext in node ele; do
        grep -v '^#' "$WORK/$1.1.$ext" >"$OUT/$1.$2.$ext"
    done
    rm -f "$WORK/$1".1.*
}
for m in anchor fandisk mpi; do keep "$m" pO0 -pO0Q; done
keep rotor_small p -pQ
cat >"$OUT/README.md" <<EOT
# TetGen meshes for the certifier's tests

Written by \`scripts/gen-certify-reference.sh\` with TetGen $(dpkg-query -W -f='${Version}' tetgen 2>/dev/null || echo unknown) from the models in
\`data/nonflat/\` (CGAL's data, free to use; see \`data/nonflat/README.md\`):

| files | command | verdict |
|---|---|---|
| \`anchor.pO0.*\`, \`fandisk.pO0.*\`, \`mpi.pO0.*\` | \`tetgen -pO0Q NAME.off\` | no CDT: shim tets on nearly flat merged facets |
| \`rotor_small.p.*\` | \`tetgen -pQ rotor_small.off\` | no CDT: the optimization's flips leave faces that are not locally Delaunay |
EOT
echo "wrote $OUT" >&2
