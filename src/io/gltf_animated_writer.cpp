// glTF output of a whole AnimatedMesh as a new file (what `animorder subdivide` writes): a mesh
// that has no source file any more, so its animation is stored as vertex keyframes.
//
// One node, one mesh, one glTF primitive per Primitive (its referenced vertices in ascending
// order, POSITION = keyframe 0, uint32 indices), one morph target per keyframe (POSITION deltas
// from keyframe 0; target 0 is an accessor without a buffer view, which glTF defines as all
// zeros), and one animation per clip that animates the node's morph `weights` with LINEAR
// interpolation: key j at j / sample_rate holds weight 1 on target first_keyframe + j and 0
// elsewhere. load_gltf sampling at the clip's rate lands on those keys and gives the keyframes
// back (up to the float rounding of base + delta). A mesh without clips gets no animation.
#include "animorder/gltf_animated_writer.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"

#include "gltf_buffer.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <sstream>

namespace animorder {
namespace {

// A float accessor of count elements of `width` components; min and max per component when
// `bounds` (glTF requires them for POSITION and animation inputs).
int add_floats(tinygltf::Model& model, const std::vector<float>& values, int type, size_t width, int target,
               bool bounds) {
    tinygltf::Accessor a;
    a.bufferView = io::append_buffer_view(model, values.data(), values.size() * sizeof(float), target);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.type = type;
    a.count = values.size() / width;
    if (bounds && a.count) {
        a.minValues.assign(values.begin(), values.begin() + ptrdiff_t(width));
        a.maxValues = a.minValues;
        for (size_t i = 0; i < values.size(); ++i) {
            a.minValues[i % width] = std::min(a.minValues[i % width], double(values[i]));
            a.maxValues[i % width] = std::max(a.maxValues[i % width], double(values[i]));
        }
    }
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
}

}  // namespace

std::string gltf_animated_mesh(const AnimatedMesh& mesh, bool binary) {
    validate_animated_mesh(mesh);
    const size_t keyframes = mesh.keyframe_count();
    if (keyframes == 0 || mesh.indices.empty()) throw InvalidInput("glTF output needs triangles and a keyframe");

    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "animorder";
    model.buffers.emplace_back();
    tinygltf::Mesh gmesh;
    gmesh.name = mesh.name.empty() ? "animorder" : mesh.name;
    gmesh.weights.assign(keyframes, 0.0);
    const float* base = mesh.keyframe(0);

    std::vector<uint32_t> local(mesh.vertex_count, UINT32_MAX);
    for (const Primitive& p : mesh.primitives) {
        if (p.index_count == 0) continue;
        // The primitive's vertices, ascending, numbered from 0.
        std::vector<uint32_t> used(mesh.indices.begin() + ptrdiff_t(p.first_index),
                                   mesh.indices.begin() + ptrdiff_t(p.first_index + p.index_count));
        std::sort(used.begin(), used.end());
        used.erase(std::unique(used.begin(), used.end()), used.end());
        for (size_t i = 0; i < used.size(); ++i) local[used[i]] = uint32_t(i);

        tinygltf::Primitive prim;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        std::vector<uint32_t> ib(p.index_count);
        for (size_t i = 0; i < p.index_count; ++i) ib[i] = local[mesh.indices[p.first_index + i]];
        tinygltf::Accessor indices;
        indices.bufferView =
            io::append_buffer_view(model, ib.data(), ib.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        indices.type = TINYGLTF_TYPE_SCALAR;
        indices.count = ib.size();
        indices.minValues = {0.0};
        indices.maxValues = {double(used.size() - 1)};
        model.accessors.push_back(indices);
        prim.indices = int(model.accessors.size() - 1);

        std::vector<float> values(used.size() * 3);
        for (size_t i = 0; i < used.size(); ++i)
            for (int c = 0; c < 3; ++c) values[3 * i + size_t(c)] = base[3 * size_t(used[i]) + size_t(c)];
        prim.attributes["POSITION"] =
            add_floats(model, values, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);

        for (size_t k = 0; k < keyframes; ++k) {
            if (k == 0) {  // no buffer view: zeros by definition
                tinygltf::Accessor zeros;
                zeros.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
                zeros.type = TINYGLTF_TYPE_VEC3;
                zeros.count = used.size();
                zeros.minValues = {0.0, 0.0, 0.0};
                zeros.maxValues = {0.0, 0.0, 0.0};
                model.accessors.push_back(zeros);
                prim.targets.push_back({{"POSITION", int(model.accessors.size() - 1)}});
                continue;
            }
            const float* frame = mesh.keyframe(k);
            for (size_t i = 0; i < used.size(); ++i)
                for (int c = 0; c < 3; ++c) {
                    const size_t at = 3 * size_t(used[i]) + size_t(c);
                    values[3 * i + size_t(c)] = frame[at] - base[at];
                }
            prim.targets.push_back(
                {{"POSITION", add_floats(model, values, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true)}});
        }
        for (uint32_t v : used) local[v] = UINT32_MAX;
        // A material only where the primitive differs from glTF's default (single-sided OPAQUE).
        if (p.double_sided || p.alpha_mode != AlphaMode::Opaque) {
            tinygltf::Material material;
            material.name = p.name;
            material.doubleSided = p.double_sided;
            material.alphaMode = alpha_mode_name(p.alpha_mode);
            // Blended surfaces are translucent: an alpha below 1, so that optimisers which turn a
            // BLEND material without any transparency into OPAQUE (gltfpack does) keep it blended.
            if (p.alpha_mode == AlphaMode::Blend) material.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 0.5};
            model.materials.push_back(material);
            prim.material = int(model.materials.size() - 1);
        }
        gmesh.primitives.push_back(std::move(prim));
    }
    model.meshes.push_back(std::move(gmesh));

    tinygltf::Node node;
    node.name = model.meshes[0].name;
    node.mesh = 0;
    model.nodes.push_back(node);
    tinygltf::Scene scene;
    scene.nodes = {0};
    model.scenes.push_back(scene);
    model.defaultScene = 0;

    for (const Clip& clip : mesh.clips) {
        if (!(clip.sample_rate > 0)) throw InvalidInput("clip '" + clip.name + "' has no positive sample rate");
        std::vector<float> times(clip.keyframe_count), weights(clip.keyframe_count * keyframes, 0.0f);
        for (size_t j = 0; j < clip.keyframe_count; ++j) {
            times[j] = float(double(j) / clip.sample_rate);
            weights[j * keyframes + clip.first_keyframe + j] = 1.0f;
        }
        tinygltf::AnimationSampler sampler;
        sampler.input = add_floats(model, times, TINYGLTF_TYPE_SCALAR, 1, 0, true);
        sampler.output = add_floats(model, weights, TINYGLTF_TYPE_SCALAR, 1, 0, false);
        sampler.interpolation = "LINEAR";
        tinygltf::AnimationChannel channel;
        channel.sampler = 0;
        channel.target_node = 0;
        channel.target_path = "weights";
        tinygltf::Animation animation;
        animation.name = clip.name;
        animation.samplers.push_back(sampler);
        animation.channels.push_back(channel);
        model.animations.push_back(std::move(animation));
    }

    tinygltf::TinyGLTF writer;
    std::ostringstream out;
    if (!writer.WriteGltfSceneToStream(&model, out, !binary, binary))
        throw LoadError(mesh.name + ": writing the glTF output failed");
    return out.str();
}

}  // namespace animorder
