#!/usr/bin/env bash
# Set-up to result: installs what the tool needs, builds the tool alone (Release, warnings as
# errors: the flags of scripts/test.sh, in the same build/ tree, so the tests build on top of it
# and recompile nothing), and runs the main job on the bundled procedural character (no input
# file needed): the default method, `measured` (Han & Sander's k-means, k = 5 per clip, each
# cluster's order from its measured overdraw), writing the buffers + lookup tables, then a quick
# evaluation against the paper's `single` and the baselines, and a heatmap. Results land in build/out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh --tool
source scripts/configure.sh
configure_build build -DANIMORDER_BUILD_TESTS=OFF -DANIMORDER_BUILD_BENCHMARKS=OFF
cmake --build build -j"$(nproc)" --target animorder
mkdir -p build/out
build/animorder inspect
build/animorder optimize -o build/out/character --report build/out/optimize.json
build/animorder evaluate --methods original,static-sander07,single,measured --eval-views 60 --eval-resolution 256 \
  --report build/out/evaluate.json
build/animorder heatmap --order original --frame 55 --view 0.5,0.3,-1 -o build/out/heatmap.png
echo "outputs: build/out/character.animorder.{bin,json}, build/out/{optimize,evaluate}.json, build/out/heatmap.png"
