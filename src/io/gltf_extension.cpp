// The ANIMORDER_animated_triangle_orders extension read back, every reference and size checked
// against the file before anything is read (docs/extension/README.md), and written into a file.
#include "animorder/gltf_extension.h"

#include "animorder/load.h"
#include "animorder/triangle_matching.h"

#include "checked_size.h"
#include "gltf_buffer.h"
#include "gltf_prune.h"

#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace animorder {
namespace {

using Object = tinygltf::Value::Object;

// The problems found so far; reading stops at the first problem of an object that later checks
// depend on.
struct Problems {
    std::vector<std::string>& list;
    void add(const std::string& what) { list.push_back(what); }
};

// The bytes of accessor `index` as `count` tightly read elements of `element` bytes, or an error
// (non-empty) naming what is wrong. Sparse accessors and accessors without a view are refused:
// the extension's accessors are plain arrays.
std::string accessor_bytes(const tinygltf::Model& model, int index, int type, const std::vector<int>& components,
                           const std::string& what, std::vector<unsigned char>& out, int& component_type) {
    const std::string name = what + " (accessor " + std::to_string(index) + ")";
    if (index < 0 || size_t(index) >= model.accessors.size())
        return what + ": accessor " + std::to_string(index) + " does not exist";
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    if (a.type != type)
        return name + " has the wrong type (expected " + (type == TINYGLTF_TYPE_VEC3 ? "VEC3" : "SCALAR") + ")";
    if (std::find(components.begin(), components.end(), a.componentType) == components.end())
        return name + " has component type " + std::to_string(a.componentType) + ", not one the extension allows";
    if (a.normalized) return name + " is normalized";
    if (a.sparse.isSparse) return name + " is sparse";
    if (a.bufferView < 0 || size_t(a.bufferView) >= model.bufferViews.size()) return name + " has no valid buffer view";
    const tinygltf::BufferView& v = model.bufferViews[size_t(a.bufferView)];
    if (v.buffer < 0 || size_t(v.buffer) >= model.buffers.size()) return name + "'s buffer view names no buffer";
    const std::vector<unsigned char>& data = model.buffers[size_t(v.buffer)].data;
    const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)));
    const size_t element = size * size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
    const size_t stride = v.byteStride ? v.byteStride : element;
    size_t view_end = 0, last = 0, end = 0;
    if (stride < element || !io::checked_add(v.byteOffset, v.byteLength, view_end) || view_end > data.size())
        return name + "'s buffer view lies outside its buffer";
    if (a.count == 0) {
        out.clear();
        component_type = a.componentType;
        return "";
    }
    if (!io::checked_mul(a.count - 1, stride, last) || !io::checked_add(last, element, end) ||
        !io::checked_add(end, a.byteOffset, end) || end > v.byteLength)
        return name + " has " + std::to_string(a.count) + " elements, more than its buffer view holds";
    out.resize(a.count * element);
    const unsigned char* base = data.data() + v.byteOffset + a.byteOffset;
    for (size_t i = 0; i < a.count; ++i) std::memcpy(out.data() + i * element, base + i * stride, element);
    component_type = a.componentType;
    return "";
}

std::string read_indices(const tinygltf::Model& model, int index, const std::string& what, std::vector<uint32_t>& out,
                         int& component_type) {
    std::vector<unsigned char> bytes;
    const std::string error =
        accessor_bytes(model, index, TINYGLTF_TYPE_SCALAR,
                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                       what, bytes, component_type);
    if (!error.empty()) return error;
    const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(component_type)));
    out.resize(bytes.size() / size);
    for (size_t i = 0; i < out.size(); ++i) {
        uint32_t v = 0;
        for (size_t b = 0; b < size; ++b) v |= uint32_t(bytes[i * size + b]) << (8 * b);
        out[i] = v;
    }
    return "";
}

// An integer member (JSON numbers that are whole), or false.
bool integer(const Object& o, const char* key, int64_t& out) {
    const auto it = o.find(key);
    if (it == o.end()) return false;
    if (it->second.IsInt()) {
        out = it->second.GetNumberAsInt();
        return true;
    }
    if (it->second.IsNumber()) {
        const double d = it->second.GetNumberAsDouble();
        if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9e15) {
            out = int64_t(d);
            return true;
        }
    }
    return false;
}

bool number(const Object& o, const char* key, double& out) {
    const auto it = o.find(key);
    if (it == o.end() || !it->second.IsNumber()) return false;
    out = it->second.GetNumberAsDouble();
    return std::isfinite(out);
}

// A required integer in [low, high]; adds a problem and returns false otherwise.
bool bounded(const Object& o, const char* key, int64_t low, int64_t high, const std::string& where, Problems& p,
             int64_t& out) {
    if (!integer(o, key, out)) {
        p.add(where + "." + key + " is missing or not an integer");
        return false;
    }
    if (out < low || out > high) {
        p.add(where + "." + key + " = " + std::to_string(out) + " is out of range [" + std::to_string(low) + ", " +
              std::to_string(high) + "]");
        return false;
    }
    return true;
}

void read_clip(const tinygltf::Model& model, const tinygltf::Value& value, size_t c, uint32_t buffer_count, Problems& p,
               std::vector<ExtensionClip>& clips) {
    const std::string where = "clips[" + std::to_string(c) + "]";
    if (!value.IsObject()) return p.add(where + " is not an object");
    const Object& o = value.Get<Object>();
    ExtensionClip clip;
    if (o.count("name") && o.at("name").IsString()) clip.name = o.at("name").Get<std::string>();
    int64_t v = 0;
    if (o.count("animation")) {
        if (!bounded(o, "animation", 0, int64_t(model.animations.size()) - 1, where, p, v)) return;
        clip.animation = int(v);
        // The clip's name is its animation's (an unnamed one's "animationN", as the loader names
        // it): the runtime and reapply find a clip's table by name, so a name of another
        // animation would put one clip's table on another.
        const std::string& own = model.animations[size_t(v)].name;
        const std::string expected = own.empty() ? "animation" + std::to_string(v) : own;
        if (o.count("name") && clip.name != expected)
            return p.add(where + ".name '" + clip.name + "' is not the name of animation " + std::to_string(v) + " ('" +
                         expected + "')");
    }
    if (o.count("startTime") && !number(o, "startTime", clip.start_time))
        return p.add(where + ".startTime is not a finite number");
    // Positive as the runtimes keep it too (a float: 1e-300 is 0 there).
    if (!number(o, "sampleRate", clip.sample_rate) || !(clip.sample_rate > 0) || !(float(clip.sample_rate) > 0) ||
        !std::isfinite(float(clip.sample_rate)))
        return p.add(where + ".sampleRate is missing or not a positive number a 32-bit float holds (from about "
                             "1.2e-38 to 3.4e38)");
    bool ok = bounded(o, "keyframes", 1, 100000, where, p, v);
    clip.keyframes = uint32_t(v);
    ok = bounded(o, "thetaSteps", 2, 100000, where, p, v) && ok;
    clip.theta_steps = uint32_t(v);
    ok = bounded(o, "phiSteps", 1, 100000, where, p, v) && ok;
    clip.phi_steps = uint32_t(v);
    ok = bounded(o, "bufferBase", 0, int64_t(buffer_count) - 1, where, p, v) && ok;
    clip.buffer_base = uint32_t(v);
    ok = bounded(o, "table", 0, INT32_MAX, where, p, v) && ok;
    clip.table_accessor = int(v);
    ok = bounded(o, "centers", 0, INT32_MAX, where, p, v) && ok;
    clip.centers_accessor = int(v);
    if (!ok) return;
    std::vector<unsigned char> bytes;
    int component = 0;
    std::string error = accessor_bytes(model, clip.table_accessor, TINYGLTF_TYPE_SCALAR,
                                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE}, where + ".table", bytes, component);
    if (!error.empty()) return p.add(error);
    const uint64_t cells = uint64_t(clip.keyframes) * clip.theta_steps * clip.phi_steps;
    if (bytes.size() != cells)
        return p.add(where + ".table has " + std::to_string(bytes.size()) +
                     " cells; keyframes x thetaSteps x phiSteps = " + std::to_string(cells));
    clip.cells.assign(bytes.begin(), bytes.end());
    for (size_t i = 0; i < clip.cells.size(); ++i)
        if (uint64_t(clip.buffer_base) + clip.cells[i] >= buffer_count)
            return p.add(where + ".table cell " + std::to_string(i) + " names order " +
                         std::to_string(clip.buffer_base + clip.cells[i]) + ", not below bufferCount " +
                         std::to_string(buffer_count));
    error = accessor_bytes(model, clip.centers_accessor, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT},
                           where + ".centers", bytes, component);
    if (!error.empty()) return p.add(error);
    if (bytes.size() != size_t(clip.keyframes) * 12)
        return p.add(where + ".centers has " + std::to_string(bytes.size() / 12) +
                     " elements, not keyframes = " + std::to_string(clip.keyframes));
    clip.centers.resize(bytes.size() / 4);
    std::memcpy(clip.centers.data(), bytes.data(), bytes.size());
    for (float f : clip.centers)
        if (!std::isfinite(f)) return p.add(where + ".centers holds a value that is not finite");
    // The table covers the animation's time range: keyframe f at startTime + f / sampleRate. The
    // key times as the loader and the engines read them, the data (an accessor's declared min and
    // max may disagree with it; they stand in only for keys this check cannot read: sparse ones).
    if (clip.animation >= 0) {
        const tinygltf::Animation& anim = model.animations[size_t(clip.animation)];
        double t0 = INFINITY, t1 = -INFINITY;
        for (const tinygltf::AnimationSampler& s : anim.samplers) {
            if (s.input < 0 || size_t(s.input) >= model.accessors.size()) continue;
            const tinygltf::Accessor& in = model.accessors[size_t(s.input)];
            std::vector<unsigned char> keys;
            int key_type = 0;
            if (accessor_bytes(model, s.input, TINYGLTF_TYPE_SCALAR, {TINYGLTF_COMPONENT_TYPE_FLOAT}, "", keys,
                               key_type)
                    .empty()) {
                for (size_t k = 0; k + 4 <= keys.size(); k += 4) {
                    float t;
                    std::memcpy(&t, keys.data() + k, 4);
                    t0 = std::min(t0, double(t)), t1 = std::max(t1, double(t));
                }
            } else if (in.minValues.size() == 1 && in.maxValues.size() == 1) {
                t0 = std::min(t0, in.minValues[0]), t1 = std::max(t1, in.maxValues[0]);
            }
        }
        if (t0 <= t1) {
            const double step = 1.0 / clip.sample_rate;
            if (std::fabs(clip.start_time - t0) > 0.5 * step)
                p.add(where + ".startTime " + std::to_string(clip.start_time) + " is not animation " +
                      std::to_string(clip.animation) + "'s first key time " + std::to_string(t0));
            else if (clip.start_time + (clip.keyframes - 1) * step < t1 - step - 1e-6)
                p.add(where + " has " + std::to_string(clip.keyframes) + " keyframes; animation " +
                      std::to_string(clip.animation) + " lasts to " + std::to_string(t1) + " s and needs " +
                      std::to_string(size_t(std::floor((t1 - clip.start_time) * clip.sample_rate + 1e-9)) + 1));
        }
    }
    clips.push_back(std::move(clip));
}

void read_primitive(const tinygltf::Model& model, size_t m, size_t pi, const Object& o,
                    const OrdersExtensionCheck& root, Problems& p, std::vector<ExtensionPrimitive>& out) {
    const std::string where = "meshes[" + std::to_string(m) + "].primitives[" + std::to_string(pi) + "]";
    const tinygltf::Primitive& prim = model.meshes[m].primitives[pi];
    ExtensionPrimitive e;
    e.mesh = int(m), e.primitive = int(pi);
    int64_t v = 0;
    bool ok = bounded(o, "orders", 0, INT32_MAX, where, p, v);
    e.orders_accessor = int(v);
    ok = bounded(o, "orderCount", 1, INT32_MAX, where, p, v) && ok;
    e.order_count = uint32_t(v);
    if (!ok) return;
    if (e.order_count != root.buffer_count)
        return p.add(where + ".orderCount " + std::to_string(e.order_count) + " differs from bufferCount " +
                     std::to_string(root.buffer_count));
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) return p.add(where + " is not a TRIANGLES primitive");
    int component = 0;
    std::string error = read_indices(model, prim.indices, where + ".indices", e.indices, component);
    if (!error.empty()) return p.add(error);
    error = read_indices(model, e.orders_accessor, where + ".orders", e.orders, e.component_type);
    if (!error.empty()) return p.add(error);
    if (e.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return p.add(where + ".orders is UNSIGNED_BYTE");
    const size_t n = e.indices.size();
    if (n % 3 != 0) return p.add(where + ".indices holds " + std::to_string(n) + " indices, not whole triangles");
    if (e.orders.size() != n * e.order_count)
        return p.add(where + ".orders has " + std::to_string(e.orders.size()) +
                     " elements; orderCount x indices = " + std::to_string(n * e.order_count));
    e.indices_equal_fallback =
        std::equal(e.indices.begin(), e.indices.end(), e.orders.begin() + ptrdiff_t(root.fallback * n));
    if (!e.indices_equal_fallback)
        p.add(where + ".indices differs from order " + std::to_string(root.fallback) + " (fallback)");
    for (uint32_t b = 0; b < e.order_count; ++b) {
        const bool permutation =
            !triangle_permutation(e.indices.data(), e.orders.data() + b * n, n / 3).empty() || n == 0;
        e.order_is_permutation.push_back(permutation);
        if (!permutation)
            p.add(where + " order " + std::to_string(b) +
                  " is not a permutation of the primitive's triangles with their winding (stale orders?)");
    }
    out.push_back(std::move(e));
}

// Integers of the extension's JSON beyond what tinygltf keeps: it holds a JSON integer as an int
// (32 bits), so 2^32 + 5 would read as 5 and pass. Each one found is a problem, quoted as written.
void add_wrapped_integers(const nlohmann::json& value, const std::string& where, Problems& p) {
    if (value.is_object()) {
        for (auto it = value.begin(); it != value.end(); ++it)
            add_wrapped_integers(it.value(), where + "." + it.key(), p);
    } else if (value.is_array()) {
        for (size_t i = 0; i < value.size(); ++i)
            add_wrapped_integers(value[i], where + "[" + std::to_string(i) + "]", p);
    } else if (value.is_number_unsigned() ? value.get<uint64_t>() > uint64_t(INT32_MAX)
                                          : value.is_number_integer() && value.get<int64_t>() < INT32_MIN) {
        p.add(where + " = " + value.dump() + " is out of range (an integer here is below 2^31)");
    }
}

// What tinygltf's model hides, checked on the JSON as the file writes it: integers it wraps
// (add_wrapped_integers over the extension's root and every primitive's object), a clip it drops,
// offsets it wraps or truncates.
void check_json_as_written(const std::string& path, Problems& p) {
    const nlohmann::json doc = nlohmann::json::parse(io::gltf_json_text(path), nullptr, false);
    if (!doc.is_object()) return;
    const auto extension_of = [](const nlohmann::json& owner) -> const nlohmann::json* {
        if (!owner.is_object() || !owner.contains("extensions") || !owner["extensions"].is_object()) return nullptr;
        const auto e = owner["extensions"].find(kOrdersExtensionName);
        return e == owner["extensions"].end() ? nullptr : &*e;
    };
    if (const nlohmann::json* e = extension_of(doc)) {
        add_wrapped_integers(*e, kOrdersExtensionName, p);
        // tinygltf drops a null from an array: clip numbers would shift silently.
        if (e->is_object() && e->contains("clips") && (*e)["clips"].is_array())
            for (size_t c = 0; c < (*e)["clips"].size(); ++c)
                if (!(*e)["clips"][c].is_object()) p.add("clips[" + std::to_string(c) + "] is not an object");
    }
    // Offsets tinygltf reads as it can (a negative one wraps, a fractional one truncates): where
    // the orders, tables and centres lie must be what the file says.
    for (const char* list : {"accessors", "bufferViews"})
        if (doc.contains(list) && doc[list].is_array())
            for (size_t i = 0; i < doc[list].size(); ++i) {
                const nlohmann::json& item = doc[list][i];
                if (item.is_object() && item.contains("byteOffset") && !item["byteOffset"].is_number_unsigned() &&
                    !(item["byteOffset"].is_number_integer() && item["byteOffset"].get<int64_t>() >= 0))
                    p.add(std::string(list) + "[" + std::to_string(i) + "].byteOffset " + item["byteOffset"].dump() +
                          " is not a non-negative integer");
            }
    if (!doc.contains("meshes") || !doc["meshes"].is_array()) return;
    for (size_t m = 0; m < doc["meshes"].size(); ++m) {
        const nlohmann::json& mesh = doc["meshes"][m];
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
        for (size_t q = 0; q < mesh["primitives"].size(); ++q)
            if (const nlohmann::json* e = extension_of(mesh["primitives"][q]))
                add_wrapped_integers(*e, "mesh " + std::to_string(m) + " primitive " + std::to_string(q), p);
    }
}

}  // namespace

OrdersExtensionCheck check_orders_extension(const std::string& path) {
    const tinygltf::Model model = io::read_model(path);
    OrdersExtensionCheck r;
    Problems p{r.errors};
    const auto root = model.extensions.find(kOrdersExtensionName);
    if (root == model.extensions.end()) {
        p.add(std::string("no ") + kOrdersExtensionName + " extension (not written by animorder optimize, or removed)");
        return r;
    }
    r.present = true;
    check_json_as_written(path, p);
    if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), kOrdersExtensionName) ==
        model.extensionsUsed.end())
        p.add(std::string(kOrdersExtensionName) + " is not listed in extensionsUsed");
    if (std::find(model.extensionsRequired.begin(), model.extensionsRequired.end(), kOrdersExtensionName) !=
        model.extensionsRequired.end())
        p.add(std::string(kOrdersExtensionName) + " must not be listed in extensionsRequired");
    if (!root->second.IsObject()) {
        p.add("the root extension object is not an object");
        return r;
    }
    const Object& o = root->second.Get<Object>();
    if (o.count("method") && o.at("method").IsString())
        r.method = o.at("method").Get<std::string>();
    else if (o.count("method"))
        p.add("root.method is not a string");
    int64_t v = 0;
    if (!bounded(o, "bufferCount", 1, 65536, "root", p, v)) return r;
    r.buffer_count = uint32_t(v);
    if (!bounded(o, "fallback", 0, int64_t(r.buffer_count) - 1, "root", p, v)) return r;
    r.fallback = uint32_t(v);
    const auto clips = o.find("clips");
    if (clips == o.end() || !clips->second.IsArray() || clips->second.ArrayLen() == 0)
        p.add("root.clips is missing or empty");
    else
        for (size_t c = 0; c < clips->second.ArrayLen(); ++c)
            read_clip(model, clips->second.Get(int(c)), c, r.buffer_count, p, r.clips);
    for (size_t m = 0; m < model.meshes.size(); ++m)
        for (size_t pi = 0; pi < model.meshes[m].primitives.size(); ++pi) {
            const tinygltf::Primitive& prim = model.meshes[m].primitives[pi];
            const auto e = prim.extensions.find(kOrdersExtensionName);
            if (e == prim.extensions.end()) {  // drawn in its file order: said, not an error
                if (prim.mode == TINYGLTF_MODE_TRIANGLES || prim.mode == -1) {
                    const bool indexed = prim.indices >= 0 && size_t(prim.indices) < model.accessors.size();
                    const auto position = prim.attributes.find("POSITION");
                    const int counted = indexed                             ? prim.indices
                                        : position != prim.attributes.end() ? position->second
                                                                            : -1;
                    const size_t count = counted >= 0 && size_t(counted) < model.accessors.size()
                                             ? model.accessors[size_t(counted)].count
                                             : 0;
                    r.without_orders.push_back({int(m), int(pi), count / 3});
                }
                continue;
            }
            if (!e->second.IsObject()) {
                p.add("meshes[" + std::to_string(m) + "].primitives[" + std::to_string(pi) +
                      "] extension is not an object");
                continue;
            }
            read_primitive(model, m, pi, e->second.Get<Object>(), r, p, r.primitives);
        }
    if (r.primitives.empty() && r.errors.empty()) p.add("no primitive carries the orders");
    return r;
}

OrdersExtensionCheck read_orders_extension(const std::string& path) {
    OrdersExtensionCheck r = check_orders_extension(path);
    if (!r.errors.empty()) throw LoadError(path + ": " + r.errors.front());
    return r;
}

namespace {

int append_indices(tinygltf::Model& model, const std::vector<uint32_t>& local, bool shorts, const std::string& name) {
    int view;
    if (shorts) {
        std::vector<uint16_t> s(local.begin(), local.end());
        view = io::append_buffer_view(model, s.data(), s.size() * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    } else {
        view = io::append_buffer_view(model, local.data(), local.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    }
    const int a = io::append_accessor(
        model, view, shorts ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
        TINYGLTF_TYPE_SCALAR, local.size(), name);
    if (!local.empty()) {
        model.accessors[size_t(a)].minValues = {double(*std::min_element(local.begin(), local.end()))};
        model.accessors[size_t(a)].maxValues = {double(*std::max_element(local.begin(), local.end()))};
    }
    return a;
}

// The processed file's animation for a clip of the optimised one: the animation of the clip's
// name there (an unnamed one is "animationN", as the loader names clips). Where several clips share
// the name (Mixamo's "mixamo.com"), the n-th of them follows the n-th animation of that name, when
// the processed file has as many; else it is ambiguous (-2). -1 when none has the name. Pipelines
// drop, reorder and rename animations, so an index copied as it was could name another animation.
int animation_of_clip(const tinygltf::Model& model, const std::vector<ExtensionClip>& clips, const ExtensionClip& c) {
    std::vector<int> theirs;
    for (size_t a = 0; a < model.animations.size(); ++a) {
        const std::string& own = model.animations[a].name;
        if ((own.empty() ? "animation" + std::to_string(a) : own) == c.name) theirs.push_back(int(a));
    }
    size_t rank = 0, ours = 0;
    for (const ExtensionClip& o : clips)
        if (o.name == c.name) rank += &o < &c, ++ours;
    if (theirs.empty()) return -1;
    return ours == theirs.size() ? theirs[rank] : -2;
}

}  // namespace

std::string gltf_with_extension_orders(const std::string& input_path, const std::string& output_path,
                                       const OrdersExtensionCheck& root, const std::vector<PrimitiveOrders>& primitives,
                                       bool binary, std::string* note) {
    tinygltf::Model model = io::read_model(input_path);
    if (root.buffer_count == 0 || root.fallback >= root.buffer_count)
        throw LoadError(input_path + ": no fallback order");
    std::vector<std::pair<int, int>> rewritten;
    for (const PrimitiveOrders& po : primitives) rewritten.emplace_back(po.mesh, po.primitive);
    const std::vector<int> replaced = io::begin_replacing(model, rewritten);
    for (const PrimitiveOrders& po : primitives) {
        if (po.mesh < 0 || size_t(po.mesh) >= model.meshes.size() || po.primitive < 0 ||
            size_t(po.primitive) >= model.meshes[size_t(po.mesh)].primitives.size())
            throw LoadError(input_path + ": no primitive " + std::to_string(po.mesh) + "/" +
                            std::to_string(po.primitive));
        if (po.orders.size() % (3 * size_t(root.buffer_count)) != 0)
            throw LoadError(input_path + ": orders of primitive " + std::to_string(po.mesh) + "/" +
                            std::to_string(po.primitive) + " are not whole triangles");
        tinygltf::Primitive& prim = model.meshes[size_t(po.mesh)].primitives[size_t(po.primitive)];
        const size_t n = po.orders.size() / root.buffer_count;
        const bool shorts = po.orders.empty() || *std::max_element(po.orders.begin(), po.orders.end()) < 65535;
        const int orders = append_indices(model, po.orders, shorts, "animorder orders");
        const std::vector<uint32_t> shown(po.orders.begin() + ptrdiff_t(root.fallback * n),
                                          po.orders.begin() + ptrdiff_t((root.fallback + 1) * n));
        prim.indices = append_indices(model, shown, shorts, "animorder fallback order");
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        Object ours;
        ours["orders"] = tinygltf::Value(orders);
        ours["orderCount"] = tinygltf::Value(int(root.buffer_count));
        prim.extensions[kOrdersExtensionName] = tinygltf::Value(ours);
    }
    tinygltf::Value::Array clips;
    for (const ExtensionClip& c : root.clips) {
        const int cells = io::append_accessor(model, io::append_buffer_view(model, c.cells.data(), c.cells.size(), 0),
                                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_SCALAR,
                                              c.cells.size(), "animorder table " + c.name);
        const int centers = io::append_accessor(
            model, io::append_buffer_view(model, c.centers.data(), c.centers.size() * 4, 0),
            TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, c.centers.size() / 3, "animorder centres " + c.name);
        Object clip;
        clip["name"] = tinygltf::Value(c.name);
        if (c.animation >= 0) {
            const int animation = animation_of_clip(model, root.clips, c);
            if (animation == -2)
                throw LoadError(input_path + ": the optimised file has clips named '" + c.name +
                                "' that the processed file has other numbers of animations of: it dropped some, "
                                "and which lookup table follows which animation cannot be told");
            if (animation < 0)
                throw LoadError(input_path + ": no animation '" + c.name + "' (the optimised file's clip " +
                                std::to_string(&c - root.clips.data()) +
                                "): the processed file dropped or renamed it, so its lookup table has no clip to "
                                "follow");
            clip["animation"] = tinygltf::Value(animation);
        }
        clip["startTime"] = tinygltf::Value(c.start_time);
        clip["sampleRate"] = tinygltf::Value(c.sample_rate);
        clip["keyframes"] = tinygltf::Value(int(c.keyframes));
        clip["bufferBase"] = tinygltf::Value(int(c.buffer_base));
        clip["thetaSteps"] = tinygltf::Value(int(c.theta_steps));
        clip["phiSteps"] = tinygltf::Value(int(c.phi_steps));
        clip["table"] = tinygltf::Value(cells);
        clip["centers"] = tinygltf::Value(centers);
        clips.push_back(tinygltf::Value(clip));
    }
    Object r;
    if (!root.method.empty()) r["method"] = tinygltf::Value(root.method);
    r["bufferCount"] = tinygltf::Value(int(root.buffer_count));
    r["fallback"] = tinygltf::Value(int(root.fallback));
    r["clips"] = tinygltf::Value(clips);
    model.extensions[kOrdersExtensionName] = tinygltf::Value(r);
    if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), kOrdersExtensionName) ==
        model.extensionsUsed.end())
        model.extensionsUsed.push_back(kOrdersExtensionName);
    model.extensionsRequired.erase(
        std::remove(model.extensionsRequired.begin(), model.extensionsRequired.end(), kOrdersExtensionName),
        model.extensionsRequired.end());
    const io::Renumbering renumbering =  // the processed file's indices, earlier orders
        io::finish_replacing(model, replaced, input_path, note);
    return io::write_model(model, input_path, output_path, binary, renumbering);
}

}  // namespace animorder
