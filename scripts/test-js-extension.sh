#!/usr/bin/env bash
# CTest gltf_transform_extension: `npm test` of js/gltf-transform-animorder (node's test runner).
# Needs node and the package's dependencies (scripts/install-deps.sh: npm ci there), the
# "gltf-tools" of ANIMORDER_REQUIRE: skipped (exit 77) without them, failed when required.
set -euo pipefail
dir="$(cd "$(dirname "$0")/.." && pwd)/js/gltf-transform-animorder"
if ! command -v node >/dev/null || ! command -v npm >/dev/null || [ ! -d "$dir/node_modules/@gltf-transform/core" ]; then
  why="node/npm or $dir/node_modules is absent (run scripts/install-deps.sh)"
  case ",${ANIMORDER_REQUIRE:-}," in
    *,gltf-tools,*|*,all,*) echo "$why (required: ANIMORDER_REQUIRE)"; exit 1 ;;
  esac
  echo "skipped: $why"; exit 77
fi
cd "$dir" && npm test --silent
