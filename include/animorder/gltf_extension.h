// animorder — the ANIMORDER_animated_triangle_orders glTF extension read back and checked
// (gltf_extension.cpp; the format: docs/extension/README.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace animorder {

inline const char* const kOrdersExtensionName = "ANIMORDER_animated_triangle_orders";

// A read-only array that copies share: the clips that name one table accessor, the primitives that
// name one orders accessor, hold one copy of its values (a small file can name one accessor
// thousands of times). Reads like a const std::vector.
template <class T>
class SharedArray {
public:
    using value_type = T;
    using const_iterator = typename std::vector<T>::const_iterator;
    using iterator = const_iterator;
    SharedArray() = default;
    SharedArray(std::vector<T> values) : values_(std::make_shared<const std::vector<T>>(std::move(values))) {}
    const std::vector<T>& get() const {
        static const std::vector<T> none;
        return values_ ? *values_ : none;
    }
    size_t size() const { return get().size(); }
    bool empty() const { return get().empty(); }
    const T* data() const { return get().data(); }
    const_iterator begin() const { return get().begin(); }
    const_iterator end() const { return get().end(); }
    const T& operator[](size_t i) const { return get()[i]; }
    friend bool operator==(const SharedArray& a, const std::vector<T>& b) { return a.get() == b; }
    friend bool operator==(const SharedArray& a, const SharedArray& b) { return a.get() == b.get(); }
    friend bool operator!=(const SharedArray& a, const std::vector<T>& b) { return a.get() != b; }
    friend bool operator!=(const SharedArray& a, const SharedArray& b) { return a.get() != b.get(); }

private:
    std::shared_ptr<const std::vector<T>> values_;
};

// `text` with every control byte (below 0x20, and 0x7f) written as \xNN and backslashes doubled:
// a name from a file quoted in a one-line message.
std::string printable(const std::string& text);

struct ExtensionClip {
    std::string name;
    int animation = -1;  // −1 when absent
    double start_time = 0;
    double sample_rate = 0;
    uint32_t keyframes = 0, buffer_base = 0, theta_steps = 0, phi_steps = 0;
    int table_accessor = -1, centers_accessor = -1;
    SharedArray<uint8_t> cells;  // keyframes × theta_steps × phi_steps
    SharedArray<float> centers;  // 3 per keyframe
};

struct ExtensionPrimitive {
    int mesh = -1, primitive = -1;
    int orders_accessor = -1;
    int component_type = 0;         // 5123 or 5125
    SharedArray<uint32_t> indices;  // the primitive's `indices` (n)
    SharedArray<uint32_t> orders;   // order_count × n, order after order
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
    // The work the checks may cost (8 × the bytes of the file's buffers + 2^20, VALIDITY.md), and
    // the vertices and indices posing the file costs the loader: each node's mesh's primitives'
    // POSITION and `indices` counts (a small file whose nodes or primitives share one large
    // accessor poses far more than it holds; check then leaves its centres unchecked).
    uint64_t work_budget = 0, posed_elements = 0;
};

// Reads the glTF file and checks its extension objects by the rules of docs/extension/VALIDITY.md:
// every accessor index, type, component type, count, stride and byte range; orderCount =
// bufferCount; fallback and every bufferBase + cell below bufferCount; finite centres; `indices`
// equal to order `fallback`; every order a permutation of the primitive's triangles with their
// winding kept; tables covering every clip's keyframes (and the animation's time range when the
// clip names one). Each accessor is read once however many clips or primitives name it, each
// (orders, indices) pair compared once, and the whole costs at most a multiple of the file's buffer
// bytes (else one problem says so). Throws LoadError only when the file is no readable glTF.
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
