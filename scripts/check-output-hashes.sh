#!/usr/bin/env bash
# Every output `scripts/output-hashes.sh` lists must hash as in tests/golden/output-hashes.txt:
# refactoring changes no output byte. A change that means to change outputs regenerates the
# golden file (bash scripts/output-hashes.sh > tests/golden/output-hashes.txt) and says why in
# its commit. Ganfaul's lines are checked when ../shared/data is present.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
golden="$here/tests/golden/output-hashes.txt"
actual="$(bash "$here/scripts/output-hashes.sh" "${1:-$here/build/animorder}")"
missing=$(grep -vxF -f "$golden" <<<"$actual" || true)
if [ -n "$missing" ]; then
    echo "check-output-hashes: these outputs differ from $golden:" >&2
    echo "$missing" >&2
    exit 1
fi
if ! grep -q '^[0-9a-f]*  ganfaul-' <<<"$actual"; then
    case ",${ANIMORDER_REQUIRE:-}," in
        *,data,*|*,all,*) echo "check-output-hashes: ../shared/data is absent and ANIMORDER_REQUIRE needs it" >&2; exit 1 ;;
        *) echo "check-output-hashes: note: Ganfaul is absent; only the bundled character was checked" ;;
    esac
fi
echo "check-output-hashes: $(wc -l <<<"$actual") outputs byte-identical to the golden hashes"
