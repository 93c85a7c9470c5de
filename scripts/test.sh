#!/usr/bin/env bash
# Set-up to green tests: installs dependencies, builds everything in build/ (Release, warnings as
# errors: the flags of scripts/demo.sh, so what the demo built is reused), and runs the whole
# suite with CTest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
source scripts/configure.sh
configure_build build -DANIMORDER_BUILD_TESTS=ON -DANIMORDER_BUILD_BENCHMARKS=ON
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
