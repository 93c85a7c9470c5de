#!/usr/bin/env bash
# The Debian package (issue 52): `cpack -G DEB` on BUILD gives animorder_VERSION_ARCH.deb; unpacked
# into a scratch root (dpkg-deb -x: nothing is installed on the machine), it holds the tool, the
# headers, the runtime header, the CMake and pkg-config files and the README, declares its
# Debian dependencies, and its tool prints the package's version and writes, on the bundled
# character, the bytes of the build's own tool.
#   deb.sh BUILD SCRATCH
set -euo pipefail
build=$(cd "$1" && pwd)
scratch=$2
rm -rf "$scratch"
mkdir -p "$scratch"
scratch=$(cd "$scratch" && pwd)

cpack --config "$build/CPackConfig.cmake" -B "$scratch/pkg" > "$scratch/cpack.log" 2>&1 ||
  { cat "$scratch/cpack.log" >&2; exit 1; }
version=$("$build/animorder" --version | cut -d' ' -f2)
deb=$scratch/pkg/animorder_${version}_$(dpkg --print-architecture).deb
[ -f "$deb" ] || { echo "deb.sh: no $deb: $(ls "$scratch/pkg")" >&2; exit 1; }
[ "$(dpkg-deb -f "$deb" Package)" = animorder ] && [ "$(dpkg-deb -f "$deb" Version)" = "$version" ] ||
  { echo "deb.sh: the package's name or version is not animorder $version" >&2; exit 1; }
depends=$(dpkg-deb -f "$deb" Depends)
for library in libtbb libassimp libmeshoptimizer libtinygltf libstdc++; do
  [[ "$depends" == *"$library"* ]] || { echo "deb.sh: Depends lacks $library: $depends" >&2; exit 1; }
done

dpkg-deb -x "$deb" "$scratch/root"
root=$scratch/root/usr
for f in bin/animorder include/animorder/methods.h include/animorder_runtime.h share/doc/animorder/README.md; do
  [ -f "$root/$f" ] || { echo "deb.sh: the package has no /usr/$f" >&2; exit 1; }
done
[ -n "$(find "$root" -name animorderConfig.cmake)" ] && [ -n "$(find "$root" -name animorder.pc)" ] ||
  { echo "deb.sh: the package has no CMake config or .pc file" >&2; exit 1; }
[ "$("$root/bin/animorder" --version)" = "animorder $version" ] ||
  { echo "deb.sh: the packaged tool says '$("$root/bin/animorder" --version)', not animorder $version" >&2; exit 1; }
mkdir -p "$scratch/packaged" "$scratch/built"
"$root/bin/animorder" optimize -q -k 2 --views 12 --resolution 32 --max-iterations 2 -o "$scratch/packaged/out"
"$build/animorder" optimize -q -k 2 --views 12 --resolution 32 --max-iterations 2 -o "$scratch/built/out"
cmp "$scratch/packaged/out.animorder.bin" "$scratch/built/out.animorder.bin"
cmp "$scratch/packaged/out.animorder.json" "$scratch/built/out.animorder.json"
# The Python module, where the build has one: it imports from the package's dist-packages.
if ls "$build"/python/animorder*.so > /dev/null 2>&1; then
  module=$(PYTHONPATH=$root/lib/python3/dist-packages /usr/bin/python3 -c \
    'import animorder; print(animorder.__file__, animorder.__version__)')
  [[ "$module" == "$root/lib/python3/dist-packages/animorder"*" $version" ]] ||
    { echo "deb.sh: the packaged Python module is not imported from the package: $module" >&2; exit 1; }
fi
echo "deb.sh: $(basename "$deb") unpacks, declares its dependencies and its tool writes the build's bytes"
