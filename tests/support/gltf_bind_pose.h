// Test support: the bind-pose triangles of a glTF file (all TRIANGLES primitives, POSITION
// and indices only, node transforms ignored) as a one-keyframe AnimatedMesh. Only for checks
// that need a real character's shape, until the asset loaders exist; include it in one
// translation unit (it defines tinygltf's implementation).
#pragma once

#include "animorder/animated_mesh.h"

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <stdexcept>
#include <string>

namespace animorder::test {

inline AnimatedMesh load_gltf_bind_pose(const std::string& path) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                             void*) { return true; },
                          nullptr);
    std::string error, warning;
    const bool binary = path.size() > 4 && path.substr(path.size() - 4) == ".glb";
    const bool ok = binary ? loader.LoadBinaryFromFile(&model, &error, &warning, path)
                           : loader.LoadASCIIFromFile(&model, &error, &warning, path);
    if (!ok) throw std::runtime_error(path + ": " + error);

    auto read_floats = [&](int accessor_index, std::vector<float>& out) {
        const tinygltf::Accessor& a = model.accessors[size_t(accessor_index)];
        const tinygltf::BufferView& view = model.bufferViews[size_t(a.bufferView)];
        const unsigned char* base = model.buffers[size_t(view.buffer)].data.data() + view.byteOffset + a.byteOffset;
        const size_t stride = view.byteStride ? view.byteStride : 12;
        for (size_t i = 0; i < a.count; ++i) {
            const float* p = reinterpret_cast<const float*>(base + i * stride);
            out.insert(out.end(), p, p + 3);
        }
        return a.count;
    };
    AnimatedMesh mesh;
    mesh.name = path;
    for (const tinygltf::Mesh& m : model.meshes)
        for (const tinygltf::Primitive& prim : m.primitives) {
            if (prim.mode != TINYGLTF_MODE_TRIANGLES || prim.indices < 0) continue;
            const uint32_t base_vertex = uint32_t(mesh.keyframe_positions.size() / 3);
            read_floats(prim.attributes.at("POSITION"), mesh.keyframe_positions);
            const tinygltf::Accessor& a = model.accessors[size_t(prim.indices)];
            const tinygltf::BufferView& view = model.bufferViews[size_t(a.bufferView)];
            const unsigned char* data = model.buffers[size_t(view.buffer)].data.data() + view.byteOffset + a.byteOffset;
            const size_t first = mesh.indices.size();
            for (size_t i = 0; i < a.count; ++i) {
                uint32_t v = 0;
                if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) v = data[i];
                else if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) v = reinterpret_cast<const uint16_t*>(data)[i];
                else v = reinterpret_cast<const uint32_t*>(data)[i];
                mesh.indices.push_back(base_vertex + v);
            }
            mesh.primitives.push_back({m.name, first, mesh.indices.size() - first});
        }
    mesh.vertex_count = mesh.keyframe_positions.size() / 3;
    mesh.clips.push_back({"bind", 0.0, 30.0, 0, 1});
    return mesh;
}

}  // namespace animorder::test
