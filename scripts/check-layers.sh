#!/usr/bin/env bash
# The layering rules of docs/ARCHITECTURE.md, checked on the source tree (CTest runs it):
#  1. every public header include/animorder/X.h is defined by one source src/LAYER/X.cpp (except
#     animorder.h, the manual, and invalid_input.h, which are declarations only);
#  2. no source or header includes a header of a higher layer, ground up:
#     mesh and support (0) → overdraw (1) → algorithms (2) → assets (3) → pipeline (4) → io (5);
#     the OpenGL reference (src/reference) sits beside the pipeline (4); tools may include
#     anything. Public headers count by their source's folder, private ones ("../DIR/x.h") by DIR;
#  3. below io nothing includes a file-format, JSON or command-line library header.
set -euo pipefail
cd "$(dirname "$0")/.."
declare -A layer_of_dir=([mesh]=0 [support]=0 [overdraw]=1 [algorithms]=2 [assets]=3 [pipeline]=4 [reference]=4 [io]=5)
io_layer=${layer_of_dir[io]}
declare -A layer   # public header name → layer
layer[animorder.h]=${layer_of_dir[algorithms]}
layer[invalid_input.h]=0
failures=0
fail() { echo "check-layers: $*" >&2; failures=$((failures + 1)); }

for header in include/animorder/*.h; do
    name=$(basename "$header")
    [ -n "${layer[$name]:-}" ] && continue
    sources=(src/*/"${name%.h}.cpp")
    if [ ! -f "${sources[0]}" ] || [ ${#sources[@]} -ne 1 ]; then
        fail "$header: expected exactly one source src/<layer>/${name%.h}.cpp"
        continue
    fi
    dir=$(basename "$(dirname "${sources[0]}")")
    layer[$name]=${layer_of_dir[$dir]:?unknown layer folder $dir}
done

check_file() {  # file, its layer
    local file="$1" own="$2" kind name l what
    # Each include of a library header: "public NAME" (animorder/NAME) or "private DIR" (../DIR/x.h).
    while read -r kind name; do
        if [ "$kind" = public ]; then
            l="${layer[$name]:-}" what="animorder/$name"
        else
            l="${layer_of_dir[$name]:-}" what="a private header of src/$name"
        fi
        if [ -z "$l" ]; then fail "$file includes $what, which is in no layer"; continue; fi
        [ "$l" -le "$own" ] || fail "$file (layer $own) includes $what (layer $l)"
    done < <(sed -n -e 's|^#include "animorder/\([^"]*\)".*|public \1|p' \
                    -e 's|^#include "\.\./\([a-z_]*\)/[^"]*".*|private \1|p' "$file")
    if [ "$own" -lt "$io_layer" ] && grep -qE '^#include [<"](tiny_gltf|assimp/|CLI/|nlohmann/|stb_)' "$file"; then
        fail "$file (layer $own) includes a file-format, JSON or CLI header"
    fi
}
for dir in "${!layer_of_dir[@]}"; do
    for file in src/"$dir"/*.cpp src/"$dir"/*.h; do
        [ -f "$file" ] && check_file "$file" "${layer_of_dir[$dir]}"
    done
done
for header in include/animorder/*.h; do check_file "$header" "${layer[$(basename "$header")]}"; done

if [ "$failures" -gt 0 ]; then
    echo "check-layers: $failures violation(s)" >&2
    exit 1
fi
echo "check-layers: ${#layer[@]} public headers, every include goes down the layers"
