#!/usr/bin/env bash
# CTest extension_example_schema: docs/extension/example.gltf conforms to the extension's schemas,
# and two corrupted copies of it do not (so the check can fail). Needs python3-jsonschema
# ("gltf-tools" of ANIMORDER_REQUIRE): skipped (exit 77) without it, failed when required.
#   test-extension-schema.sh [PARENT]   its files go to a folder of its own, made under PARENT
#                                       (default: $TMPDIR or /tmp) and removed on exit; nothing
#                                       else there is touched (it removed a fixed folder before,
#                                       whoever had made it)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
parent="${1:-${TMPDIR:-/tmp}}"
if ! python3 -c "import jsonschema" 2>/dev/null; then
  case ",${ANIMORDER_REQUIRE:-}," in
    *,gltf-tools,*|*,all,*) echo "python3-jsonschema is absent (required: ANIMORDER_REQUIRE)"; exit 1 ;;
  esac
  echo "skipped: python3-jsonschema is absent"; exit 77
fi
mkdir -p "$parent"
scratch="$(mktemp -d "$parent/extension_schema.XXXXXX")"
trap 'rm -rf "$scratch"' EXIT
python3 "$here/scripts/validate-extension-schema.py" "$here/docs/extension/example.gltf"
python3 - "$here/docs/extension/example.gltf" "$scratch" <<'PY'
import json, sys
g = json.load(open(sys.argv[1]))
n = "ANIMORDER_animated_triangle_orders"
a = json.loads(json.dumps(g)); a["extensions"][n]["clips"][0]["thetaSteps"] = 1
b = json.loads(json.dumps(g)); del b["meshes"][0]["primitives"][0]["extensions"][n]["orderCount"]
json.dump(a, open(sys.argv[2] + "/bad-theta.gltf", "w")); json.dump(b, open(sys.argv[2] + "/bad-count.gltf", "w"))
PY
for bad in bad-theta bad-count; do
  if python3 "$here/scripts/validate-extension-schema.py" "$scratch/$bad.gltf" >/dev/null; then
    echo "$bad.gltf passed the schema check"; exit 1
  fi
done
echo "example conforms; corrupted copies rejected"
