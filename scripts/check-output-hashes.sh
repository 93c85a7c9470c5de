#!/usr/bin/env bash
# Every output `scripts/output-hashes.sh` lists must hash as in tests/golden/output-hashes.txt,
# both ways: a line that differs, an output no longer written (a golden line missing from the
# actual list) and an output not in the golden file (an extra line) all fail, listed. Refactoring
# changes no output byte. A change that means to change outputs regenerates the golden file
# (bash scripts/output-hashes.sh > tests/golden/output-hashes.txt) and says why in its commit.
# Without ../shared/data (Ganfaul), the bundled character's lines are checked, and then the
# script exits 77 (skipped, CTest's SKIP_RETURN_CODE) with the reason, or 1 where ANIMORDER_REQUIRE
# needs data.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
golden="$here/tests/golden/output-hashes.txt"
ganfaul="$here/../shared/data/mixamo-ganfaul/Ganfaul.gltf"
actual="$(bash "$here/scripts/output-hashes.sh" "${1:-$here/build/animorder}")"
expected="$(cat "$golden")"
have_ganfaul=1
[ -f "$ganfaul" ] || have_ganfaul=0
if [ "$have_ganfaul" = 0 ]; then  # what can be checked: the golden lines that are not Ganfaul's
    expected="$(grep -v '^[0-9a-f]*  ganfaul-' <<<"$expected" || true)"
fi
missing="$(comm -23 <(sort <<<"$expected") <(sort <<<"$actual"))"
extra="$(comm -13 <(sort <<<"$expected") <(sort <<<"$actual"))"
if [ -n "$missing" ] || [ -n "$extra" ]; then
    echo "check-output-hashes: the outputs differ from $golden" >&2
    if [ -n "$missing" ]; then
        echo "golden lines not produced (an output changed or is no longer written):" >&2
        echo "$missing" >&2
    fi
    if [ -n "$extra" ]; then
        echo "produced lines not in the golden file (an output changed or is new):" >&2
        echo "$extra" >&2
    fi
    exit 1
fi
if [ "$have_ganfaul" = 0 ]; then
    why="$ganfaul is absent (../shared/data): only the bundled character's $(wc -l <<<"$actual") outputs were checked"
    case ",${ANIMORDER_REQUIRE:-}," in
        *,data,*|*,all,*) echo "check-output-hashes: $why, and ANIMORDER_REQUIRE needs data" >&2; exit 1 ;;
        *) echo "check-output-hashes: skipped: $why"; exit 77 ;;
    esac
fi
echo "check-output-hashes: $(wc -l <<<"$actual") outputs byte-identical to the golden hashes"
