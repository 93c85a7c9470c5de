#!/usr/bin/env bash
# Set-up to result: installs dependencies, builds everything in Release, and runs the main job on
# the bundled procedural character (no input file needed): Han & Sander's k-means ("single", k = 5
# per clip), writing the buffers + lookup tables, then a quick evaluation against the baselines.
# Results land in build/out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
mkdir -p build/out
build/animorder inspect
build/animorder optimize --method single -o build/out/character --report build/out/optimize.json
build/animorder evaluate --methods original,static-sander07,single --eval-views 60 --eval-resolution 256 \
  --report build/out/evaluate.json
build/animorder heatmap --order original --frame 55 --view 0.5,0.3,-1 -o build/out/heatmap.png
echo "outputs: build/out/character.animorder.{bin,json}, build/out/{optimize,evaluate}.json, build/out/heatmap.png"
