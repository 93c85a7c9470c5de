#!/usr/bin/env bash
# Hashes of everything `optimize` writes (glTF/GLB, sidecar and its description) for every
# method `optimize --method` accepts (all but oracle, a bound and not an order to ship), on the
# bundled character and on Ganfaul's Idle clip, plus `evaluate`'s table without its time column:
# the check that a refactoring changed no output byte. The measured methods, and the variants of
# `variants` (bundled character only), run on cheap clustering settings: a dozen seconds in all.
# A method `optimize` accepts that no list here names fails the script. Usage:
#   bash scripts/output-hashes.sh [ANIMORDER_EXE] > hashes.txt
# Compare two builds with `diff`; the data set is skipped with a note when ../shared/data is absent.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-$here/build/animorder}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
methods=(original static-sander07 static-nehab06 meshopt single joint tipsify-per-frame)  # defaults
cheap=(measured measured-joint)  # on cheap_settings
cheap_settings=(-k 3 --views 12 --resolution 64 --max-iterations 4)
variants=("measured --planar-units" "measured --blend-clusters" "single --blend-clusters"
          "single --distance i3d --update paper")  # on cheap_settings, bundled character only
known=$({ "$exe" optimize --quiet --method none 2>&1 || true; } | sed -n 's/.*(known: \(.*\))$/\1/p' | tr -d ' ' | tr , ' ')
[ -n "$known" ] || { echo "output-hashes: $exe did not list the methods optimize accepts" >&2; exit 1; }
for m in $known; do
    case " oracle ${methods[*]} ${cheap[*]} " in
        *" $m "*) ;;
        *) echo "output-hashes: method $m is not hashed: add it to methods or cheap" >&2; exit 1 ;;
    esac
done
run() {  # label, output extension ("" or .glb), then optimize's arguments
    local label="$1" extension="$2"; shift 2
    "$exe" optimize --quiet "$@" -o "$work/$label$extension" >/dev/null
    for f in "$work/$label".*; do echo "$(sha256sum <"$f" | cut -c1-16)  ${f##*/}"; done
}
for m in "${methods[@]}"; do run "bundled-$m" "" --method "$m"; done
for m in "${cheap[@]}"; do run "bundled-$m-cheap" "" --method "$m" "${cheap_settings[@]}"; done
for v in "${variants[@]}"; do
    read -ra words <<<"$v"
    run "bundled-$(sed 's/ --/-/g; s/ /-/g' <<<"$v")-cheap" "" --method "${words[@]}" "${cheap_settings[@]}"
done
"$exe" evaluate --quiet --methods original,static-sander07,single,oracle --eval-views 20 --eval-resolution 256 \
    --csv "$work/evaluate.csv" >/dev/null
echo "$(cut -d, -f1-9 "$work/evaluate.csv" | sha256sum | cut -c1-16)  bundled evaluate.csv (no time column)"
ganfaul="$here/../shared/data/mixamo-ganfaul/Ganfaul.gltf"
if [ -f "$ganfaul" ]; then
    for m in "${methods[@]}"; do run "ganfaul-$m" .glb "$ganfaul" --clip Idle --method "$m"; done
    for m in "${cheap[@]}"; do
        run "ganfaul-$m-cheap" .glb "$ganfaul" --clip Idle --method "$m" "${cheap_settings[@]}"
    done
else
    echo "note: $ganfaul is absent; Ganfaul skipped" >&2
fi
