#!/usr/bin/env bash
# Hashes of everything `optimize` writes (glTF/GLB, sidecar and its description) for every
# method, on the bundled character and on Ganfaul's Idle clip, plus `evaluate`'s table without
# its time column: the check that a refactoring changed no output byte. Usage:
#   bash scripts/output-hashes.sh [ANIMORDER_EXE] > hashes.txt
# Compare two builds with `diff`; the data set is skipped with a note when ../shared/data is absent.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-$here/build/animorder}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
methods=(original static-sander07 static-nehab06 meshopt single joint)
run() {  # label, output extension ("" or .glb), then optimize's arguments
    local label="$1" extension="$2"; shift 2
    "$exe" optimize --quiet "$@" -o "$work/$label$extension" >/dev/null
    for f in "$work/$label".*; do echo "$(sha256sum <"$f" | cut -c1-16)  ${f##*/}"; done
}
for m in "${methods[@]}"; do run "bundled-$m" "" --method "$m"; done
"$exe" evaluate --quiet --methods original,static-sander07,single,oracle --eval-views 20 --eval-resolution 256 \
    --csv "$work/evaluate.csv" >/dev/null
echo "$(cut -d, -f1-9 "$work/evaluate.csv" | sha256sum | cut -c1-16)  bundled evaluate.csv (no time column)"
ganfaul="$here/../shared/data/mixamo-ganfaul/Ganfaul.gltf"
if [ -f "$ganfaul" ]; then
    for m in "${methods[@]}"; do run "ganfaul-$m" .glb "$ganfaul" --clip Idle --method "$m"; done
else
    echo "note: $ganfaul is absent; Ganfaul skipped" >&2
fi
