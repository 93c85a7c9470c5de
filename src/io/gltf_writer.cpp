// glTF output: the input file with its primitives drawn in the new orders.
//
// Every viewer draws a primitive's `indices`: that accessor now holds the fallback order (the
// buffer most nodes chose). The k orders of the primitive are one accessor, order after order,
// named by the primitive's ANIMORDER_animated_triangle_orders extension; the runtime lookup
// tables and frame centres are accessors named by the root extension object (docs/extension).
// The extension is used, never required: a loader that knows nothing of animorder still gets a
// valid, better-ordered file. Everything else — materials, textures, skins,
// animations, other extras and extensions, vertex arrays — is written back as read: the new
// indices refer to the file's own vertices. New bytes are appended to buffer 0; what the new ones
// replace (the drawn indices, orders a previous run wrote) leaves the file (gltf_prune.h).
#include "animorder/gltf_writer.h"

#include "animorder/animated_mesh.h"
#include "animorder/load.h"
#include "animorder/methods.h"
#include "animorder/selection_table.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include "gltf_buffer.h"
#include "gltf_prune.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

namespace animorder {
namespace {

const char* const kOrdersExtension = "ANIMORDER_animated_triangle_orders";

// The primitive's vertex indices (local to its vertices) of `count` orders stored one after the
// other, as one SCALAR accessor of the smallest index type that holds them, over its own buffer
// view (ELEMENT_ARRAY_BUFFER).
int append_indices(tinygltf::Model& model, const std::vector<uint32_t>& local, const std::string& name) {
    const uint32_t largest = local.empty() ? 0 : *std::max_element(local.begin(), local.end());
    int view;
    int component;
    if (largest < 65535) {  // 65535 is the primitive-restart value: never used as an index
        std::vector<uint16_t> shorts(local.begin(), local.end());
        view = io::append_buffer_view(model, shorts.data(), shorts.size() * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        component = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
        view = io::append_buffer_view(model, local.data(), local.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        component = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    const int accessor = io::append_accessor(model, view, component, TINYGLTF_TYPE_SCALAR, local.size(), name);
    if (!local.empty()) {
        model.accessors[size_t(accessor)].minValues = {double(*std::min_element(local.begin(), local.end()))};
        model.accessors[size_t(accessor)].maxValues = {double(largest)};
    }
    return accessor;
}

void add_extension_used(tinygltf::Model& model, const std::string& name) {
    if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), name) == model.extensionsUsed.end())
        model.extensionsUsed.push_back(name);
    model.extensionsRequired.erase(std::remove(model.extensionsRequired.begin(), model.extensionsRequired.end(), name),
                                   model.extensionsRequired.end());
}

}  // namespace

void check_gltf_output(const std::string& input_path, const AnimatedMesh& mesh) {
    for (const Primitive& p : mesh.primitives)
        if (p.source_mesh < 0) throw LoadError(input_path + ": the mesh was not read from this file");
}

std::string gltf_with_orders(const std::string& input_path, const std::string& output_path, const AnimatedMesh& mesh,
                             const MethodBuffers& buffers, uint32_t fallback, const Framing& framing,
                             const std::string& method, bool binary, std::string* note) {
    if (fallback >= buffers.orders.size()) throw LoadError(input_path + ": no buffer " + std::to_string(fallback));
    check_gltf_output(input_path, mesh);
    tinygltf::Model model = io::read_model(input_path);
    // A file primitive several nodes draw (instances) is written once, from its first instance:
    // run_method gave them one order (tie_instances), which is checked here.
    std::map<std::pair<int, int>, const Primitive*> first;
    std::vector<const Primitive*> written;
    for (const Primitive& p : mesh.primitives) {
        const auto [at, inserted] = first.emplace(std::make_pair(p.source_mesh, p.source_primitive), &p);
        if (inserted) {
            if (p.index_count > 0) written.push_back(&p);
            continue;
        }
        const Primitive& f = *at->second;
        for (const std::vector<uint32_t>& order : buffers.orders)
            for (size_t i = 0; f.index_count == p.index_count && i < p.index_count / 3; ++i)
                if (order[p.first_index / 3 + i] - p.first_index / 3 !=
                    order[f.first_index / 3 + i] - f.first_index / 3)
                    throw LoadError(input_path + ": mesh " + std::to_string(p.source_mesh) +
                                    " is drawn by several nodes in different orders; glTF has one per primitive");
    }
    std::vector<std::pair<int, int>> rewritten;
    for (const Primitive* p : written) rewritten.emplace_back(p->source_mesh, p->source_primitive);
    const std::vector<int> replaced = io::begin_replacing(model, rewritten);
    std::vector<std::vector<uint32_t>> index_buffers(buffers.orders.size(), std::vector<uint32_t>(mesh.indices.size()));
    for (size_t b = 0; b < buffers.orders.size(); ++b) {
        apply_triangle_order(index_buffers[b].data(), mesh.indices.data(), buffers.orders[b].data(),
                             mesh.triangle_count());
        to_file_winding(mesh, index_buffers[b].data());  // a mirrored primitive's triangles as the file has them
    }

    const size_t k = buffers.orders.size();
    for (const Primitive* written_primitive : written) {  // no empty one: glTF has no empty accessor
        const Primitive& p = *written_primitive;
        tinygltf::Primitive& prim = model.meshes[size_t(p.source_mesh)].primitives[size_t(p.source_primitive)];
        // Order b of the primitive is elements [b·n, (b+1)·n) of one accessor (docs/extension).
        std::vector<uint32_t> all(k * p.index_count);
        for (size_t b = 0; b < k; ++b)
            for (size_t i = 0; i < p.index_count; ++i)
                all[b * p.index_count + i] = uint32_t(index_buffers[b][p.first_index + i] - p.vertex_base);
        const int orders = append_indices(model, all, "animorder orders");
        const std::vector<uint32_t> shown(all.begin() + ptrdiff_t(fallback * p.index_count),
                                          all.begin() + ptrdiff_t((fallback + 1) * p.index_count));
        prim.indices = append_indices(model, shown, "animorder fallback order");
        prim.mode = TINYGLTF_MODE_TRIANGLES;  // strips and fans were converted to lists
        tinygltf::Value::Object ours;
        ours["orders"] = tinygltf::Value(orders);
        ours["orderCount"] = tinygltf::Value(int(k));
        prim.extensions[kOrdersExtension] = tinygltf::Value(ours);
    }

    tinygltf::Value::Array clips;
    for (size_t c = 0; c < mesh.clips.size() && c < buffers.tables.size(); ++c) {
        const SelectionTable& t = buffers.tables[c];
        const int cells = io::append_accessor(model, io::append_buffer_view(model, t.cells.data(), t.cells.size(), 0),
                                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_SCALAR,
                                              t.cells.size(), "animorder table " + mesh.clips[c].name);
        std::vector<float> centres(
            framing.centres.begin() + ptrdiff_t(3 * mesh.clips[c].first_keyframe),
            framing.centres.begin() + ptrdiff_t(3 * (mesh.clips[c].first_keyframe + mesh.clips[c].keyframe_count)));
        const int centre = io::append_accessor(
            model, io::append_buffer_view(model, centres.data(), centres.size() * 4, 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
            TINYGLTF_TYPE_VEC3, mesh.clips[c].keyframe_count, "animorder centres " + mesh.clips[c].name);
        tinygltf::Value::Object clip;
        clip["name"] = tinygltf::Value(mesh.clips[c].name);
        if (mesh.clips[c].source_animation >= 0) clip["animation"] = tinygltf::Value(mesh.clips[c].source_animation);
        clip["startTime"] = tinygltf::Value(mesh.clips[c].start_time_s);
        clip["sampleRate"] = tinygltf::Value(mesh.clips[c].sample_rate);
        clip["keyframes"] = tinygltf::Value(int(t.keyframes));
        clip["bufferBase"] = tinygltf::Value(int(buffers.table_base[c]));
        clip["thetaSteps"] = tinygltf::Value(int(t.theta_steps));
        clip["phiSteps"] = tinygltf::Value(int(t.phi_steps));
        clip["table"] = tinygltf::Value(cells);
        clip["centers"] = tinygltf::Value(centre);
        clips.push_back(tinygltf::Value(clip));
    }
    tinygltf::Value::Object root;
    root["method"] = tinygltf::Value(method);
    root["bufferCount"] = tinygltf::Value(int(k));
    root["fallback"] = tinygltf::Value(int(fallback));
    root["clips"] = tinygltf::Value(clips);
    model.extensions[kOrdersExtension] = tinygltf::Value(root);
    add_extension_used(model, kOrdersExtension);
    // What the new orders replace leaves the file: no growth run after run.
    const io::Renumbering renumbering = io::finish_replacing(model, replaced, input_path, note);
    // Buffers embedded (the output stands alone); image files stay where they are, a relative URI
    // re-expressed from the output's folder (gltf_buffer.h).
    return io::write_model(model, input_path, output_path, binary, renumbering);
}

}  // namespace animorder
