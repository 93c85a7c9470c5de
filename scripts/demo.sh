#!/usr/bin/env bash
# Set-up to result: installs dependencies, builds everything in Release, and runs the main job
# on the bundled procedural character (no input file needed). Results land in build/out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
mkdir -p build/out
build/animorder inspect
build/animorder optimize --method static-sander07 --lambda 0.85 \
  -o build/out/character.indices.bin --report build/out/report.json
echo "report: build/out/report.json"
