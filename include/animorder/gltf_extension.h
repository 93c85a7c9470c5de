// animorder — the ANIMORDER_animated_triangle_orders glTF extension read back and checked
// (gltf_extension.cpp; the format: docs/extension/README.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace animorder {

inline const char* const kOrdersExtensionName = "ANIMORDER_animated_triangle_orders";

struct ExtensionClip {
    std::string name;
    int animation = -1;  // −1 when absent
    double start_time = 0;
    double sample_rate = 0;
    uint32_t keyframes = 0, buffer_base = 0, theta_steps = 0, phi_steps = 0;
    int table_accessor = -1, centers_accessor = -1;
    std::vector<uint8_t> cells;  // keyframes × theta_steps × phi_steps
    std::vector<float> centers;  // 3 per keyframe
};

struct ExtensionPrimitive {
    int mesh = -1, primitive = -1;
    int orders_accessor = -1;
    int component_type = 0;         // 5123 or 5125
    std::vector<uint32_t> indices;  // the primitive's `indices` (n)
    std::vector<uint32_t> orders;   // order_count × n, order after order
    uint32_t order_count = 0;
    bool indices_equal_fallback = false;
    std::vector<bool> order_is_permutation;  // per order: the triangles of `indices`, windings kept
};

// What `animorder check` reports. `present`: the root object is there (else nothing else is
// filled). `errors`: every problem found, one line each; empty means the file's orders are usable.
struct OrdersExtensionCheck {
    bool present = false;
    std::string method;
    uint32_t buffer_count = 0, fallback = 0;
    std::vector<ExtensionClip> clips;
    std::vector<ExtensionPrimitive> primitives;
    // Triangle primitives without orders (a tool dropped them, say): drawn in their file order.
    struct Unordered {
        int mesh = -1, primitive = -1;
        size_t triangles = 0;
    };
    std::vector<Unordered> without_orders;
    std::vector<std::string> errors;
};

// Reads the glTF file and checks its extension objects: every accessor index, type, component
// type, count and byte range; orderCount = bufferCount; fallback and every bufferBase + cell below
// bufferCount; `indices` equal to order `fallback`; every order a permutation of the primitive's
// triangles with their winding kept; tables covering every clip's keyframes (and the animation's
// time range when the clip names one). Throws LoadError only when the file is no readable glTF.
OrdersExtensionCheck check_orders_extension(const std::string& path);

// check_orders_extension, throwing LoadError("<path>: <first problem>") unless the orders are
// usable (including when the file has no extension): the loader path of every command that uses
// a file's orders.
OrdersExtensionCheck read_orders_extension(const std::string& path);

// The orders of one primitive of a file to be written: order_count orders of the primitive's own
// vertex indices, order after order.
struct PrimitiveOrders {
    int mesh = -1, primitive = -1;
    std::vector<uint32_t> orders;
};

// The glTF file `input_path` with the extension written from `root` (its method, buffer count,
// fallback and clips with cells and centres) and `primitives` (each primitive's `indices` becomes
// a copy of order `root.fallback`); any earlier extension objects of the file are replaced, and
// what they and the new indices replace leaves the file as in gltf_with_orders (`note` the same).
// Buffers embedded, image URIs re-pointed from output_path's folder. GLB bytes when `binary`.
std::string gltf_with_extension_orders(const std::string& input_path, const std::string& output_path,
                                       const OrdersExtensionCheck& root, const std::vector<PrimitiveOrders>& primitives,
                                       bool binary, std::string* note = nullptr);

}  // namespace animorder
