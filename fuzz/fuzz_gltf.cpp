// libFuzzer target: any bytes → a .glb or .gltf file → animorder::load_gltf. load_gltf chooses
// binary or JSON by the "glTF" magic, not the name, so the file is named .glb when the bytes start
// with the magic and .gltf otherwise (one load per input instead of two identical ones).
#include "loader_target.h"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const std::string path = animorder_fuzz::write_input(data, size, binary ? "input.glb" : "input.gltf");
    animorder_fuzz::run_loader(
        [](const std::string& p, const animorder::LoadOptions& o) { return animorder::load_gltf(p, o); }, path);
    return 0;
}
