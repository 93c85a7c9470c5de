// Characters in the formats assimp reads (FBX, Collada, .X, .b3d, MD5, …) into keyframes, and
// Mixamo-style clip files: animation-only files whose channels drive the character's joints by
// name.
//
// Assimp (Debian's libassimp) parses the files; this file evaluates them like the glTF loader:
// node hierarchy with keyed position/rotation/scaling (linear, rotations slerped), bones as
// joint = node global transform · offset matrix (assimp's inverse bind), linear blend skinning
// with weights normalised, every clip sampled at a fixed rate from its first to its last tick.
// Triangulated on import (polygons become triangle fans); points and lines are dropped by
// assimp's primitive sorting and reported if nothing triangular is left.
#include "animorder/assimp_loader.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/skinning.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <memory>
#include <cmath>
#include <filesystem>
#include <map>

namespace animorder {
namespace {

aiMatrix4x4 interpolate(const aiNodeAnim* channel, double tick, const aiMatrix4x4& rest) {
    aiVector3D t, s;
    aiQuaternion r;
    rest.Decompose(s, r, t);
    auto key_index = [tick](const auto* keys, unsigned count) {
        unsigned i = 0;
        while (i + 1 < count && keys[i + 1].mTime <= tick) ++i;
        return i;
    };
    auto blend = [tick](double t0, double t1) { return t1 > t0 ? std::clamp((tick - t0) / (t1 - t0), 0.0, 1.0) : 0.0; };
    // Position and scaling keys interpolate alike; rotations slerp.
    auto vector_at = [&](const aiVectorKey* keys, unsigned count, aiVector3D& out) {
        if (!count) return;
        const unsigned i = key_index(keys, count);
        const aiVectorKey& a = keys[i];
        const aiVectorKey& b = keys[std::min(i + 1, count - 1)];
        out = a.mValue + (b.mValue - a.mValue) * float(blend(a.mTime, b.mTime));
    };
    vector_at(channel->mPositionKeys, channel->mNumPositionKeys, t);
    vector_at(channel->mScalingKeys, channel->mNumScalingKeys, s);
    if (channel->mNumRotationKeys) {
        const unsigned i = key_index(channel->mRotationKeys, channel->mNumRotationKeys);
        const aiQuatKey& a = channel->mRotationKeys[i];
        const aiQuatKey& b = channel->mRotationKeys[std::min(i + 1, channel->mNumRotationKeys - 1)];
        aiQuaternion::Interpolate(r, a.mValue, b.mValue, float(blend(a.mTime, b.mTime)));
        r.Normalize();
    }
    return aiMatrix4x4(s, r, t);
}

struct Flat {
    std::vector<const aiNode*> nodes;  // parents first
    std::vector<int> parent;
    std::map<std::string, size_t> by_name;
};

void flatten(const aiNode* node, int parent, Flat& flat) {
    const size_t id = flat.nodes.size();
    flat.nodes.push_back(node);
    flat.parent.push_back(parent);
    flat.by_name.emplace(node->mName.C_Str(), id);
    for (unsigned c = 0; c < node->mNumChildren; ++c) flatten(node->mChildren[c], int(id), flat);
}

const aiScene* import(Assimp::Importer& importer, const std::string& path) {
    if (!std::filesystem::exists(path)) throw LoadError(path + ": cannot open file");
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_SortByPType |
                                                       aiProcess_JoinIdenticalVertices | aiProcess_ValidateDataStructure);
    if (!scene || !scene->mRootNode) {
        std::string why = importer.GetErrorString();
        std::replace(why.begin(), why.end(), '\n', ' ');
        throw LoadError(path + ": not readable by assimp: " + why);
    }
    return scene;
}

}  // namespace

AnimatedMesh load_assimp(const std::string& path, const std::vector<std::string>& clip_files, const LoadOptions& options) {
    if (!(options.sample_rate > 0 && options.sample_rate <= 1000)) throw LoadError(path + ": sample rate must be in (0, 1000]");
    Assimp::Importer importer;
    const aiScene* scene = import(importer, path);
    Flat flat;
    flatten(scene->mRootNode, -1, flat);

    // Meshes in node order, each with its own vertices (vertex identity kept per mesh).
    struct Part {
        const aiMesh* mesh;
        size_t node;
        size_t vertex_base;
        std::vector<uint16_t> joints;  // 8 influences, the strongest
        std::vector<float> weights;
        std::vector<size_t> bone_node;  // per bone: its node
        std::vector<aiMatrix4x4> offset;
    };
    constexpr size_t kInfluences = 8;
    AnimatedMesh mesh;
    mesh.name = path;
    std::vector<Part> parts;
    for (size_t n = 0; n < flat.nodes.size(); ++n)
        for (unsigned k = 0; k < flat.nodes[n]->mNumMeshes; ++k) {
            const aiMesh* m = scene->mMeshes[flat.nodes[n]->mMeshes[k]];
            if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || m->mNumFaces == 0) continue;
            Part part{m, n, mesh.vertex_count, {}, {}, {}, {}};
            Primitive prim;
            prim.name = m->mName.length ? m->mName.C_Str() : "mesh" + std::to_string(parts.size());
            prim.first_index = mesh.indices.size();
            prim.vertex_base = mesh.vertex_count;
            prim.vertex_count = m->mNumVertices;
            for (unsigned f = 0; f < m->mNumFaces; ++f) {
                if (m->mFaces[f].mNumIndices != 3) continue;  // leftovers of mixed meshes
                for (int c = 0; c < 3; ++c) mesh.indices.push_back(uint32_t(mesh.vertex_count + m->mFaces[f].mIndices[c]));
            }
            prim.index_count = mesh.indices.size() - prim.first_index;
            if (m->mNumBones) {
                part.joints.assign(size_t(m->mNumVertices) * kInfluences, 0);
                part.weights.assign(size_t(m->mNumVertices) * kInfluences, 0.0f);
                for (unsigned b = 0; b < m->mNumBones; ++b) {
                    const aiBone* bone = m->mBones[b];
                    const auto found = flat.by_name.find(bone->mName.C_Str());
                    if (found == flat.by_name.end())
                        throw LoadError(path + ": bone '" + std::string(bone->mName.C_Str()) + "' has no node");
                    part.bone_node.push_back(found->second);
                    part.offset.push_back(bone->mOffsetMatrix);
                    for (unsigned w = 0; w < bone->mNumWeights; ++w) {
                        const aiVertexWeight& vw = bone->mWeights[w];
                        if (vw.mVertexId >= m->mNumVertices) throw LoadError(path + ": a bone weight names a missing vertex");
                        // Keep the strongest kInfluences weights of the vertex.
                        float* ws = &part.weights[size_t(vw.mVertexId) * kInfluences];
                        uint16_t* js = &part.joints[size_t(vw.mVertexId) * kInfluences];
                        const size_t weakest = size_t(std::min_element(ws, ws + kInfluences) - ws);
                        if (vw.mWeight > ws[weakest]) ws[weakest] = vw.mWeight, js[weakest] = uint16_t(b);
                    }
                }
                mesh.joint_count = std::max<size_t>(mesh.joint_count, m->mNumBones);
            }
            mesh.vertex_count += m->mNumVertices;
            mesh.primitives.push_back(prim);
            parts.push_back(std::move(part));
        }
    if (parts.empty()) throw LoadError(path + ": no triangle mesh in the file");

    // Clips: the file's own animations, then those of every clip file (matched by node name).
    struct ClipSource {
        const aiAnimation* animation;
        std::string name;
    };
    std::vector<std::unique_ptr<Assimp::Importer>> clip_importers;
    std::vector<ClipSource> sources;
    for (unsigned a = 0; a < scene->mNumAnimations; ++a)
        sources.push_back({scene->mAnimations[a], scene->mAnimations[a]->mName.length ? scene->mAnimations[a]->mName.C_Str()
                                                                                    : "animation" + std::to_string(a)});
    for (const std::string& file : clip_files) {
        clip_importers.push_back(std::make_unique<Assimp::Importer>());
        const aiScene* clip_scene = import(*clip_importers.back(), file);
        if (clip_scene->mNumAnimations == 0) throw LoadError(file + ": has no animation");
        for (unsigned a = 0; a < clip_scene->mNumAnimations; ++a) {
            const aiAnimation* anim = clip_scene->mAnimations[a];
            size_t matched = 0;
            for (unsigned c = 0; c < anim->mNumChannels; ++c) matched += flat.by_name.count(anim->mChannels[c]->mNodeName.C_Str());
            if (matched == 0)
                throw LoadError(file + ": none of its " + std::to_string(anim->mNumChannels) + " animated joints is a joint of " + path);
            sources.push_back({anim, std::filesystem::path(file).stem().string() +
                                         (clip_scene->mNumAnimations > 1 ? "/" + std::to_string(a) : "")});
        }
    }

    auto add_keyframe = [&](const aiAnimation* anim, double tick) {
        std::vector<aiMatrix4x4> local(flat.nodes.size()), global(flat.nodes.size());
        for (size_t n = 0; n < flat.nodes.size(); ++n) local[n] = flat.nodes[n]->mTransformation;
        if (anim)
            for (unsigned c = 0; c < anim->mNumChannels; ++c) {
                const auto found = flat.by_name.find(anim->mChannels[c]->mNodeName.C_Str());
                if (found != flat.by_name.end()) local[found->second] = interpolate(anim->mChannels[c], tick, local[found->second]);
            }
        for (size_t n = 0; n < flat.nodes.size(); ++n)
            global[n] = flat.parent[n] >= 0 ? global[size_t(flat.parent[n])] * local[n] : local[n];
        const size_t first = mesh.keyframe_positions.size();
        mesh.keyframe_positions.resize(first + mesh.vertex_count * 3);
        float* out = mesh.keyframe_positions.data() + first;
        for (const Part& part : parts) {
            const aiMesh* m = part.mesh;
            std::vector<float> bind(size_t(m->mNumVertices) * 3);
            for (unsigned v = 0; v < m->mNumVertices; ++v)
                bind[3 * v] = m->mVertices[v].x, bind[3 * v + 1] = m->mVertices[v].y, bind[3 * v + 2] = m->mVertices[v].z;
            if (!part.bone_node.empty()) {
                std::vector<Mat4> joints(part.bone_node.size());
                for (size_t b = 0; b < joints.size(); ++b) {
                    const aiMatrix4x4 j = global[part.bone_node[b]] * part.offset[b];
                    const float rows[4][4] = {{j.a1, j.a2, j.a3, j.a4}, {j.b1, j.b2, j.b3, j.b4}, {j.c1, j.c2, j.c3, j.c4}, {j.d1, j.d2, j.d3, j.d4}};
                    for (int c = 0; c < 4; ++c)
                        for (int r = 0; r < 4; ++r) joints[b][size_t(c * 4 + r)] = rows[r][c];  // to column-major
                }
                try {
                    skin_positions(out + 3 * part.vertex_base, bind.data(), m->mNumVertices, part.joints.data(),
                                   part.weights.data(), kInfluences, joints.data(), joints.size());
                } catch (const InvalidInput& e) {
                    throw LoadError(path + ": " + e.what());
                }
            } else {
                const aiMatrix4x4& g = global[part.node];
                for (unsigned v = 0; v < m->mNumVertices; ++v) {
                    const aiVector3D p = g * m->mVertices[v];
                    float* o = out + 3 * (part.vertex_base + v);
                    o[0] = p.x, o[1] = p.y, o[2] = p.z;
                }
            }
        }
    };

    if (sources.empty()) {
        add_keyframe(nullptr, 0);
        mesh.clips.push_back({"static", 0.0, options.sample_rate, 0, 1});
    }
    for (const ClipSource& source : sources) {
        const aiAnimation* anim = source.animation;
        const double ticks_per_second = anim->mTicksPerSecond > 0 ? anim->mTicksPerSecond : 25.0;
        double first = INFINITY, last = -INFINITY;
        for (unsigned c = 0; c < anim->mNumChannels; ++c) {
            const aiNodeAnim* ch = anim->mChannels[c];
            for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) first = std::min(first, ch->mPositionKeys[k].mTime), last = std::max(last, ch->mPositionKeys[k].mTime);
            for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) first = std::min(first, ch->mRotationKeys[k].mTime), last = std::max(last, ch->mRotationKeys[k].mTime);
        }
        if (!(first <= last)) throw LoadError(path + ": clip '" + source.name + "' animates nothing");
        Clip clip;
        clip.name = source.name;
        clip.duration_s = (last - first) / ticks_per_second;
        clip.sample_rate = options.sample_rate;
        clip.first_keyframe = mesh.keyframe_count();
        clip.keyframe_count = size_t(std::llround(clip.duration_s * options.sample_rate)) + 1;
        if (clip.keyframe_count > 100000) throw LoadError(path + ": clip '" + source.name + "' is absurdly long");
        for (size_t f = 0; f < clip.keyframe_count; ++f)
            add_keyframe(anim, std::min(first + double(f) / options.sample_rate * ticks_per_second, last));
        mesh.clips.push_back(clip);
    }
    try {
        validate_animated_mesh(mesh);
    } catch (const InvalidInput& e) {
        throw LoadError(path + ": " + e.what());
    }
    return mesh;
}

}  // namespace animorder
