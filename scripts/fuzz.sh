#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang in build-fuzz/ and runs each for
# SECONDS_PER_TARGET seconds (default 30): fuzz_runtime (the sidecar runtime header), fuzz_gltf,
# fuzz_md2, fuzz_iqm (the loaders), fuzz_gltf_extension (the ANIMORDER_animated_triangle_orders
# reader), fuzz_http_request (the request parser of `animorder view`). Each target starts from a
# temporary corpus: the committed seeds in fuzz/corpus/<name>/ (the target's name without
# "fuzz_") plus, when ../shared/data is there, its small files of that format (read only, copied
# to the temporary folder). Exits non-zero when any target finds a crash, leak, timeout or
# out-of-memory, printing the path of the input that triggers it.
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]      e.g. scripts/fuzz.sh 60 fuzz_runtime
#
# Environment: FUZZ_JOBS (build parallelism, default 2), FUZZ_DATA (characters folder, default
# ../shared/data next to the repository), FUZZ_SHARED_MAX_KB (largest characters file used as a
# seed, default 100: a sanitized load of a 300 KB character takes ~0.3 s, which would leave only a
# few hundred executions a minute), FUZZ_KEEP=1 keeps the temporary folder (corpora grown).
set -euo pipefail

seconds="${1:-30}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_runtime fuzz_gltf fuzz_md2 fuzz_iqm fuzz_gltf_extension fuzz_http_request)
case "$seconds" in '' | *[!0-9]*) echo "fuzz.sh: SECONDS_PER_TARGET must be a number" >&2; exit 2 ;; esac

here="$(cd "$(dirname "$0")/.." && pwd)"
data="${FUZZ_DATA:-$here/../shared/data}"
build="$here/build-fuzz"

bash "$here/scripts/install-deps.sh" --fuzz
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (scripts/install-deps.sh --fuzz)" >&2; exit 2; }
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DANIMORDER_FUZZ=ON \
    -DANIMORDER_BUILD_TESTS=OFF -DANIMORDER_BUILD_BENCHMARKS=OFF >/dev/null
fi
cmake --build "$build" -j"${FUZZ_JOBS:-2}" --target "${targets[@]}" >/dev/null

work="$(mktemp -d "${TMPDIR:-/tmp}/animorder-fuzz.XXXXXX")"
[ "${FUZZ_KEEP:-0}" = 1 ] || trap 'rm -rf "$work"' EXIT

# Small files of a target's format from the characters folder (never written to).
shared_seeds() {
  local pattern
  [ -d "$data" ] || return 0
  case "$1" in
    fuzz_gltf | fuzz_gltf_extension) pattern='-name *.glb -o -name *.gltf' ;;
    fuzz_md2) pattern='-name *.md2' ;;
    fuzz_iqm) pattern='-name *.iqm' ;;
    *) return 0 ;;
  esac
  # shellcheck disable=SC2086
  find "$data" -type f \( $pattern \) -size -"${FUZZ_SHARED_MAX_KB:-100}"k -print
}

# Stack traces for UBSan reports too; ASan's defaults already print them.
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"

status=0
for target in "${targets[@]}"; do
  name="${target#fuzz_}"
  corpus="$work/$name/corpus"
  artifacts="$work/$name/artifacts/"
  mkdir -p "$corpus" "$artifacts"
  cp "$here/fuzz/corpus/$name/"* "$corpus/" 2>/dev/null || true
  while IFS= read -r f; do cp "$f" "$corpus/shared-$(basename "$f")"; done < <(shared_seeds "$target")
  echo "fuzz.sh: $target for ${seconds}s ($(ls "$corpus" | wc -l) seeds)"
  log="$work/$name/log.txt"
  if ! "$build/fuzz/$target" "$corpus" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
       -artifact_prefix="$artifacts" -print_final_stats=1 >"$log" 2>&1; then
    status=1
    grep -E "ERROR|runtime error|SUMMARY|^ +#[0-9]+ +0x" "$log" | head -12 >&2 || true
    for crash in "$artifacts"*; do
      [ -e "$crash" ] || continue
      kept="${TMPDIR:-/tmp}/animorder-$name-$(basename "$crash")"
      cp "$crash" "$kept"
      echo "fuzz.sh: $target FAILED, input: $kept (reproduce: $build/fuzz/$target $kept)" >&2
    done
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$log" | sed "s/^/fuzz.sh: $target /"
  fi
done
exit $status
