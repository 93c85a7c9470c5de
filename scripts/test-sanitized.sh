#!/usr/bin/env bash
# The loaders, the glTF writers (and their pruning of replaced accessors), the output sets (their
# signal handler) and the sidecar reader under AddressSanitizer and UBSan: every bad-input test
# runs with memory errors and undefined behaviour turned into failures.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DANIMORDER_SANITIZE=ON -DANIMORDER_BUILD_BENCHMARKS=OFF >/dev/null
targets=(test_gltf_loader test_md2_loader test_iqm_loader test_assimp_loader test_gltf_writer test_gltf_prune test_atomic_write
         test_animated_mesh
         test_runtime test_skinning)
cmake --build build-asan -j"$(nproc)" --target "${targets[@]}"
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for t in "${targets[@]}"; do
  echo "sanitized: $t"
  "build-asan/tests/$t" --gtest_brief=1
done
# The kept fragments of k-means (hand-worked and random lists, the bundled character's budgets).
cmake --build build-asan -j"$(nproc)" --target test_kept_fragments
echo "sanitized: test_kept_fragments"
build-asan/tests/test_kept_fragments --gtest_brief=1 --gtest_filter='KeptFragments.*:NodeCache.BundledCharacterScores*'
