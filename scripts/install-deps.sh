#!/usr/bin/env bash
# Installs the Debian packages animorder needs. Idempotent: packages already present are skipped,
# and apt is only asked when something is missing.
#   install-deps.sh          build, tests, benchmarks, the JS and browser tests (scripts/test.sh)
#   install-deps.sh --tool   only what the library and the animorder tool need (scripts/demo.sh)
#   install-deps.sh --fuzz   the tool's packages and clang 14 with its libFuzzer runtime (scripts/fuzz.sh)
set -euo pipefail

mode=all
case "${1:-}" in
  "") ;;
  --tool) mode=tool ;;
  --fuzz) mode=fuzz ;;
  *) echo "install-deps: unknown option '$1' (use --tool, --fuzz, or nothing)" >&2; exit 2 ;;
esac

install_missing() {
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -gt 0 ] || return 0
  echo "install-deps: installing ${missing[*]}" >&2
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

tool_packages=(
  build-essential cmake pkg-config
  ccache                                   # compiler cache, used when present (CMakeLists.txt)
  libtbb-dev                               # parallel node scoring
  libcli11-dev nlohmann-json3-dev          # the tool: options, JSON report
  libstb-dev                               # PNG heatmaps
  nettle-dev                               # batch: SHA-256 stamps of items' inputs and options
  libmeshoptimizer-dev                     # the meshopt baseline method
  libnanoflann-dev                         # reapply --nearest: the nearest optimised triangle (k-d tree)
  libtinygltf-dev                          # glTF 2.0 in and out
  libassimp-dev                            # FBX, Collada, .X, .b3d, MD5, ...
)
install_missing "${tool_packages[@]}"
if [ "$mode" = fuzz ]; then
  install_missing clang libclang-rt-14-dev  # clang 14 and its libFuzzer/ASan runtimes
  exit 0
fi
[ "$mode" = all ] || exit 0

packages=(
  libgtest-dev libgmock-dev                # tests
  libbenchmark-dev                         # benchmarks
  libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri  # OpenGL reference (llvmpipe)
  strace procps                            # signal tests: strace slows a commit down; pgrep finds the child
  util-linux                               # unshare -p (a PID namespace); essential, so normally present
  slurm-wlm munge                          # batch as a SLURM array job on a one-node cluster (tests/tool/one-node-slurm.sh)
  python3-dev python3-pybind11 python3-numpy python3-pytest  # the Python module (python/) and its tests
)

# Node.js runs the Khronos glTF Validator in the tests; any node >= 12 will do (the machine's own
# counts), else Debian's.
command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)

install_missing "${packages[@]}"

# The Khronos glTF Validator (npm), pinned, into .tools/ of the repository (ignored by git).
validator_version=2.0.0-dev.3.10
here="$(cd "$(dirname "$0")/.." && pwd)"
if [ ! -f "$here/.tools/node_modules/gltf-validator/package.json" ] ||
   ! grep -q "\"version\": \"$validator_version\"" "$here/.tools/node_modules/gltf-validator/package.json"; then
  echo "install-deps: installing gltf-validator $validator_version (npm)" >&2
  mkdir -p "$here/.tools"
  npm install --silent --no-audit --no-fund --prefix "$here/.tools" "gltf-validator@$validator_version" >/dev/null
fi

# glTF round trips of the ANIMORDER_animated_triangle_orders extension (tests/tool/test_gltf_pipelines.cpp,
# js/gltf-transform-animorder): gltfpack and a JSON-schema checker from Debian; glTF-Transform and
# gltf-pipeline from npm, pinned, into .tools/ (the JS package's own node_modules gets the same).
install_missing gltfpack python3-jsonschema
gltf_transform_version=4.5.1
gltf_pipeline_version=4.3.1
if [ ! -f "$here/.tools/node_modules/@gltf-transform/cli/package.json" ] ||
   ! grep -q "\"version\": \"$gltf_transform_version\"" "$here/.tools/node_modules/@gltf-transform/cli/package.json" ||
   [ ! -f "$here/.tools/node_modules/gltf-pipeline/package.json" ] ||
   ! grep -q "\"version\": \"$gltf_pipeline_version\"" "$here/.tools/node_modules/gltf-pipeline/package.json"; then
  echo "install-deps: installing @gltf-transform/* $gltf_transform_version, gltf-pipeline $gltf_pipeline_version (npm)" >&2
  mkdir -p "$here/.tools"
  npm install --silent --no-audit --no-fund --prefix "$here/.tools" "gltf-validator@$validator_version" \
    "@gltf-transform/core@$gltf_transform_version" "@gltf-transform/extensions@$gltf_transform_version" \
    "@gltf-transform/functions@$gltf_transform_version" "@gltf-transform/cli@$gltf_transform_version" \
    "gltf-pipeline@$gltf_pipeline_version" >/dev/null
fi
if [ -f "$here/js/gltf-transform-animorder/package-lock.json" ] &&
   [ ! -d "$here/js/gltf-transform-animorder/node_modules/@gltf-transform/core" ]; then
  echo "install-deps: installing js/gltf-transform-animorder's dependencies (npm ci)" >&2
  (cd "$here/js/gltf-transform-animorder" && npm ci --silent --no-audit --no-fund >/dev/null)
fi

# The viewer and its browser tests (viewer/, tests/js): Debian's Chromium (headless, WebGL2 on
# SwiftShader) and, from viewer/package-lock.json, three 0.187.0 and puppeteer-core 24.9.0 (no
# browser download: the tests point puppeteer at /usr/bin/chromium).
install_missing chromium
if [ ! -f "$here/viewer/node_modules/three/package.json" ] ||
   ! grep -q '"version": "0.187.0"' "$here/viewer/node_modules/three/package.json" ||
   [ ! -f "$here/viewer/node_modules/puppeteer-core/package.json" ]; then
  echo "install-deps: installing the viewer's npm packages (npm ci in viewer/)" >&2
  (cd "$here/viewer" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --silent --no-audit --no-fund >/dev/null)
fi
