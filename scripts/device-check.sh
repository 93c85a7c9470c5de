#!/usr/bin/env bash
# Checks made on another machine than this one, the device machine some tasks are lent (an Intel
# Xeon with AVX-512 and 16 cores; CI never runs there and nothing needs it):
# - the rasteriser's tests and bench_raster with every copy that CPU runs (portable, AVX2,
#   AVX-512): the same hashes, so the AVX-512 copy, never run on this project's own machines, is
#   checked on real hardware;
# - a run's buffers there are the same bytes as here (another CPU, copy and thread count);
# - Xbot single-sided (issue 19's case, as bench_scale's xbot-single-sided), every clip, `single`,
#   default protocol, 2 threads: this build against the issue's engine, 2 rounds, the order
#   reversed in the second; and the same pinned to the CPU's first two logical processors.
#
#   bash scripts/device-check.sh prepare   # here: .devcheck/ (ignored) with the executables, the
#                                          # libraries they load and their loader (the device runs
#                                          # another system), the input and the expected hashes
#   bash scripts/device-check.sh run       # there: the device tool's run, carrying .devcheck
#
# prepare needs build/ (scripts/test.sh), build-baseline/ (scripts/build-baseline.sh) and the data
# beside the repository (../shared/data, or $ANIMORDER_DATA).
set -euo pipefail
cd "$(dirname "$0")/.."
D=.devcheck

prepare() {
  local data=${ANIMORDER_DATA:-../shared/data}
  [ -f "$data/glb-xbot/Xbot.glb" ] || { echo "device-check: $data/glb-xbot/Xbot.glb is absent" >&2; exit 1; }
  [ -x build-baseline/build/animorder ] || { echo "device-check: run scripts/build-baseline.sh first" >&2; exit 1; }
  rm -rf "$D"
  mkdir -p "$D/lib"
  cp build/animorder build/bench/bench_raster build/tests/test_rasterizer build/tests/test_kept_fragments \
     build/tests/test_facing_filter build/tests/test_overdraw "$D/"
  cp build-baseline/build/animorder "$D/base_animorder"
  for f in "$D"/*; do
    if [ -f "$f" ]; then ldd "$f" | awk '$3 ~ /^\// {print $3}'; fi
  done | sort -u | xargs -I{} cp -L {} "$D/lib/"
  cp -L /lib64/ld-linux-x86-64.so.2 "$D/lib/"
  # Every material single-sided, the binary chunk byte for byte (bench_scale's write_single_sided_copy).
  python3 - "$data/glb-xbot/Xbot.glb" "$D/XbotSS.glb" <<'EOF'
import json, struct, sys
glb = open(sys.argv[1], 'rb').read()
length, kind = struct.unpack_from('<II', glb, 12)
assert glb[:4] == b'glTF' and kind == 0x4E4F534A
gltf = json.loads(glb[20:20 + length])
for m in gltf.get('materials', []):
    m['doubleSided'] = False
text = json.dumps(gltf, separators=(',', ':')).encode()
text += b' ' * (-len(text) % 4)
rest = glb[20 + length:]
header = struct.pack('<5I', 0x46546C67, 2, 20 + len(text) + len(rest), len(text), 0x4E4F534A)
open(sys.argv[2], 'wb').write(header + text + rest)
EOF
  echo "device-check: the same runs here, for the hashes to expect there" >&2
  build/animorder optimize --method single "$D/XbotSS.glb" --clip idle -o /tmp/devcheck-idle --threads 2 -q >/dev/null
  build/animorder optimize --method single "$D/XbotSS.glb" -o /tmp/devcheck-all -q >/dev/null
  for f in /tmp/devcheck-idle.animorder.bin /tmp/devcheck-all.animorder.bin; do
    sha256sum < "$f" | cut -c1-16
  done > "$D/expected.txt"
  rm -f /tmp/devcheck-idle.animorder.* /tmp/devcheck-all.animorder.*
  du -sh "$D" >&2
}

run() {
  local L="$D/lib/ld-linux-x86-64.so.2 --library-path $D/lib"
  local idle all
  idle=$(sed -n 1p "$D/expected.txt")
  all=$(sed -n 2p "$D/expected.txt")
  same() { [ "$(sha256sum < "$1" | cut -c1-16)" = "$2" ] && echo "same bytes as here" || echo "DIFFERENT from here"; }
  echo "== CPU"
  lscpu | grep -E "Model name|^CPU\(s\)|Thread\(s\) per core"
  grep -o -w -E "avx2|avx512f|avx512vl|avx512bw|avx512dq" /proc/cpuinfo | sort | uniq -c
  echo "== tests (every copy this CPU runs)"
  for t in test_rasterizer test_kept_fragments test_facing_filter test_overdraw; do
    timeout 200 $L "$D/$t" --gtest_brief=1 2>&1 | tail -3
  done
  echo "== bench_raster, every copy in one run"
  timeout 120 $L "$D/bench_raster" "$D/XbotSS.glb" --keyframes 2 --simd all 2>&1 | grep -E "copy|hash|faster"
  echo "== the idle clip with 16 threads"
  timeout 120 $L "$D/animorder" optimize --method single "$D/XbotSS.glb" --clip idle -o /tmp/idle --threads 16 \
    -q >/dev/null
  same /tmp/idle.animorder.bin "$idle"
  echo "== every clip, 2 threads: this build and the issue's engine"
  for round in 1 2; do
    local order="animorder base_animorder"
    [ "$round" = 2 ] && order="base_animorder animorder"
    for b in $order; do
      /usr/bin/time -f "round $round $b: %e s wall, %M KB peak" \
        timeout 200 $L "$D/$b" optimize --method single "$D/XbotSS.glb" -o "/tmp/all_$b" --threads 2 -q >/dev/null
      same "/tmp/all_$b.animorder.bin" "$all"
    done
  done
  echo "== the same, pinned to logical processors 0 and 1 (taskset; maybe one core's two threads)"
  for b in animorder base_animorder; do
    /usr/bin/time -f "pinned $b: %e s wall" \
      taskset -c 0,1 $L "$D/$b" optimize --method single "$D/XbotSS.glb" -o "/tmp/pin_$b" -q >/dev/null
  done
}

case "${1:-}" in
  prepare) prepare ;;
  run) run ;;
  *) echo "usage: bash scripts/device-check.sh prepare|run" >&2; exit 2 ;;
esac
