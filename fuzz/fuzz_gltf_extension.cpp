// libFuzzer target: any bytes → a .glb or .gltf file → animorder::check_orders_extension, the
// reader of ANIMORDER_animated_triangle_orders that check, reapply and evaluate --stored use.
// LoadError (no readable glTF) is the expected answer; every other problem must come back as a
// line in `errors`, never as a crash. Seeds: fuzz/corpus/gltf_extension/ (the spec's example).
#include "loader_target.h"

#include "animorder/gltf_extension.h"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const std::string path = animorder_fuzz::write_input(data, size, binary ? "input.glb" : "input.gltf");
    try {
        const animorder::OrdersExtensionCheck r = animorder::check_orders_extension(path);
        // Whatever it accepted must be self-consistent.
        if (r.errors.empty())
            for (const animorder::ExtensionPrimitive& p : r.primitives)
                if (p.orders.size() != size_t(p.order_count) * p.indices.size()) std::abort();
    } catch (const animorder::LoadError&) {}
    return 0;
}
