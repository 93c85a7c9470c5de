#!/usr/bin/env bash
# The installed package as a user consumes it (issue 52): `cmake --install` of BUILD into a prefix
# in SCRATCH, then tests/consumer built against that prefix alone, with CMake
# (find_package(animorder CONFIG)) and with pkg-config; each build runs `single` on the bundled
# character and writes the sidecar, which must be the installed tool's bytes for the same settings.
#   run.sh BUILD SCRATCH
set -euo pipefail
build=$(cd "$1" && pwd)
scratch=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$scratch"
mkdir -p "$scratch"
scratch=$(cd "$scratch" && pwd)
prefix=$scratch/prefix

cmake --install "$build" --prefix "$prefix" > "$scratch/install.log"
for f in bin/animorder include/animorder/methods.h include/animorder_runtime.h; do
  [ -f "$prefix/$f" ] || { echo "run.sh: the install has no $f" >&2; exit 1; }
done
config=$(find "$prefix" -name animorderConfig.cmake)
version=$(find "$prefix" -name animorderConfigVersion.cmake)
pc=$(find "$prefix" -name animorder.pc)
[ -n "$config" ] && [ -n "$version" ] && [ -n "$pc" ] || { echo "run.sh: no CMake config, version file or .pc installed" >&2; exit 1; }

# The README's CMake lines are this project's.
readme=$here/../../README.md
block=$(awk '/^```cmake$/ {on = 1; next} on && /^```$/ {exit} on' "$readme")
[ -n "$block" ] || { echo "run.sh: README.md has no cmake block" >&2; exit 1; }
while IFS= read -r line; do
  grep -qxF -- "$line" "$here/CMakeLists.txt" || { echo "run.sh: README's '$line' is not in tests/consumer/CMakeLists.txt" >&2; exit 1; }
done <<< "$block"

# The installed tool's sidecar for the settings main.cpp uses.
"$prefix/bin/animorder" optimize -q --method single -k 2 --views 12 --resolution 32 --max-iterations 2 \
  -o "$scratch/tool"
expected=$scratch/tool.animorder.bin

# CMake: nothing but the prefix.
cmake -S "$here" -B "$scratch/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  > "$scratch/configure.log" 2>&1 || { cat "$scratch/configure.log" >&2; exit 1; }
cmake --build "$scratch/cmake-build" > "$scratch/build.log" 2>&1 || { cat "$scratch/build.log" >&2; exit 1; }
"$scratch/cmake-build/my_exporter" "$scratch/cmake.animorder.bin"
cmp "$scratch/cmake.animorder.bin" "$expected"

# pkg-config: the same program from the .pc file's flags alone.
flags=$(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --cflags --libs animorder)
# shellcheck disable=SC2086  # the flags are words
g++ -std=c++17 -O1 "$here/main.cpp" $flags -o "$scratch/consumer-pc"
"$scratch/consumer-pc" "$scratch/pc.animorder.bin"
cmp "$scratch/pc.animorder.bin" "$expected"
[ "$(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --modversion animorder)" = "$("$prefix/bin/animorder" --version | cut -d' ' -f2)" ] ||
  { echo "run.sh: the .pc version is not the tool's" >&2; exit 1; }
# The README's C++ block, its includes first and its statements as one main, built the same way and
# run on a glb of the bundled character.
mkdir -p "$scratch/snippet"
awk '/^```cpp$/ {on = 1; next} on && /^```$/ {exit} on' "$readme" > "$scratch/snippet/block.cpp"
[ -s "$scratch/snippet/block.cpp" ] || { echo "run.sh: README.md has no cpp block" >&2; exit 1; }
{
  grep '^#include' "$scratch/snippet/block.cpp"
  echo 'int main() {'
  grep -v '^#include' "$scratch/snippet/block.cpp"
  echo '}'
} > "$scratch/snippet/readme.cpp"
# shellcheck disable=SC2086
g++ -std=c++17 -O1 "$scratch/snippet/readme.cpp" $flags -o "$scratch/snippet/readme"
(cd "$scratch/snippet" && "$prefix/bin/animorder" subdivide -q --levels 0 -o character.glb > /dev/null && ./readme)
[ -s "$scratch/snippet/character.animorder.bin" ] || { echo "run.sh: the README's C++ block wrote no sidecar" >&2; exit 1; }

echo "run.sh: the installed package builds a consumer with CMake and with pkg-config; both write the tool's bytes; the README's C++ block runs"
