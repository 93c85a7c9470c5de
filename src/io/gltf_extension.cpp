// The ANIMORDER_animated_triangle_orders extension read back, every reference and size checked
// against the file before anything is read (docs/extension/README.md, the rules of
// docs/extension/VALIDITY.md), and written into a file.
#include "animorder/gltf_extension.h"

#include "animorder/load.h"
#include "animorder/triangle_matching.h"

#include "checked_size.h"
#include "gltf_buffer.h"
#include "gltf_prune.h"

#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>

namespace animorder {

std::string printable(const std::string& text) {
    std::string out;
    for (const char ch : text) {
        const unsigned char c = static_cast<unsigned char>(ch);
        if (c == '\\') {
            out += "\\\\";
        } else if (c < 0x20 || c == 0x7f) {
            const char* const hex = "0123456789abcdef";
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
        } else {
            out += ch;
        }
    }
    return out;
}

namespace {

using Object = tinygltf::Value::Object;

// The problems found so far; reading stops at the first problem of an object that later checks
// depend on.
struct Problems {
    std::vector<std::string>& list;
    void add(const std::string& what) { list.push_back(what); }
};

// One accessor as read the first time a clip or primitive named it: the problem (after the
// accessor's name), or its elements, tightly packed; and the forms its uses make of them, each
// made once.
struct Decoded {
    bool tried = false;
    std::string error;
    size_t count = 0;
    std::vector<unsigned char> bytes;
    bool has_values = false;  // indices and orders
    SharedArray<uint32_t> values;
    uint32_t largest = 0;
    bool has_cells = false;  // tables
    SharedArray<uint8_t> cells;
    std::array<size_t, 256> first_of_value{};  // SIZE_MAX: the value is not in the table
    bool has_floats = false;                   // centres
    SharedArray<float> floats;
    bool finite = true;
    bool has_range = false;  // key times
    double t0 = INFINITY, t1 = -INFINITY;
};

// Whether two orders of one primitive hold the same triangles, windings kept, for each
// (orders, indices) pair of accessors: compared once however many primitives share the pair.
struct PairVerdict {
    bool indices_equal_fallback = false;
    std::vector<bool> order_is_permutation;
};

// The triangles of `v` (3·count indices), each rotated so that its smallest corner comes first
// (the winding kept), sorted: two orders hold the same triangles when these are equal.
std::vector<std::array<uint32_t, 3>> sorted_triangles(const uint32_t* v, size_t count) {
    std::vector<std::array<uint32_t, 3>> t(count);
    for (size_t i = 0; i < count; ++i) {
        const uint32_t a = v[3 * i], b = v[3 * i + 1], c = v[3 * i + 2];
        t[i] = a <= b && a <= c ? std::array<uint32_t, 3>{a, b, c}
               : b <= c         ? std::array<uint32_t, 3>{b, c, a}
                                : std::array<uint32_t, 3>{c, a, b};
    }
    std::sort(t.begin(), t.end());
    return t;
}

// The accessors the extension names, each read and checked once, and the work all of it may
// cost (VALIDITY.md, "Work"): the elements of every distinct accessor read plus the orders of
// every distinct (orders, indices) pair compared, at most 8 × the bytes of the file's buffers
// + 2^20. Past that, one problem says so and every later read fails (`over`).
class Accessors {
public:
    Accessors(const tinygltf::Model& model, Problems& p) : model_(model), p_(p) {
        for (const tinygltf::Buffer& b : model.buffers) budget_ += 8 * uint64_t(b.data.size());
    }

    bool over() const { return over_; }
    uint64_t budget() const { return budget_; }

    // Adds `error` unless the budget ran out (then the one problem that says so stands for it).
    void report(const std::string& error) {
        if (!over_) p_.add(error);
    }

    // Accessor `index` as `type` of one of `components`, not normalized: "" and `out` the decoded
    // accessor, or the error (non-empty) naming what is wrong. Sparse accessors and accessors
    // without a view are refused: the extension's accessors are plain arrays.
    std::string get(int index, int type, const std::vector<int>& components, const std::string& what, Decoded*& out) {
        out = nullptr;
        const std::string name = what + " (accessor " + std::to_string(index) + ")";
        if (index < 0 || size_t(index) >= model_.accessors.size())
            return what + ": accessor " + std::to_string(index) + " does not exist";
        const tinygltf::Accessor& a = model_.accessors[size_t(index)];
        if (a.type != type)
            return name + " has the wrong type (expected " + (type == TINYGLTF_TYPE_VEC3 ? "VEC3" : "SCALAR") + ")";
        if (std::find(components.begin(), components.end(), a.componentType) == components.end())
            return name + " has component type " + std::to_string(a.componentType) + ", not one the extension allows";
        if (a.normalized) return name + " is normalized";
        Decoded& d = decoded_[index];
        if (!d.tried) {
            d.tried = true;
            d.error = decode(a, d);
        }
        if (!d.error.empty()) return name + d.error;
        out = &d;
        return "";
    }

    // The accessor's values as unsigned integers (indices, orders) and the largest of them.
    static void make_values(Decoded& d, int component_type) {
        if (d.has_values) return;
        d.has_values = true;
        const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(component_type)));
        std::vector<uint32_t> values(d.count);
        for (size_t i = 0; i < values.size(); ++i) {
            uint32_t v = 0;
            for (size_t b = 0; b < size; ++b) v |= uint32_t(d.bytes[i * size + b]) << (8 * b);
            values[i] = v;
            d.largest = std::max(d.largest, v);
        }
        d.values = SharedArray<uint32_t>(std::move(values));
    }

    // A table's cells, and where each value first occurs.
    static void make_cells(Decoded& d) {
        if (d.has_cells) return;
        d.has_cells = true;
        d.first_of_value.fill(SIZE_MAX);
        for (size_t i = d.bytes.size(); i-- > 0;) d.first_of_value[d.bytes[i]] = i;
        d.cells = SharedArray<uint8_t>(std::vector<uint8_t>(d.bytes.begin(), d.bytes.end()));
    }

    // Centres as floats, and whether every one is finite.
    static void make_floats(Decoded& d) {
        if (d.has_floats) return;
        d.has_floats = true;
        std::vector<float> floats(d.bytes.size() / 4);
        if (!floats.empty()) std::memcpy(floats.data(), d.bytes.data(), floats.size() * 4);
        for (const float f : floats) d.finite = d.finite && std::isfinite(f);
        d.floats = SharedArray<float>(std::move(floats));
    }

    // The key times of sampler input `index` as the loader and the engines read them, the data
    // (an accessor's declared min and max may disagree with it; they stand in only for keys this
    // check cannot read: sparse ones): widens [t0, t1].
    void widen_key_range(int index, double& t0, double& t1) {
        if (index < 0 || size_t(index) >= model_.accessors.size()) return;
        Decoded* d = nullptr;
        if (get(index, TINYGLTF_TYPE_SCALAR, {TINYGLTF_COMPONENT_TYPE_FLOAT}, "", d).empty()) {
            if (!d->has_range) {
                d->has_range = true;
                for (size_t k = 0; k + 4 <= d->bytes.size(); k += 4) {
                    float t;
                    std::memcpy(&t, d->bytes.data() + k, 4);
                    d->t0 = std::min(d->t0, double(t)), d->t1 = std::max(d->t1, double(t));
                }
            }
            t0 = std::min(t0, d->t0), t1 = std::max(t1, d->t1);
            return;
        }
        const tinygltf::Accessor& in = model_.accessors[size_t(index)];
        if (in.minValues.size() == 1 && in.maxValues.size() == 1)
            t0 = std::min(t0, in.minValues[0]), t1 = std::max(t1, in.maxValues[0]);
    }

    // The permutation verdicts of orders accessor `orders` (order_count × n values) against
    // indices accessor `indices` (n values, whole triangles), each pair compared once; null when
    // the budget ran out.
    const PairVerdict* pair(int orders, int indices, const Decoded& o, const Decoded& in, uint32_t order_count,
                            uint32_t fallback) {
        const auto key = std::make_pair(orders, indices);
        const auto found = pairs_.find(key);
        if (found != pairs_.end()) return &found->second;
        if (!charge(o.count)) return nullptr;
        PairVerdict& v = pairs_[key];
        const size_t n = in.count;
        const uint32_t* all = o.values.data();
        v.indices_equal_fallback = std::equal(in.values.begin(), in.values.end(), all + size_t(fallback) * n);
        const std::vector<std::array<uint32_t, 3>> base = sorted_triangles(in.values.data(), n / 3);
        for (uint32_t b = 0; b < order_count; ++b)
            v.order_is_permutation.push_back(sorted_triangles(all + size_t(b) * n, n / 3) == base);
        return &v;
    }

private:
    // Counts `elements` of work; false (with one problem said) once past the budget.
    bool charge(uint64_t elements) {
        if (over_) return false;
        if (elements > budget_ - used_) {
            over_ = true;
            p_.add("the extension asks for more work than its file's size allows: over " + std::to_string(budget_) +
                   " accessor elements read and compared (8 x the buffers' bytes + 2^20; accessors shared by "
                   "many clips or primitives?)");
            return false;
        }
        used_ += elements;
        return true;
    }

    std::string decode(const tinygltf::Accessor& a, Decoded& d) {
        if (a.sparse.isSparse) return " is sparse";
        if (a.bufferView < 0 || size_t(a.bufferView) >= model_.bufferViews.size()) return " has no valid buffer view";
        const tinygltf::BufferView& v = model_.bufferViews[size_t(a.bufferView)];
        if (v.buffer < 0 || size_t(v.buffer) >= model_.buffers.size()) return "'s buffer view names no buffer";
        const std::vector<unsigned char>& data = model_.buffers[size_t(v.buffer)].data;
        const size_t size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)));
        const size_t element = size * size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)));
        const size_t stride = v.byteStride ? v.byteStride : element;
        if (stride < element || stride % size != 0)
            return "'s buffer view has byteStride " + std::to_string(stride) + ", not a multiple of " +
                   std::to_string(size) + " of at least its element size " + std::to_string(element);
        size_t view_end = 0, last = 0, end = 0;
        if (!io::checked_add(v.byteOffset, v.byteLength, view_end) || view_end > data.size())
            return "'s buffer view lies outside its buffer";
        if (a.count > 0 && (!io::checked_mul(a.count - 1, stride, last) || !io::checked_add(last, element, end) ||
                            !io::checked_add(end, a.byteOffset, end) || end > v.byteLength))
            return " has " + std::to_string(a.count) + " elements, more than its buffer view holds";
        if (!charge(uint64_t(a.count) * uint64_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)))))
            return " was not read (the work cap)";
        d.count = a.count;
        d.bytes.resize(a.count * element);
        const unsigned char* base = data.data() + v.byteOffset + a.byteOffset;
        for (size_t i = 0; i < a.count; ++i) std::memcpy(d.bytes.data() + i * element, base + i * stride, element);
        return "";
    }

    const tinygltf::Model& model_;
    Problems& p_;
    uint64_t budget_ = uint64_t(1) << 20, used_ = 0;
    bool over_ = false;
    std::map<int, Decoded> decoded_;
    std::map<std::pair<int, int>, PairVerdict> pairs_;
};

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
               Accessors& accessors, std::vector<ExtensionClip>& clips) {
    const std::string where = "clips[" + std::to_string(c) + "]";
    if (!value.IsObject()) return p.add(where + " is not an object");
    const Object& o = value.Get<Object>();
    ExtensionClip clip;
    if (o.count("name") && !o.at("name").IsString()) return p.add(where + ".name is not a string");
    if (o.count("name")) clip.name = o.at("name").Get<std::string>();
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
            return p.add(where + ".name '" + printable(clip.name) + "' is not the name of animation " +
                         std::to_string(v) + " ('" + printable(expected) + "')");
    }
    if (o.count("startTime") && !number(o, "startTime", clip.start_time))
        return p.add(where + ".startTime is not a finite number");
    // Positive as the runtimes keep it too (a float: 1e-300 is 0 there).
    if (!number(o, "sampleRate", clip.sample_rate) || !(clip.sample_rate > 0) || !(float(clip.sample_rate) > 0) ||
        !std::isfinite(float(clip.sample_rate)))
        return p.add(where +
                     ".sampleRate is missing or not a positive number a 32-bit float holds (from about "
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
    Decoded* table = nullptr;
    std::string error = accessors.get(clip.table_accessor, TINYGLTF_TYPE_SCALAR,
                                      {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE}, where + ".table", table);
    if (!error.empty()) return accessors.report(error);
    const uint64_t cells = uint64_t(clip.keyframes) * clip.theta_steps * clip.phi_steps;
    if (table->count != cells)
        return p.add(where + ".table has " + std::to_string(table->count) +
                     " cells; keyframes x thetaSteps x phiSteps = " + std::to_string(cells));
    Accessors::make_cells(*table);
    clip.cells = table->cells;
    // The first cell naming an order past bufferCount: the first of any value that large.
    size_t first = SIZE_MAX;
    for (size_t value = buffer_count - clip.buffer_base; value < 256; ++value)
        first = std::min(first, table->first_of_value[value]);
    if (first != SIZE_MAX)
        return p.add(where + ".table cell " + std::to_string(first) + " names order " +
                     std::to_string(clip.buffer_base + clip.cells[first]) + ", not below bufferCount " +
                     std::to_string(buffer_count));
    Decoded* centers = nullptr;
    error = accessors.get(clip.centers_accessor, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT},
                          where + ".centers", centers);
    if (!error.empty()) return accessors.report(error);
    if (centers->count != clip.keyframes)
        return p.add(where + ".centers has " + std::to_string(centers->count) +
                     " elements, not keyframes = " + std::to_string(clip.keyframes));
    Accessors::make_floats(*centers);
    clip.centers = centers->floats;
    if (!centers->finite) return p.add(where + ".centers holds a value that is not finite");
    // The table covers the animation's time range: keyframe f at startTime + f / sampleRate.
    if (clip.animation >= 0) {
        const tinygltf::Animation& anim = model.animations[size_t(clip.animation)];
        double t0 = INFINITY, t1 = -INFINITY;
        for (const tinygltf::AnimationSampler& s : anim.samplers) accessors.widen_key_range(s.input, t0, t1);
        if (accessors.over()) return;
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
                    const OrdersExtensionCheck& root, Problems& p, Accessors& accessors,
                    std::vector<ExtensionPrimitive>& out) {
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
    const std::vector<int> unsigned_types = {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT};
    Decoded *indices = nullptr, *orders = nullptr;
    std::string error = accessors.get(prim.indices, TINYGLTF_TYPE_SCALAR, unsigned_types, where + ".indices", indices);
    if (!error.empty()) return accessors.report(error);
    error = accessors.get(e.orders_accessor, TINYGLTF_TYPE_SCALAR, unsigned_types, where + ".orders", orders);
    if (!error.empty()) return accessors.report(error);
    e.component_type = model.accessors[size_t(e.orders_accessor)].componentType;
    if (e.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return p.add(where + ".orders is UNSIGNED_BYTE");
    const size_t n = indices->count;
    if (n % 3 != 0) return p.add(where + ".indices holds " + std::to_string(n) + " indices, not whole triangles");
    if (orders->count != n * e.order_count)
        return p.add(where + ".orders has " + std::to_string(orders->count) +
                     " elements; orderCount x indices = " + std::to_string(n * e.order_count));
    Accessors::make_values(*indices, model.accessors[size_t(prim.indices)].componentType);
    Accessors::make_values(*orders, e.component_type);
    e.indices = indices->values;
    e.orders = orders->values;
    // Every order names vertices of the primitive (an unsigned short never 65535, WebGL 2's
    // primitive restart).
    const auto position = prim.attributes.find("POSITION");
    if (position == prim.attributes.end() || position->second < 0 || size_t(position->second) >= model.accessors.size())
        return p.add(where + " has no POSITION accessor");
    const size_t vertices = model.accessors[size_t(position->second)].count;
    if (!orders->values.empty() && orders->largest >= vertices)
        return p.add(where + ".orders names vertex " + std::to_string(orders->largest) + " of " +
                     std::to_string(vertices));
    if (e.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && orders->largest == 65535)
        return p.add(where + ".orders names vertex 65535 (primitive restart)");
    const PairVerdict* verdict =
        accessors.pair(e.orders_accessor, prim.indices, *orders, *indices, e.order_count, root.fallback);
    if (!verdict) return;
    e.indices_equal_fallback = verdict->indices_equal_fallback;
    e.order_is_permutation = verdict->order_is_permutation;
    if (!e.indices_equal_fallback)
        p.add(where + ".indices differs from order " + std::to_string(root.fallback) + " (fallback)");
    const auto bad = std::find(e.order_is_permutation.begin(), e.order_is_permutation.end(), false);
    if (bad != e.order_is_permutation.end()) {
        const size_t more = size_t(std::count(bad + 1, e.order_is_permutation.end(), false));
        p.add(where + " order " + std::to_string(bad - e.order_is_permutation.begin()) +
              " is not a permutation of the primitive's triangles with their winding (stale orders?)" +
              (more ? " (and " + std::to_string(more) + " more orders)" : ""));
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
    // A stride tinygltf reads as absent (a negative one) or as tight (0): glTF's from 4 to 252, a
    // multiple of 4, or none.
    if (doc.contains("bufferViews") && doc["bufferViews"].is_array())
        for (size_t i = 0; i < doc["bufferViews"].size(); ++i) {
            const nlohmann::json& item = doc["bufferViews"][i];
            if (!item.is_object() || !item.contains("byteStride")) continue;
            const nlohmann::json& stride = item["byteStride"];
            if (!stride.is_number_unsigned() || stride.get<uint64_t>() < 4 || stride.get<uint64_t>() > 252 ||
                stride.get<uint64_t>() % 4 != 0)
                p.add("bufferViews[" + std::to_string(i) + "].byteStride " + stride.dump() +
                      " is not an integer from 4 to 252, a multiple of 4");
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
    Accessors accessors(model, p);
    const auto clips = o.find("clips");
    if (clips == o.end() || !clips->second.IsArray() || clips->second.ArrayLen() == 0)
        p.add("root.clips is missing or empty");
    else
        for (size_t c = 0; c < clips->second.ArrayLen() && !accessors.over(); ++c)
            read_clip(model, clips->second.Get(int(c)), c, r.buffer_count, p, accessors, r.clips);
    for (size_t m = 0; m < model.meshes.size() && !accessors.over(); ++m)
        for (size_t pi = 0; pi < model.meshes[m].primitives.size() && !accessors.over(); ++pi) {
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
            read_primitive(model, m, pi, e->second.Get<Object>(), r, p, accessors, r.primitives);
        }
    if (r.primitives.empty() && r.errors.empty()) p.add("no primitive carries the orders");
    r.work_budget = accessors.budget();
    const auto count = [&model](int a) {
        return a >= 0 && size_t(a) < model.accessors.size() ? model.accessors[size_t(a)].count : 0;
    };
    for (const tinygltf::Node& node : model.nodes)
        if (node.mesh >= 0 && size_t(node.mesh) < model.meshes.size())
            for (const tinygltf::Primitive& prim : model.meshes[size_t(node.mesh)].primitives) {
                const auto position = prim.attributes.find("POSITION");
                r.posed_elements +=
                    count(prim.indices) + (position == prim.attributes.end() ? 0 : count(position->second));
            }
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
