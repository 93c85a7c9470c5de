// What the glTF writers replaced, left out of the file they write (gltf_prune.h).
#include "gltf_prune.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

namespace animorder::io {
namespace {

const char* const kOrders = "ANIMORDER_animated_triangle_orders";
const char* const kInstancing = "EXT_mesh_gpu_instancing";

// Extensions whose references to accessors and buffer views are known here: none, or (ours,
// EXT_mesh_gpu_instancing) followed by for_each_accessor_reference.
bool known_extension(const std::string& name) {
    static const char* const kKnown[] = {kOrders,
                                         kInstancing,
                                         "KHR_texture_transform",
                                         "KHR_texture_basisu",
                                         "EXT_texture_webp",
                                         "EXT_texture_avif",
                                         "MSFT_texture_dds",
                                         "KHR_mesh_quantization",
                                         "KHR_lights_punctual",
                                         "KHR_xmp_json_ld",
                                         "KHR_animation_pointer"};
    if (name.rfind("KHR_materials_", 0) == 0) return true;  // material properties and textures only
    return std::find(std::begin(kKnown), std::end(kKnown), name) != std::end(kKnown);
}

// The first extension the model uses whose references are not known here, or "" when none.
std::string unknown_extension(const tinygltf::Model& model) {
    std::string first;
    const auto known = [&first](const tinygltf::ExtensionMap& map) {
        for (const auto& entry : map)
            if (!known_extension(entry.first)) {
                first = entry.first;
                return false;
            }
        return true;
    };
    const auto all_known = [&known](const auto& objects) {
        return std::all_of(objects.begin(), objects.end(), [&known](const auto& o) { return known(o.extensions); });
    };
    for (const std::string& name : model.extensionsUsed)
        if (!known_extension(name)) return name;
    for (const std::string& name : model.extensionsRequired)
        if (!known_extension(name)) return name;
    if (!known(model.extensions)) return first;
    for (const tinygltf::Mesh& mesh : model.meshes)
        if (!known(mesh.extensions) || !all_known(mesh.primitives)) return first;
    for (const tinygltf::Animation& animation : model.animations) {
        if (!known(animation.extensions) || !all_known(animation.samplers) || !all_known(animation.channels))
            return first;
        for (const tinygltf::AnimationChannel& channel : animation.channels)
            if (!known(channel.target_extensions)) return first;
    }
    const bool rest_known = all_known(model.nodes) && all_known(model.accessors) && all_known(model.bufferViews) &&
                            all_known(model.buffers) && all_known(model.images) && all_known(model.skins) &&
                            all_known(model.materials) && all_known(model.textures) && all_known(model.samplers) &&
                            all_known(model.cameras) && all_known(model.scenes);
    return rest_known ? "" : first;
}

// A JSON number as an index: an integer, or a real with an integer value, in [0, INT_MAX]; any
// other value names nothing (and is never converted: a real beyond int is undefined behaviour).
bool as_index(const tinygltf::Value& v, int& out) {
    if (v.IsInt()) {
        out = v.Get<int>();
        return out >= 0;
    }
    if (!v.IsReal()) return false;
    const double d = v.Get<double>();
    if (!(d >= 0.0 && d <= double(INT_MAX) && d == std::floor(d))) return false;
    out = int(d);
    return true;
}

// An integer member of an extension object, as a reference that can be read and rewritten.
struct ValueReference {
    tinygltf::Value* object;
    std::string key;
};

void integer_members(tinygltf::Value& object, const char* key, std::vector<ValueReference>& out) {
    int index;
    if (!object.IsObject() || !object.Has(key) || !as_index(object.Get(key), index)) return;
    out.push_back({&object, key});
}

// Every place of `model` that names an accessor: visit(index) for core glTF's int members (which
// may rewrite it), and the integer members of the two known extensions that name accessors.
void for_each_accessor_reference(tinygltf::Model& model, const std::function<void(int&)>& visit) {
    std::vector<ValueReference> in_extensions;
    for (tinygltf::Mesh& mesh : model.meshes)
        for (tinygltf::Primitive& prim : mesh.primitives) {
            for (auto& attribute : prim.attributes) visit(attribute.second);
            visit(prim.indices);
            for (auto& target : prim.targets)
                for (auto& attribute : target) visit(attribute.second);
            const auto ours = prim.extensions.find(kOrders);
            if (ours != prim.extensions.end()) integer_members(ours->second, "orders", in_extensions);
        }
    for (tinygltf::Skin& skin : model.skins) visit(skin.inverseBindMatrices);
    for (tinygltf::Animation& animation : model.animations)
        for (tinygltf::AnimationSampler& sampler : animation.samplers) {
            visit(sampler.input);
            visit(sampler.output);
        }
    for (tinygltf::Node& node : model.nodes) {
        const auto instancing = node.extensions.find(kInstancing);
        if (instancing == node.extensions.end() || !instancing->second.Has("attributes")) continue;
        tinygltf::Value& attributes = instancing->second.Get<tinygltf::Value::Object>()["attributes"];
        if (!attributes.IsObject()) continue;
        for (auto& entry : attributes.Get<tinygltf::Value::Object>())
            if (int index; as_index(entry.second, index)) in_extensions.push_back({&attributes, entry.first});
    }
    const auto root = model.extensions.find(kOrders);
    if (root != model.extensions.end() && root->second.Has("clips") && root->second.Get("clips").IsArray()) {
        tinygltf::Value& clips = root->second.Get<tinygltf::Value::Object>()["clips"];
        for (tinygltf::Value& clip : clips.Get<tinygltf::Value::Array>()) {
            integer_members(clip, "table", in_extensions);
            integer_members(clip, "centers", in_extensions);
        }
    }
    for (const ValueReference& r : in_extensions) {
        tinygltf::Value& member = r.object->Get<tinygltf::Value::Object>()[r.key];
        int index = 0;
        as_index(member, index);  // true: listed so above
        const int before = index;
        visit(index);
        if (index != before) member = tinygltf::Value(index);  // a count leaves the model as it was
    }
}

void for_each_view_reference(tinygltf::Model& model, const std::function<void(int&)>& visit) {
    for (tinygltf::Accessor& a : model.accessors) {
        visit(a.bufferView);
        if (a.sparse.isSparse) {
            visit(a.sparse.indices.bufferView);
            visit(a.sparse.values.bufferView);
        }
    }
    for (tinygltf::Image& image : model.images) visit(image.bufferView);
}

// Leaves the marked items out of `items`: the last unmarked ones move into the marked places
// (fewest indices changed). Returns each old index's new one (-1: left out).
template <typename T>
std::vector<int> remove_marked(std::vector<T>& items, const std::vector<bool>& marked) {
    std::vector<int> to(items.size());
    for (size_t i = 0; i < items.size(); ++i) to[i] = int(i);
    size_t end = items.size();
    for (size_t i = 0; i < end; ++i) {
        if (!marked[i]) continue;
        to[i] = -1;
        while (end > i + 1 && marked[end - 1]) to[--end] = -1;  // marked at the end: just dropped
        if (end <= i + 1) {
            end = i;
            break;
        }
        items[i] = std::move(items[end - 1]);
        to[end - 1] = int(i);
        --end;
    }
    items.resize(end);
    return to;
}

// [begin, end) ranges sorted and merged.
std::vector<std::pair<size_t, size_t>> merged(std::vector<std::pair<size_t, size_t>> ranges) {
    std::sort(ranges.begin(), ranges.end());
    std::vector<std::pair<size_t, size_t>> out;
    for (const auto& r : ranges) {
        if (r.first >= r.second) continue;
        if (!out.empty() && r.first <= out.back().second)
            out.back().second = std::max(out.back().second, r.second);
        else
            out.push_back(r);
    }
    return out;
}

// Drops from each buffer the bytes of the left-out views that no kept view covers, the later
// bytes moving down by a multiple of 4 (the byte offsets a view or accessor needs aligned keep
// their alignment); the kept views' offsets follow. Returns the buffers it left without a byte.
std::vector<bool> drop_bytes(tinygltf::Model& model, const std::vector<tinygltf::BufferView>& dropped) {
    std::vector<bool> emptied(model.buffers.size(), false);
    for (size_t b = 0; b < model.buffers.size(); ++b) {
        std::vector<unsigned char>& data = model.buffers[b].data;
        std::vector<std::pair<size_t, size_t>> kept, gone;
        const auto range = [&](const tinygltf::BufferView& v) {
            const size_t begin = std::min(v.byteOffset, data.size());
            return std::make_pair(begin, begin + std::min(v.byteLength, data.size() - begin));
        };
        for (const tinygltf::BufferView& v : model.bufferViews)
            if (v.buffer == int(b)) kept.push_back(range(v));
        for (const tinygltf::BufferView& v : dropped)  // with the padding to the next multiple of 4
            if (v.buffer == int(b)) {
                const auto r = range(v);
                gone.emplace_back(r.first, std::min(data.size(), (r.second + 3) / 4 * 4));
            }
        kept = merged(kept);
        gone = merged(gone);
        // The runs to leave out: the dropped views' bytes less the kept ones', each run but one
        // ending the buffer shortened to a multiple of 4 bytes (its last bytes stay).
        std::vector<std::pair<size_t, size_t>> leave;
        size_t k = 0;
        for (auto [begin, end] : gone) {
            while (begin < end) {
                while (k < kept.size() && kept[k].second <= begin) ++k;
                const size_t stop = k < kept.size() ? std::min(end, std::max(begin, kept[k].first)) : end;
                // Nothing after the buffer's last run moves: it leaves whole.
                const size_t length = stop == data.size() ? stop - begin : (stop - begin) / 4 * 4;
                if (length) leave.emplace_back(begin, begin + length);
                begin = k < kept.size() && stop < end ? std::min(end, kept[k].second) : end;
            }
        }
        if (leave.empty()) continue;
        std::vector<unsigned char> out;
        out.reserve(data.size());
        size_t from = 0;
        for (const auto& r : leave) {
            out.insert(out.end(), data.begin() + std::ptrdiff_t(from), data.begin() + std::ptrdiff_t(r.first));
            from = r.second;
        }
        out.insert(out.end(), data.begin() + std::ptrdiff_t(from), data.end());
        for (tinygltf::BufferView& v : model.bufferViews) {
            if (v.buffer != int(b)) continue;
            size_t shift = 0;  // the bytes left out before the view (inside it only when it is empty)
            for (const auto& r : leave)
                if (r.first < v.byteOffset) shift += std::min(r.second, v.byteOffset) - r.first;
            v.byteOffset -= shift;
        }
        data.swap(out);
        emptied[b] = data.empty();
    }
    return emptied;
}

}  // namespace

std::vector<int> accessors_to_replace(const tinygltf::Model& model,
                                      const std::vector<std::pair<int, int>>& primitives) {
    std::vector<int> replaced;
    for (const auto& [mesh, primitive] : primitives)
        if (mesh >= 0 && size_t(mesh) < model.meshes.size() && primitive >= 0 &&
            size_t(primitive) < model.meshes[size_t(mesh)].primitives.size())
            replaced.push_back(model.meshes[size_t(mesh)].primitives[size_t(primitive)].indices);
    // The extension's own members: the primitives' orders, the clips' tables and centres.
    for (const tinygltf::Mesh& mesh : model.meshes)
        for (const tinygltf::Primitive& prim : mesh.primitives) {
            const auto ours = prim.extensions.find(kOrders);
            int index;
            if (ours != prim.extensions.end() && ours->second.Has("orders") &&
                as_index(ours->second.Get("orders"), index))
                replaced.push_back(index);
        }
    const auto root = model.extensions.find(kOrders);
    if (root != model.extensions.end() && root->second.Has("clips") && root->second.Get("clips").IsArray())
        for (const tinygltf::Value& clip : root->second.Get("clips").Get<tinygltf::Value::Array>())
            for (const char* key : {"table", "centers"})
                if (int index; clip.IsObject() && clip.Has(key) && as_index(clip.Get(key), index))
                    replaced.push_back(index);
    return replaced;
}

std::vector<int> begin_replacing(tinygltf::Model& model, const std::vector<std::pair<int, int>>& primitives) {
    std::vector<int> replaced = accessors_to_replace(model, primitives);
    for (tinygltf::Mesh& mesh : model.meshes)
        for (tinygltf::Primitive& prim : mesh.primitives) prim.extensions.erase(kOrders);
    return replaced;
}

Renumbering finish_replacing(tinygltf::Model& model, const std::vector<int>& replaced, const std::string& path,
                             std::string* note) {
    std::string unknown;
    Renumbering renumbering;
    if (drop_replaced_accessors(model, replaced, &unknown, &renumbering) || !note) return renumbering;
    *note = path + " uses extension " + unknown +
            ", whose references to accessors animorder does not know: the indices and orders the new orders replace "
            "stay in the output, unused (renumbering could break what the extension names)";
    return renumbering;
}

bool drop_replaced_accessors(tinygltf::Model& model, const std::vector<int>& replaced, std::string* unknown,
                             Renumbering* renumbering) {
    // Accessors: those replaced that nothing names any more.
    std::vector<int> uses(model.accessors.size(), 0);
    for_each_accessor_reference(model, [&](int& a) {
        if (a >= 0 && size_t(a) < uses.size()) ++uses[size_t(a)];
    });
    std::vector<bool> drop_accessor(model.accessors.size(), false);
    for (const int a : replaced)
        if (a >= 0 && size_t(a) < uses.size() && uses[size_t(a)] == 0) drop_accessor[size_t(a)] = true;
    if (std::find(drop_accessor.begin(), drop_accessor.end(), true) == drop_accessor.end()) return true;
    const std::string first_unknown = unknown_extension(model);
    if (!first_unknown.empty()) {  // what it names is unknown: drop_accessor may be in use
        if (unknown) *unknown = first_unknown;
        return false;
    }

    // Views: those the dropped accessors read that nothing else names.
    std::vector<bool> view_of_dropped(model.bufferViews.size(), false);
    for (size_t a = 0; a < model.accessors.size(); ++a) {
        if (!drop_accessor[a]) continue;
        const tinygltf::Accessor& accessor = model.accessors[a];
        for (const int v : {accessor.bufferView, accessor.sparse.isSparse ? accessor.sparse.indices.bufferView : -1,
                            accessor.sparse.isSparse ? accessor.sparse.values.bufferView : -1})
            if (v >= 0 && size_t(v) < view_of_dropped.size()) view_of_dropped[size_t(v)] = true;
    }
    const std::vector<int> accessor_to = remove_marked(model.accessors, drop_accessor);
    for_each_accessor_reference(model, [&](int& a) {
        if (a >= 0 && size_t(a) < accessor_to.size()) a = accessor_to[size_t(a)];
    });

    std::vector<bool> view_used(model.bufferViews.size(), false);
    for_each_view_reference(model, [&](int& v) {
        if (v >= 0 && size_t(v) < view_used.size()) view_used[size_t(v)] = true;
    });
    std::vector<bool> drop_view(model.bufferViews.size(), false);
    std::vector<tinygltf::BufferView> dropped;
    for (size_t v = 0; v < model.bufferViews.size(); ++v)
        if (view_of_dropped[v] && !view_used[v]) {
            drop_view[v] = true;
            dropped.push_back(model.bufferViews[v]);
        }
    const std::vector<int> view_to = remove_marked(model.bufferViews, drop_view);
    for_each_view_reference(model, [&](int& v) {
        if (v >= 0 && size_t(v) < view_to.size()) v = view_to[size_t(v)];
    });
    // A buffer left without a byte (it held only dropped views, say the indices of a file whose
    // every view has its own .bin) would be written with byteLength 0, which glTF forbids: it
    // leaves too, when no view names it.
    std::vector<bool> drop_buffer = drop_bytes(model, dropped);
    for (const tinygltf::BufferView& v : model.bufferViews)
        if (v.buffer >= 0 && size_t(v.buffer) < drop_buffer.size()) drop_buffer[size_t(v.buffer)] = false;
    const std::vector<int> buffer_to = remove_marked(model.buffers, drop_buffer);
    for (tinygltf::BufferView& v : model.bufferViews)
        if (v.buffer >= 0 && size_t(v.buffer) < buffer_to.size()) v.buffer = buffer_to[size_t(v.buffer)];
    if (renumbering) *renumbering = {accessor_to, view_to, buffer_to};
    return true;
}

}  // namespace animorder::io
