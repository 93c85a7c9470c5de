// glTF 2.0 characters into keyframes: the node hierarchy, skins, morph targets and animations
// evaluated on the CPU at a fixed sample rate (DESIGN.md "Keyframes of a clip").
//
// Follows the glTF 2.0 specification (Khronos): §3.5 node transforms (matrix, or T·R·S), §3.7
// skins (joint matrix = joint's global transform · inverse bind matrix; the skinned mesh node's
// own transform is ignored), §3.7.2.2 morph targets (position = base + Σ weight · delta), §3.11
// animation samplers (LINEAR with slerp for rotations, STEP, CUBICSPLINE Hermite with tangents
// scaled by the key interval), sparse accessors. Parsing is tinygltf's (Debian's libtinygltf);
// every access it leaves unchecked (accessor ranges, indices, joints) is checked here, so a
// broken file is a one-line LoadError, never a crash.
#include "animorder/gltf_loader.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/skinning.h"

#include "../support/worker_threads.h"
#include "checked_size.h"
#include "gltf_buffer.h"
#include "transform.h"

#include <tiny_gltf.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <map>
#include <set>

namespace animorder {
namespace {

using io::identity;
using io::Mat;
using io::mul;
using io::Quat;
using io::trs;

// A number from a file for an error message: an integer when it is one, without converting a
// value out of range.
std::string number_text(double v) {
    if (v > -1e15 && v < 1e15 && v == std::floor(v)) return std::to_string(int64_t(v));
    return std::to_string(v);
}

class Reader {
public:
    // max_bytes: the loading budget, also the most bytes that the values of all accessors read
    // (as doubles) may take together: a small file that names one large accessor many times (as
    // morph targets, samplers) must not multiply it past the budget.
    Reader(const tinygltf::Model& model, const std::string& file, size_t max_bytes)
        : model_(model), file_(file), max_bytes_(max_bytes) {}

    [[noreturn]] void fail(const std::string& what) const { throw LoadError(file_ + ": " + what); }

    // count × components values of an accessor as doubles (normalised integers mapped to [0, 1]
    // or [−1, 1] as the spec says), sparse substitution applied, every byte range checked before
    // anything is allocated or read.
    std::vector<double> read(int index, int expected_components = 0) const {
        if (index < 0 || size_t(index) >= model_.accessors.size())
            fail("accessor " + std::to_string(index) + " does not exist");
        const tinygltf::Accessor& a = model_.accessors[size_t(index)];
        const std::string name = "accessor " + std::to_string(index);
        const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
        const int size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
        if (components <= 0 || size <= 0) fail(name + " has an unknown type");
        if (expected_components && components != expected_components)
            fail(name + " has " + std::to_string(components) + " components, expected " +
                 std::to_string(expected_components));
        const size_t element = size_t(components) * size_t(size);
        // The count is the file's: checked against the buffer view (and the budget) first.
        size_t stride = element;
        const unsigned char* base = nullptr;
        if (a.bufferView >= 0) {
            base = view_bytes(a.bufferView, a.byteOffset, a.count, element, true, index, stride);
            // glTF 2.0 §3.6.2.4: an accessor's start in its buffer and its stride are multiples of its
            // component size (engines make typed arrays over the bytes: three.js throws otherwise).
            const size_t start = model_.bufferViews[size_t(a.bufferView)].byteOffset + a.byteOffset;
            if (start % size_t(size) != 0 || stride % size_t(size) != 0)
                fail(name +
                     (start % size_t(size) ? " starts at byte " + std::to_string(start) + " of its buffer"
                                           : " has a stride of " + std::to_string(stride) + " bytes") +
                     ", not a multiple of its " + std::to_string(size) + "-byte components (glTF requires it)");
        }
        size_t values = 0;
        if (!io::checked_mul(a.count, size_t(components), values) || values > max_bytes_ / sizeof(double))
            fail(name + " has " + std::to_string(a.count) + " elements, more than the loading budget of " +
                 std::to_string(max_bytes_) + " bytes");
        if (values > (max_bytes_ - read_bytes_) / sizeof(double))
            fail("the accessors read need more than the loading budget of " + std::to_string(max_bytes_) +
                 " bytes (is one accessor named many times?); raise it with --max-memory");
        read_bytes_ += values * sizeof(double);
        std::vector<double> out(values, 0.0);
        if (base)
            for (size_t i = 0; i < a.count; ++i)
                for (int c = 0; c < components; ++c)
                    out[i * size_t(components) + size_t(c)] =
                        convert(base + i * stride + size_t(c * size), a.componentType, a.normalized);
        if (a.sparse.isSparse) {
            if (a.sparse.count < 0 || size_t(a.sparse.count) > a.count)
                fail("sparse " + name + " substitutes " + std::to_string(a.sparse.count) + " of " +
                     std::to_string(a.count) + " elements");
            const int index_type = a.sparse.indices.componentType;
            if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                fail("sparse " + name + " has indices that are not unsigned integers");
            const size_t n = size_t(a.sparse.count);
            const size_t index_size = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(index_type)));
            size_t unused = 0;
            const unsigned char* idx =
                view_bytes(a.sparse.indices.bufferView, offset_of(a.sparse.indices.byteOffset, index), n, index_size,
                           false, index, unused);
            const unsigned char* val =
                view_bytes(a.sparse.values.bufferView, offset_of(a.sparse.values.byteOffset, index), n, element, false,
                           index, unused);
            for (size_t i = 0; i < n; ++i) {
                const size_t target = size_t(convert(idx + i * index_size, index_type, false));
                if (target >= a.count) fail("sparse " + name + " names element " + std::to_string(target));
                for (int c = 0; c < components; ++c)
                    out[target * size_t(components) + size_t(c)] = convert(
                        val + (i * size_t(components) + size_t(c)) * size_t(size), a.componentType, a.normalized);
            }
        }
        for (double v : out)
            if (!std::isfinite(v)) fail(name + " holds a NaN or infinite value");
        return out;
    }

private:
    size_t offset_of(int byte_offset, int accessor) const {
        if (byte_offset < 0) fail("accessor " + std::to_string(accessor) + " has a negative byte offset");
        return size_t(byte_offset);
    }

    // The first byte of `count` elements of `element` bytes at `offset` in buffer view
    // `view_index`, every index and range checked with overflow-checked arithmetic. `stride` is
    // the view's byteStride when `strided` (and the view has one), else `element`.
    const unsigned char* view_bytes(int view_index, size_t offset, size_t count, size_t element, bool strided,
                                    int accessor, size_t& stride) const {
        if (view_index < 0 || size_t(view_index) >= model_.bufferViews.size())
            fail("accessor " + std::to_string(accessor) + " names a missing buffer view");
        const tinygltf::BufferView& view = model_.bufferViews[size_t(view_index)];
        if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
            fail("buffer view " + std::to_string(view_index) + " names a missing buffer");
        const std::vector<unsigned char>& data = model_.buffers[size_t(view.buffer)].data;
        size_t view_end = 0;
        if (!io::checked_add(view.byteOffset, view.byteLength, view_end) || view_end > data.size())
            fail("buffer view " + std::to_string(view_index) + " runs past the end of its buffer (truncated file?)");
        if (strided && view.byteStride && view.byteStride < element)
            fail("buffer view " + std::to_string(view_index) + " has a byteStride of " +
                 std::to_string(view.byteStride) + ", less than the " + std::to_string(element) +
                 " bytes of accessor " + std::to_string(accessor) + "'s elements");
        stride = strided && view.byteStride ? view.byteStride : element;
        size_t end = offset, last = 0;  // offset + stride · (count − 1) + element
        if (count > 0 && (!io::checked_mul(stride, count - 1, last) || !io::checked_add(end, last, end) ||
                          !io::checked_add(end, element, end)))
            end = SIZE_MAX;
        if (end > view.byteLength)
            fail("accessor " + std::to_string(accessor) + " runs past the end of its buffer view");
        return data.data() + view.byteOffset + offset;
    }

    static double convert(const unsigned char* p, int type, bool normalized) {
        switch (type) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: {
                float f;
                std::memcpy(&f, p, 4);
                return f;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
            case TINYGLTF_COMPONENT_TYPE_BYTE: {
                const int8_t v = int8_t(p[0]);
                return normalized ? std::max(v / 127.0, -1.0) : v;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                uint16_t v;
                std::memcpy(&v, p, 2);
                return normalized ? v / 65535.0 : v;
            }
            case TINYGLTF_COMPONENT_TYPE_SHORT: {
                int16_t v;
                std::memcpy(&v, p, 2);
                return normalized ? std::max(v / 32767.0, -1.0) : v;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
                uint32_t v;
                std::memcpy(&v, p, 4);
                return v;
            }
            default: return NAN;
        }
    }

    const tinygltf::Model& model_;
    std::string file_;
    size_t max_bytes_;
    mutable size_t read_bytes_ = 0;  // bytes of all accessors read so far (≤ max_bytes_)
};

struct PrimitiveData {
    size_t node = 0;
    size_t vertex_base = 0, vertex_count = 0;
    std::vector<double> positions;             // V × 3
    std::vector<std::vector<double>> targets;  // per morph target: V × 3 deltas
    std::vector<uint16_t> joints;              // V × influences
    std::vector<float> weights;                // V × influences
    size_t influences = 0;
};

struct NodePose {
    std::array<double, 3> t{0, 0, 0}, s{1, 1, 1};
    Quat r{0, 0, 0, 1};
    std::vector<double> weights;
    bool has_matrix = false;
    Mat matrix = identity();
};

std::vector<uint32_t> triangle_list(const std::vector<double>& raw, int mode, size_t vertex_count, const Reader& reader,
                                    const std::string& where) {
    std::vector<uint32_t> idx(raw.size());
    for (size_t i = 0; i < raw.size(); ++i) {
        if (!(raw[i] >= 0 && raw[i] < double(vertex_count)))
            reader.fail(where + ": index " + std::to_string(i) + " is " + number_text(raw[i]) + ", but there are " +
                        std::to_string(vertex_count) + " vertices");
        idx[i] = uint32_t(raw[i]);
    }
    std::vector<uint32_t> out;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (idx.size() % 3) reader.fail(where + ": " + std::to_string(idx.size()) + " indices are not whole triangles");
        return idx;
    }
    if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {  // every other triangle flipped to keep the winding
        for (size_t i = 2; i < idx.size(); ++i)
            if (i % 2 == 0)
                out.insert(out.end(), {idx[i - 2], idx[i - 1], idx[i]});
            else
                out.insert(out.end(), {idx[i - 1], idx[i - 2], idx[i]});
        return out;
    }
    if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        for (size_t i = 2; i < idx.size(); ++i) out.insert(out.end(), {idx[0], idx[i - 1], idx[i]});
        return out;
    }
    reader.fail(where + ": points and lines cannot be reordered for overdraw (mode " + std::to_string(mode) + ")");
}

Quat slerp(Quat a, Quat b, double t) {
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    if (d < 0) {
        for (double& v : b) v = -v;
        d = -d;
    }
    Quat q;
    if (d > 0.9995) {
        for (int i = 0; i < 4; ++i) q[i] = a[i] + t * (b[i] - a[i]);
    } else {
        const double theta = std::acos(d), s = std::sin(theta);
        const double wa = std::sin((1 - t) * theta) / s, wb = std::sin(t * theta) / s;
        for (int i = 0; i < 4; ++i) q[i] = wa * a[i] + wb * b[i];
    }
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& v : q) v /= n;
    return q;
}

// One animation channel's value at time t (components values per key; rotations slerped).
std::vector<double> sample(const std::vector<double>& times, const std::vector<double>& values, size_t components,
                           const std::string& interpolation, bool rotation, double t) {
    const bool cubic = interpolation == "CUBICSPLINE";
    const size_t stride = cubic ? 3 * components : components;  // in-tangent, value, out-tangent
    auto value = [&](size_t key, size_t part) {
        return std::vector<double>(values.begin() + ptrdiff_t(key * stride + part * components),
                                   values.begin() + ptrdiff_t(key * stride + (part + 1) * components));
    };
    const size_t mid = cubic ? 1 : 0;
    if (t <= times.front()) return value(0, mid);
    if (t >= times.back()) return value(times.size() - 1, mid);
    const size_t k = size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    const double dt = times[k + 1] - times[k], u = dt > 0 ? (t - times[k]) / dt : 0.0;
    if (interpolation == "STEP") return value(k, 0);
    std::vector<double> out(components);
    if (cubic) {
        const auto p0 = value(k, 1), m0 = value(k, 2), p1 = value(k + 1, 1), m1 = value(k + 1, 0);
        const double u2 = u * u, u3 = u2 * u;
        for (size_t c = 0; c < components; ++c)
            out[c] = (2 * u3 - 3 * u2 + 1) * p0[c] + (u3 - 2 * u2 + u) * dt * m0[c] + (-2 * u3 + 3 * u2) * p1[c] +
                     (u3 - u2) * dt * m1[c];
        if (rotation) {
            const double n = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
            for (double& v : out) v /= n;
        }
        return out;
    }
    const auto a = value(k, 0), b = value(k + 1, 0);
    if (rotation) {
        const Quat q = slerp({a[0], a[1], a[2], a[3]}, {b[0], b[1], b[2], b[3]}, u);
        return {q[0], q[1], q[2], q[3]};
    }
    for (size_t c = 0; c < components; ++c) out[c] = a[c] + u * (b[c] - a[c]);
    return out;
}

// One animation channel: a node's translation, rotation, scale or morph weights over time.
struct Channel {
    size_t node;
    std::string path;
    std::vector<double> times, values;
    std::string interpolation;
    bool geometry = true;  // translation, rotation, scale or weights; else only its times are read
};

// A clip and its channels, read before any clip is sampled, so that the keyframes of every clip
// are counted (and checked against the loading budget) first.
struct ClipChannels {
    Clip clip;
    double t0 = 0, t1 = 0;  // first and last key time
    std::vector<Channel> channels;
};

// What the steps after parsing the file share; each parse_* step fills its part.
struct Scene {
    const tinygltf::Model& model;
    const Reader& reader;
    std::vector<int> parent;           // per node: its parent, −1 for a root
    std::vector<size_t> order;         // nodes of the scene, depth first (parents before children)
    std::vector<PrimitiveData> prims;  // triangle primitives of the mesh nodes, in scene order
    std::vector<NodePose> rest;        // per node: its pose without animation
    std::vector<Mat> inverse_bind;     // per skin, concatenated
    std::vector<size_t> skin_first;    // per skin: the index of its first inverse bind matrix
};

// Components of a channel's value: 4 for a rotation, the node's morph target count for weights,
// 3 for translation and scale.
size_t channel_components(const Scene& s, size_t node, const std::string& path) {
    return path == "rotation" ? 4 : path == "weights" ? s.rest[node].weights.size() : 3;
}

// The file through tinygltf (binary when it starts with "glTF", else JSON), textures passed
// through undecoded; no file it reads larger than the loading budget.
tinygltf::Model parse_file(const std::string& path, const LoadOptions& options) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    const uint64_t budget = options.file_budget();               // no file read whole is larger
    loader.SetFsCallbacks(io::regular_file_callbacks(&budget));  // a FIFO or a device is never opened
    loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*,
                             int, void*) { return true; },  // textures pass through untouched: never decoded
                          nullptr);
    std::string error, warning;
    const std::string magic = io::magic_of(path);
    io::check_json_depth(path);
    const bool ok = io::load_gltf_file(loader, model, error, warning, path, magic == "glTF", &budget);
    io::finish_load(ok, error, model, path);
    return model;
}

// Every node's parent (a node is the child of one node at most, so the nodes form a forest) and
// the nodes of the default scene (or, without scenes, of every root), depth first.
void parse_node_hierarchy(Scene& s) {
    const tinygltf::Model& model = s.model;
    s.parent.assign(model.nodes.size(), -1);
    for (size_t n = 0; n < model.nodes.size(); ++n)
        for (int c : model.nodes[n].children) {
            if (c < 0 || size_t(c) >= model.nodes.size())
                s.reader.fail("node " + std::to_string(n) + " names child " + std::to_string(c) +
                              ", but the file has " + std::to_string(model.nodes.size()) + " nodes");
            if (size_t(c) == n)
                s.reader.fail("node hierarchy is not a tree: node " + std::to_string(n) + " names itself as its child");
            if (s.parent[size_t(c)] >= 0)
                s.reader.fail("node hierarchy is not a tree: node " + std::to_string(c) + " is a child of node " +
                              std::to_string(s.parent[size_t(c)]) + " and of node " + std::to_string(n));
            s.parent[size_t(c)] = int(n);
        }
    std::vector<int> roots;
    const int scene = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (size_t(scene) < model.scenes.size())
        roots = model.scenes[size_t(scene)].nodes;
    else
        for (size_t n = 0; n < model.nodes.size(); ++n)
            if (s.parent[n] < 0) roots.push_back(int(n));
    std::vector<int> stack(roots.rbegin(), roots.rend());
    std::vector<uint8_t> seen(model.nodes.size(), 0);  // a cycle or a repeated root shows as a node seen twice
    while (!stack.empty()) {
        const int n = stack.back();
        stack.pop_back();
        if (n < 0 || size_t(n) >= model.nodes.size() || seen[size_t(n)])
            s.reader.fail("scene names a bad or repeated node");
        seen[size_t(n)] = 1;
        s.order.push_back(size_t(n));
        const auto& children = model.nodes[size_t(n)].children;
        for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back(*it);
    }
}

// The name of a component type for an error message.
std::string component_name(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "bytes";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "unsigned bytes";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "shorts";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "unsigned shorts";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "unsigned ints";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "floats";
        default: return "component type " + std::to_string(type);
    }
}

// LoadError unless accessor `index` holds one of the component types glTF allows `what`
// (`normalized` among them: the integer types that must be normalized; others may be either): read
// as another type, its bytes would be taken for other numbers (a float's bytes as shorts).
void require_format(const Scene& s, int index, const std::string& what, std::initializer_list<int> allowed,
                    std::initializer_list<int> normalized, const std::string& note = "") {
    if (index < 0 || size_t(index) >= s.model.accessors.size()) return;  // read() says so
    const tinygltf::Accessor& a = s.model.accessors[size_t(index)];
    const bool listed = std::find(allowed.begin(), allowed.end(), a.componentType) != allowed.end();
    const bool must_normalize = std::find(normalized.begin(), normalized.end(), a.componentType) != normalized.end();
    if (listed && (!must_normalize || a.normalized)) return;
    s.reader.fail(what + " (accessor " + std::to_string(index) + ") are " +
                  (a.normalized               ? "normalized "
                   : must_normalize && listed ? "unnormalized "
                                              : "") +
                  component_name(a.componentType) + ", which glTF does not allow there" + note);
}

// POSITION (a primitive's or a morph target's) is floats, or with KHR_mesh_quantization
// (extensionsUsed) bytes or shorts, signed or not, normalized or not.
void require_position_format(const Scene& s, int index, const std::string& what) {
    const auto& used = s.model.extensionsUsed;
    if (std::find(used.begin(), used.end(), "KHR_mesh_quantization") == used.end())
        return require_format(s, index, what, {TINYGLTF_COMPONENT_TYPE_FLOAT}, {},
                              " (integer positions need KHR_mesh_quantization, which the file does not use)");
    require_format(s, index, what,
                   {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                    TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                   {});
}

// POSITION of each morph target of a primitive (zero deltas for a target without one).
void parse_morph_targets(const Scene& s, const tinygltf::Primitive& prim, const std::string& where, PrimitiveData& d) {
    for (const auto& target : prim.targets) {
        const auto t = target.find("POSITION");
        if (t != target.end()) require_position_format(s, t->second, where + ": a morph target's POSITION");
        d.targets.push_back(t == target.end() ? std::vector<double>(d.positions.size(), 0.0)
                                              : s.reader.read(t->second, 3));
        if (d.targets.back().size() != d.positions.size()) s.reader.fail(where + ": a morph target has the wrong size");
    }
}

// Indices and joints are unsigned integers, not normalized (glTF 2.0, 3.7.2.1 and 3.7.3.3): any
// other type would be truncated into other vertices or joints.
void require_unsigned_integers(const Scene& s, int accessor, const std::string& what) {
    if (accessor < 0 || size_t(accessor) >= s.model.accessors.size()) return;  // read() says so
    const tinygltf::Accessor& a = s.model.accessors[size_t(accessor)];
    const bool unsigned_integer = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                  a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                                  a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    if (!unsigned_integer || a.normalized)
        s.reader.fail(what + " (accessor " + std::to_string(accessor) + ") are " +
                      (a.normalized ? "normalized" : "not unsigned integers") +
                      ": glTF asks for unsigned bytes, shorts or ints");
}

// JOINTS_n / WEIGHTS_n sets of a skinned primitive, interleaved per vertex (4 influences per
// set); every joint with weight is checked against the skin's joint_count.
void parse_skin_weights(const Scene& s, const tinygltf::Primitive& prim, size_t joint_count, const std::string& where,
                        PrimitiveData& d) {
    for (int set = 0;; ++set) {
        const auto j = prim.attributes.find("JOINTS_" + std::to_string(set));
        const auto w = prim.attributes.find("WEIGHTS_" + std::to_string(set));
        if (j == prim.attributes.end() || w == prim.attributes.end()) break;
        require_unsigned_integers(s, j->second, where + ": JOINTS_" + std::to_string(set));
        require_format(s, w->second, where + ": WEIGHTS_" + std::to_string(set),
                       {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                        TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
        const std::vector<double> jv = s.reader.read(j->second, 4), wv = s.reader.read(w->second, 4);
        if (jv.size() != 4 * d.vertex_count || wv.size() != 4 * d.vertex_count)
            s.reader.fail(where + ": joints or weights do not match the vertex count");
        std::vector<uint16_t> joints(d.joints.size() + jv.size());
        std::vector<float> weights(d.weights.size() + wv.size());
        for (size_t v = 0; v < d.vertex_count; ++v) {  // interleave sets: influences per vertex grow by 4
            for (size_t i = 0; i < d.influences; ++i) {
                joints[v * (d.influences + 4) + i] = d.joints[v * d.influences + i];
                weights[v * (d.influences + 4) + i] = d.weights[v * d.influences + i];
            }
            for (size_t i = 0; i < 4; ++i) {
                const double joint = jv[4 * v + i];
                if (joint < 0 || (joint >= double(joint_count) && wv[4 * v + i] > 0))
                    s.reader.fail(where + ": vertex " + std::to_string(v) + " names joint " + number_text(joint) +
                                  ", the skin has " + std::to_string(joint_count));
                if (joint > 65535.0 && wv[4 * v + i] > 0)
                    s.reader.fail(where + ": vertex " + std::to_string(v) + " names joint " + number_text(joint) +
                                  "; at most 65,536 joints a skin are supported");
                joints[v * (d.influences + 4) + d.influences + i] = uint16_t(std::min(joint, 65535.0));
                weights[v * (d.influences + 4) + d.influences + i] = float(wv[4 * v + i]);
            }
        }
        d.joints = std::move(joints);
        d.weights = std::move(weights);
        d.influences += 4;
    }
    if (d.influences == 0) s.reader.fail(where + ": skinned without JOINTS_0/WEIGHTS_0");
}

// Primitive p of node n's mesh: its vertices (appended to the mesh's), its triangles (appended to
// the mesh's index buffer), morph targets and skin weights.
PrimitiveData parse_primitive(const Scene& s, size_t n, size_t p, AnimatedMesh& mesh) {
    const tinygltf::Node& node = s.model.nodes[n];
    const tinygltf::Mesh& m = s.model.meshes[size_t(node.mesh)];
    const tinygltf::Primitive& prim = m.primitives[p];
    const std::string where = (m.name.empty() ? "mesh " + std::to_string(node.mesh) : "mesh '" + m.name + "'") +
                              " primitive " + std::to_string(p);
    const auto position = prim.attributes.find("POSITION");
    if (position == prim.attributes.end()) s.reader.fail(where + " has no POSITION");
    require_position_format(s, position->second, where + ": POSITION");
    PrimitiveData d;
    d.node = n;
    d.positions = s.reader.read(position->second, 3);
    d.vertex_count = d.positions.size() / 3;
    d.vertex_base = mesh.vertex_count;
    std::vector<double> raw;
    if (prim.indices >= 0) {
        require_unsigned_integers(s, prim.indices, where + ": the indices");
        raw = s.reader.read(prim.indices, 1);
    } else
        for (size_t i = 0; i < d.vertex_count; ++i) raw.push_back(double(i));  // non-indexed
    const std::vector<uint32_t> local = triangle_list(raw, prim.mode, d.vertex_count, s.reader, where);
    Primitive out;
    out.name = m.name.empty() ? "primitive" + std::to_string(s.prims.size()) : m.name + "/" + std::to_string(p);
    out.first_index = mesh.indices.size();
    out.index_count = local.size();
    out.source_mesh = node.mesh;
    out.source_primitive = int(p);
    out.vertex_base = d.vertex_base;
    out.vertex_count = d.vertex_count;
    // Its material: glTF's defaults (single-sided, OPAQUE) without one.
    if (prim.material >= 0) {
        if (size_t(prim.material) >= s.model.materials.size()) s.reader.fail(where + " names a missing material");
        const tinygltf::Material& material = s.model.materials[size_t(prim.material)];
        out.double_sided = material.doubleSided;
        if (material.alphaMode == "BLEND")
            out.alpha_mode = AlphaMode::Blend;
        else if (material.alphaMode == "MASK")
            out.alpha_mode = AlphaMode::Mask;
        else if (material.alphaMode.empty() || material.alphaMode == "OPAQUE")
            out.alpha_mode = AlphaMode::Opaque;
        else
            s.reader.fail(where + ": material alphaMode '" + material.alphaMode + "' is not OPAQUE, MASK or BLEND");
    }
    for (uint32_t i : local) mesh.indices.push_back(uint32_t(d.vertex_base + i));
    mesh.primitives.push_back(out);
    parse_morph_targets(s, prim, where, d);
    mesh.morph_target_count = std::max(mesh.morph_target_count, d.targets.size());
    if (node.skin >= 0) {
        if (size_t(node.skin) >= s.model.skins.size()) s.reader.fail(where + ": the node names a missing skin");
        const size_t joint_count = s.model.skins[size_t(node.skin)].joints.size();
        parse_skin_weights(s, prim, joint_count, where, d);
    }
    mesh.vertex_count += d.vertex_count;
    return d;
}

// Whether a node of the tree under `root` draws a mesh (a cycle or a bad index ends the search).
bool draws_a_mesh(const tinygltf::Model& model, int root) {
    std::vector<int> stack = {root};
    for (size_t visited = 0; !stack.empty() && visited <= model.nodes.size(); ++visited) {
        const int n = stack.back();
        stack.pop_back();
        if (n < 0 || size_t(n) >= model.nodes.size()) continue;
        if (model.nodes[size_t(n)].mesh >= 0) return true;
        stack.insert(stack.end(), model.nodes[size_t(n)].children.begin(), model.nodes[size_t(n)].children.end());
    }
    return false;
}

// The scene parse_node_hierarchy read, for an error: which one and why that one, and another
// scene that draws a mesh when there is one.
std::string scene_named(const Scene& s) {
    const tinygltf::Model& model = s.model;
    if (model.scenes.empty()) return "the file's nodes (it has no scene)";
    const size_t used = model.defaultScene >= 0 ? size_t(model.defaultScene) : 0;
    if (used >= model.scenes.size()) return "the file's nodes";
    std::string named = "scene " + std::to_string(used) +
                        (model.defaultScene >= 0 ? " (the file's default `scene`)"
                                                 : " (the file names no default `scene`: the first, as viewers show)");
    for (size_t other = 0; other < model.scenes.size(); ++other)
        if (other != used && std::any_of(model.scenes[other].nodes.begin(), model.scenes[other].nodes.end(),
                                         [&](int root) { return draws_a_mesh(model, root); }))
            return named + "; scene " + std::to_string(other) + " draws meshes: make it the file's `scene` to " +
                   "optimise it";
    return named;
}

// Every triangle primitive of the mesh nodes, in scene order (node, then primitive): at least one.
// Points and lines are left out: they draw as the file has them, and writers leave them alone.
void parse_primitives(Scene& s, AnimatedMesh& mesh) {
    mesh.joint_count = 0;
    bool points_or_lines = false;
    for (size_t n : s.order) {
        const tinygltf::Node& node = s.model.nodes[n];
        if (node.mesh < 0) continue;
        if (size_t(node.mesh) >= s.model.meshes.size())
            s.reader.fail("node " + std::to_string(n) + " names a missing mesh");
        for (size_t p = 0; p < s.model.meshes[size_t(node.mesh)].primitives.size(); ++p) {
            const int mode = s.model.meshes[size_t(node.mesh)].primitives[p].mode;
            if (mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP ||
                mode == TINYGLTF_MODE_LINE_STRIP) {  // parse_primitive then sees triangles only
                points_or_lines = true;              // drawn as the file has them (as assimp's loader drops them too)
                continue;
            }
            s.prims.push_back(parse_primitive(s, n, p, mesh));
        }
    }
    if (s.prims.empty())
        s.reader.fail("no triangle mesh in " + scene_named(s) +
                      (points_or_lines ? " (points and lines cannot be reordered for overdraw)" : ""));
    // The joints: the nodes of the skins that the drawn primitives' nodes name, each node once
    // (two skins of one skeleton share their nodes; two skeletons add up).
    std::set<int> joints;
    for (const PrimitiveData& d : s.prims) {
        const tinygltf::Node& node = s.model.nodes[d.node];
        if (node.skin >= 0)
            for (const int j : s.model.skins[size_t(node.skin)].joints) joints.insert(j);
    }
    mesh.joint_count = joints.size();
}

// Every node's pose without animation: matrix or T, R, S, and morph weights (the node's, else
// its mesh's defaults).
void parse_rest_pose(Scene& s) {
    s.rest.resize(s.model.nodes.size());
    for (size_t n = 0; n < s.model.nodes.size(); ++n) {
        const tinygltf::Node& node = s.model.nodes[n];
        NodePose& p = s.rest[n];
        if (node.matrix.size() == 16) {
            p.has_matrix = true;
            std::copy(node.matrix.begin(), node.matrix.end(), p.matrix.begin());
        }
        if (node.translation.size() == 3) std::copy(node.translation.begin(), node.translation.end(), p.t.begin());
        if (node.rotation.size() == 4) std::copy(node.rotation.begin(), node.rotation.end(), p.r.begin());
        if (node.scale.size() == 3) std::copy(node.scale.begin(), node.scale.end(), p.s.begin());
        if (node.mesh >= 0 && size_t(node.mesh) < s.model.meshes.size()) {
            const tinygltf::Mesh& mesh = s.model.meshes[size_t(node.mesh)];
            p.weights = mesh.weights;
            if (p.weights.empty()) {  // optional: one zero per morph target
                size_t targets = 0;
                for (const tinygltf::Primitive& prim : mesh.primitives)
                    targets = std::max(targets, prim.targets.size());
                p.weights.assign(targets, 0.0);
            }
        }
        if (!node.weights.empty()) p.weights = node.weights;
    }
}

// Every skin's inverse bind matrices (identity without them), its joints checked to be nodes.
void parse_skins(Scene& s) {
    for (const tinygltf::Skin& skin : s.model.skins) {
        s.skin_first.push_back(s.inverse_bind.size());
        std::vector<double> m;
        if (skin.inverseBindMatrices >= 0) m = s.reader.read(skin.inverseBindMatrices, 16);
        for (size_t j = 0; j < skin.joints.size(); ++j) {
            if (skin.joints[j] < 0 || size_t(skin.joints[j]) >= s.model.nodes.size())
                s.reader.fail("a skin names a missing joint node");
            Mat ibm = identity();
            if (!m.empty()) {
                if (m.size() < 16 * (j + 1)) s.reader.fail("a skin has fewer inverse bind matrices than joints");
                std::copy(m.begin() + ptrdiff_t(16 * j), m.begin() + ptrdiff_t(16 * j + 16), ibm.begin());
            }
            s.inverse_bind.push_back(ibm);
        }
    }
}

// One channel of a clip: its sampler's key times (sorted) and values (as many as the keys and
// the path need).
Channel parse_channel(const Scene& s, const tinygltf::Animation& anim, const tinygltf::AnimationChannel& ch,
                      const std::string& name) {
    if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
        s.reader.fail("clip '" + name + "' names a missing sampler");
    const tinygltf::AnimationSampler& sampler = anim.samplers[size_t(ch.sampler)];
    Channel c;
    c.node = size_t(ch.target_node);
    c.path = ch.target_path;
    c.interpolation = sampler.interpolation;
    if (c.interpolation != "LINEAR" && c.interpolation != "STEP" && c.interpolation != "CUBICSPLINE")
        s.reader.fail("clip '" + name + "' has a sampler of interpolation '" + c.interpolation +
                      "' (glTF has LINEAR, STEP and CUBICSPLINE)");
    require_format(s, sampler.input, "clip '" + name + "': key times", {TINYGLTF_COMPONENT_TYPE_FLOAT}, {});
    c.times = s.reader.read(sampler.input, 1);
    if (c.times.empty()) s.reader.fail("clip '" + name + "' has a channel without keys");
    if (!std::is_sorted(c.times.begin(), c.times.end()))
        s.reader.fail("clip '" + name + "' has key times out of order");
    c.geometry = c.path == "translation" || c.path == "rotation" || c.path == "scale" || c.path == "weights";
    if (!c.geometry) return c;  // another path (KHR_animation_pointer's): its times only, the clip's length
    c.values = s.reader.read(sampler.output);
    const size_t components = channel_components(s, c.node, c.path);
    if (c.path == "weights" && components == 0)
        s.reader.fail("clip '" + name + "' animates the morph weights of node " + std::to_string(c.node) +
                      ", which draws no morph targets");
    const size_t per_key = (c.interpolation == "CUBICSPLINE" ? 3 : 1) * components;
    if (components == 0 || c.values.size() != per_key * c.times.size())
        s.reader.fail("clip '" + name + "' channel for node " + std::to_string(c.node) + " (" + c.path +
                      ") has the wrong number of values");
    return c;
}

// A channel whose target names no node in the file (read with io::json_with_placeholder_nodes'
// placeholder) as the loader takes it: KHR_animation_pointer's pointer to
// a node's translation, rotation, scale or weights ("/nodes/3/rotation") as that node's channel;
// any other (a material's colour, a light's intensity, a node-less TRS channel, which glTF says to
// ignore) a channel of no path, whose times alone count (the clip's length).
tinygltf::AnimationChannel pointed_channel(const Scene& s, const tinygltf::AnimationChannel& ch) {
    tinygltf::AnimationChannel out = ch;
    out.target_node = 0;
    out.target_path.clear();
    const auto extension = ch.target_extensions.find("KHR_animation_pointer");
    if (extension == ch.target_extensions.end() || !extension->second.IsObject() || !extension->second.Has("pointer") ||
        !extension->second.Get("pointer").IsString())
        return out;
    const std::string pointer = extension->second.Get("pointer").Get<std::string>();
    const std::string prefix = "/nodes/";
    if (pointer.rfind(prefix, 0) != 0) return out;
    size_t at = prefix.size(), node = 0;
    for (; at < pointer.size() && at < prefix.size() + 9 && pointer[at] >= '0' && pointer[at] <= '9'; ++at)
        node = 10 * node + size_t(pointer[at] - '0');
    if (at == prefix.size() || at >= pointer.size() || pointer[at] != '/' || node >= s.model.nodes.size()) return out;
    const std::string path = pointer.substr(at + 1);
    if (path == "translation" || path == "rotation" || path == "scale" || path == "weights")
        out.target_node = int(node), out.target_path = path;
    return out;
}

// Every animation as a clip of channels, from its first to its last key time, with its keyframe
// count at the sample rate (no more than kMaxClipKeyframes); a channel naming a missing node is refused.
std::vector<ClipChannels> parse_animations(const Scene& s, const std::string& path, const LoadOptions& options) {
    std::vector<ClipChannels> clips;
    for (size_t a = 0; a < s.model.animations.size(); ++a) {
        const tinygltf::Animation& anim = s.model.animations[a];
        ClipChannels c;
        c.clip.name = anim.name.empty() ? "animation" + std::to_string(a) : anim.name;
        for (size_t i = 0; i < anim.channels.size(); ++i) {
            const tinygltf::AnimationChannel& ch = anim.channels[i];
            if (ch.target_node == io::kPlaceholderNode)  // no node in the file
                c.channels.push_back(parse_channel(s, anim, pointed_channel(s, ch), c.clip.name));
            else if (ch.target_node >= 0 && size_t(ch.target_node) < s.model.nodes.size())
                c.channels.push_back(parse_channel(s, anim, ch, c.clip.name));
            else  // engines fail on it (three.js throws reading the missing node)
                s.reader.fail("clip '" + c.clip.name + "' channel " + std::to_string(i) + " targets node " +
                              std::to_string(ch.target_node) + ", but the file has " +
                              std::to_string(s.model.nodes.size()) + " nodes");
        }
        if (c.channels.empty()) s.reader.fail("clip '" + c.clip.name + "' animates nothing");
        c.t0 = INFINITY, c.t1 = -INFINITY;
        for (const Channel& ch : c.channels)
            c.t0 = std::min(c.t0, ch.times.front()), c.t1 = std::max(c.t1, ch.times.back());
        c.clip.duration_s = c.t1 - c.t0;
        c.clip.source_animation = int(a);
        c.clip.start_time_s = c.t0;
        c.clip.sample_rate = options.sample_rate;
        c.clip.keyframe_count = io::clip_keyframes(path, c.clip.name, c.clip.duration_s, options.sample_rate);
        clips.push_back(std::move(c));
    }
    return clips;
}

// Positions of every vertex in `pose` into out (vertex_count × 3 floats): node transforms down
// the hierarchy, then per primitive morph targets, then its skin (joint matrix = joint's global
// transform · inverse bind matrix) or, unskinned, its node's global transform. Per primitive,
// winding[i] gets the sign of its node's global determinant (−1 mirrors; 0: flattened, or not a
// number), which gives the file's winding even where a skin ignores the node's transform (as
// engines cull: three.js flips by the mesh object's world matrix).
void evaluate_pose(const Scene& s, const std::vector<NodePose>& pose, float* out, int8_t* winding) {
    std::vector<Mat> global(s.model.nodes.size(), identity());
    for (size_t n : s.order) {
        const NodePose& p = pose[n];
        const Mat local = p.has_matrix ? p.matrix : trs(p.t, p.r, p.s);
        global[n] = s.parent[n] >= 0 ? mul(global[size_t(s.parent[n])], local) : local;
    }
    for (size_t i = 0; i < s.prims.size(); ++i) {
        const double det = io::determinant3(global[s.prims[i].node]);
        winding[i] = int8_t(det < 0 ? -1 : det > 0 ? 1 : 0);
    }
    for (const PrimitiveData& d : s.prims) {
        const tinygltf::Node& node = s.model.nodes[d.node];
        std::vector<float> morphed(d.positions.size());
        const std::vector<double>& w = pose[d.node].weights;
        for (size_t i = 0; i < d.positions.size(); ++i) {
            double v = d.positions[i];
            for (size_t t = 0; t < d.targets.size() && t < w.size(); ++t) v += w[t] * d.targets[t][i];
            morphed[i] = float(v);
        }
        float* dst = out + 3 * d.vertex_base;
        if (node.skin >= 0) {
            const tinygltf::Skin& skin = s.model.skins[size_t(node.skin)];
            std::vector<Mat4> joints(skin.joints.size());
            for (size_t j = 0; j < skin.joints.size(); ++j) {
                const Mat m = mul(global[size_t(skin.joints[j])], s.inverse_bind[s.skin_first[size_t(node.skin)] + j]);
                for (int k = 0; k < 16; ++k) joints[j][size_t(k)] = float(m[size_t(k)]);
            }
            try {
                skin_positions(dst, morphed.data(), d.vertex_count, d.joints.data(), d.weights.data(), d.influences,
                               joints.data(), joints.size());
            } catch (const InvalidInput& e) {
                s.reader.fail(e.what());
            }
        } else {
            const Mat& m = global[d.node];
            for (size_t v = 0; v < d.vertex_count; ++v) {
                const double x = morphed[3 * v], y = morphed[3 * v + 1], z = morphed[3 * v + 2];
                for (int r = 0; r < 3; ++r)
                    dst[3 * v + size_t(r)] =
                        float(m[size_t(r)] * x + m[size_t(4 + r)] * y + m[size_t(8 + r)] * z + m[size_t(12 + r)]);
            }
        }
    }
}

// One more keyframe of the mesh: the vertices in `pose`; `winding` gets evaluate_pose's signs.
void add_keyframe(const Scene& s, const std::vector<NodePose>& pose, AnimatedMesh& mesh, std::vector<int8_t>& winding) {
    const size_t first = mesh.keyframe_positions.size();
    mesh.keyframe_positions.resize(first + mesh.vertex_count * 3);
    winding.resize(winding.size() + s.prims.size());
    evaluate_pose(s, pose, mesh.keyframe_positions.data() + first, winding.data() + winding.size() - s.prims.size());
}

// The rest pose with every channel of a clip sampled at time t (an animated T, R or S replaces a
// node's matrix).
std::vector<NodePose> pose_at(const Scene& s, const std::vector<Channel>& channels, double t) {
    std::vector<NodePose> pose = s.rest;
    for (const Channel& c : channels) {
        if (!c.geometry) continue;
        const bool rotation = c.path == "rotation";
        const std::vector<double> v =
            sample(c.times, c.values, channel_components(s, c.node, c.path), c.interpolation, rotation, t);
        NodePose& p = pose[c.node];
        if (c.path == "translation")
            std::copy(v.begin(), v.end(), p.t.begin());
        else if (rotation)
            std::copy(v.begin(), v.end(), p.r.begin());
        else if (c.path == "scale")
            std::copy(v.begin(), v.end(), p.s.begin());
        else if (c.path == "weights")
            p.weights = v;
        if (c.path == "translation" || rotation || c.path == "scale")
            p.has_matrix = false;  // an animated TRS replaces a matrix (another path leaves it)
    }
    return pose;
}

// The clips' keyframes, every 1 / sample_rate seconds from each clip's first key time, the last
// one at its last key time: the clips one after the other, `keyframes` in all. The keyframes are
// evaluated in parallel (options.threads), each into its own slice of the one array allocated up
// front; the first failing keyframe's error (in keyframe order) is the one thrown, whatever the
// threads.
void sample_keyframes(const Scene& s, std::vector<ClipChannels>& clips, size_t keyframes, const LoadOptions& options,
                      AnimatedMesh& mesh, std::vector<int8_t>& winding) {
    if (clips.empty()) return;
    struct Sample {
        const ClipChannels* clip;
        size_t f;
    };
    std::vector<Sample> samples;
    samples.reserve(keyframes);
    for (ClipChannels& c : clips) {
        c.clip.first_keyframe = samples.size();
        for (size_t f = 0; f < c.clip.keyframe_count; ++f) samples.push_back({&c, f});
        mesh.clips.push_back(c.clip);
    }
    const size_t floats = mesh.vertex_count * 3;
    mesh.keyframe_positions.resize(samples.size() * floats);
    winding.resize(samples.size() * s.prims.size());
    std::vector<std::exception_ptr> errors(samples.size());
    const auto evaluate = [&](size_t k) {
        try {
            const ClipChannels& c = *samples[k].clip;
            const double t = std::min(c.t0 + double(samples[k].f) / options.sample_rate, c.t1);
            evaluate_pose(s, pose_at(s, c.channels, t), mesh.keyframe_positions.data() + k * floats,
                          winding.data() + k * s.prims.size());
        } catch (...) {
            errors[k] = std::current_exception();
        }
    };
    tbb::task_arena(worker_threads(options.threads)).execute([&] {
        tbb::parallel_for(size_t(0), samples.size(), evaluate);
    });
    for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
}

// Gives each primitive the winding its node's transform gives it in the file (evaluate_pose's
// signs, keyframe after keyframe): a mirrored one is marked and its triangles flipped to
// counter-clockwise front faces (Primitive::mirrored). One index buffer has one winding, so a
// primitive mirrored in some keyframes and not in others (a scale that changes sign) is refused.
void apply_mirroring(const Scene& s, const std::vector<int8_t>& winding, AnimatedMesh& mesh) {
    const size_t prims = s.prims.size();
    for (size_t i = 0; i < prims; ++i) {
        bool mirrored = false, upright = false;
        for (size_t k = i; k < winding.size(); k += prims) {
            mirrored = mirrored || winding[k] < 0;
            upright = upright || winding[k] > 0;
        }
        const size_t n = s.prims[i].node;
        if (mirrored && upright)
            s.reader.fail("node " + std::to_string(n) + " ('" + s.model.nodes[n].name + "') mirrors its mesh in some " +
                          "keyframes and not in others (a scale that changes sign), but one index buffer has one " +
                          "winding");
        mesh.primitives[i].mirrored = mirrored;
    }
    to_file_winding(mesh, mesh.indices.data());  // its own inverse: from the file's winding too
}

// Only the clips named in `asked` (LoadOptions::clips), when each name is one of them; every
// clip otherwise (none asked, or a name the file lacks: select_clips then reports it with the
// file's clip names). A kept clip's keyframes are sampled as they would be among all the clips.
void keep_asked_clips(std::vector<ClipChannels>& clips, const std::vector<std::string>& asked) {
    const auto named = [&](const std::string& name) {
        return std::any_of(clips.begin(), clips.end(), [&](const ClipChannels& c) { return c.clip.name == name; });
    };
    if (asked.empty() || !std::all_of(asked.begin(), asked.end(), named)) return;
    clips.erase(std::remove_if(clips.begin(), clips.end(),
                               [&](const ClipChannels& c) {
                                   return std::find(asked.begin(), asked.end(), c.clip.name) == asked.end();
                               }),
                clips.end());
}

}  // namespace

// The steps, in order: the file, the node hierarchy, primitives (with morph targets and skin
// weights), rest pose, skins, animations into clips; then, within the loading budget, keyframes.
AnimatedMesh load_gltf(const std::string& path, const LoadOptions& options) {
    if (!(options.sample_rate > 0 && options.sample_rate <= 1000))
        throw LoadError(path + ": sample rate must be in (0, 1000]");
    const tinygltf::Model model = parse_file(path, options);
    const Reader reader(model, path, options.max_keyframe_bytes);
    Scene scene{model, reader, {}, {}, {}, {}, {}, {}};
    AnimatedMesh mesh;
    mesh.name = path;
    parse_node_hierarchy(scene);
    parse_primitives(scene, mesh);
    parse_rest_pose(scene);
    parse_skins(scene);
    std::vector<ClipChannels> clips = parse_animations(scene, path, options);
    keep_asked_clips(clips, options.clips);

    size_t keyframes = clips.empty() ? 1 : 0;  // without animation: one static keyframe
    for (const ClipChannels& c : clips) keyframes += c.clip.keyframe_count;
    io::check_keyframe_budget(path, keyframes, mesh.vertex_count, options);
    std::vector<int8_t> winding;
    if (clips.empty()) {
        add_keyframe(scene, scene.rest, mesh, winding);
        mesh.clips.push_back({"static", 0.0, options.sample_rate, 0, 1});
    }
    sample_keyframes(scene, clips, keyframes, options, mesh, winding);
    apply_mirroring(scene, winding, mesh);
    try {
        validate_animated_mesh(mesh);
    } catch (const InvalidInput& e) {
        reader.fail(e.what());
    }
    return mesh;
}

}  // namespace animorder
