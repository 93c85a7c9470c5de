// Characters in the formats assimp reads (FBX, Collada, .X, .b3d, MD5, …) into keyframes, and
// Mixamo-style clip files: animation-only files whose channels drive the character's joints by
// name.
//
// Assimp (Debian's libassimp) parses the files; this file evaluates them like the glTF loader:
// node hierarchy with keyed position/rotation/scaling (linear, rotations slerped), bones as
// joint = node global transform · offset matrix (assimp's inverse bind), linear blend skinning
// with weights normalised, every clip sampled at a fixed rate from its first to its last tick.
// Morph targets (assimp's anim meshes, whole replacement positions) move a mesh by the weights
// its clip keys for them (a morph channel named after the mesh's node or the mesh, linear between
// keys): position = base + Σ weight · (target − base), before skinning, as glTF defines it (for
// Collada's RELATIVE morphs, whose targets are offsets, base + Σ weight · target). Only
// keyed weights count: importers fill an anim mesh's own weight inconsistently (assimp's FBX
// reader gives every single-shape channel 1), so an unkeyed target is left at 0.
// Triangulated on import (polygons become triangle fans); points and lines are dropped by
// assimp's primitive sorting and reported if nothing triangular is left.
//
// The rule: assimp runs in a child process. Debian's libassimp 5.2.5 crashes on crafted files
// (.X face or normal indices past the vertices, skin weights naming vertex -2^31, tens of
// thousands of nested frames; MD5 triangle indices near 2^31: SEGV, heap overflows, stack
// overflows), and we cannot fix it, but a user's file must never kill us with a signal. So
// load_assimp forks (isolated_import.h): the child imports with assimp and builds the
// AnimatedMesh exactly as before, passes it back through a memfd, and exits; the parent reads it
// with every size checked and validates it. A child that dies by a signal or exits non-zero (as
// AddressSanitizer does) becomes one LoadError "FILE: assimp crashed reading it (signal 11:
// SIGSEGV)"; its stderr is captured, never shown. Cost: one fork plus one copy of the mesh
// through memory. `animorder inspect`, median of 5: x-dwarf 48 -> 70 ms, md5-bob 32 -> 40 ms,
// pg-witch 123 -> 130 ms; pg-barbarian with its 10 clip files: user time unchanged (0.30 s),
// system time 0.12 -> 0.27 s (page faults of the copy), peak memory 149 -> 239 MB (child
// and parent each hold the mesh for a moment).
#include "animorder/assimp_loader.h"

#include "animorder/animated_mesh.h"
#include "animorder/gltf_extension.h"  // printable: names quoted on one line
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/skinning.h"

#include "animorder/regular_file.h"
#include "checked_size.h"
#include "isolated_import.h"
#include "lower_extension.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/GltfMaterial.h>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <memory>
#include <sstream>
#include <unordered_set>

namespace animorder {
namespace {

// The last of `count` keys (sorted by time) at or before `tick` (the first when none is).
template <typename Key>
unsigned key_index(const Key* keys, unsigned count, double tick) {
    unsigned i = 0;
    while (i + 1 < count && keys[i + 1].mTime <= tick) ++i;
    return i;
}

// How far `tick` lies from key time t0 to t1 (0 to 1, held outside; 0 when they are equal).
double blend(double t0, double t1, double tick) {
    return t1 > t0 ? std::clamp((tick - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
}

aiMatrix4x4 interpolate(const aiNodeAnim* channel, double tick, const aiMatrix4x4& rest) {
    aiVector3D t, s;
    aiQuaternion r;
    rest.Decompose(s, r, t);
    // Position and scaling keys interpolate alike; rotations slerp.
    auto vector_at = [&](const aiVectorKey* keys, unsigned count, aiVector3D& out) {
        if (!count) return;
        const unsigned i = key_index(keys, count, tick);
        const aiVectorKey& a = keys[i];
        const aiVectorKey& b = keys[std::min(i + 1, count - 1)];
        out = a.mValue + (b.mValue - a.mValue) * float(blend(a.mTime, b.mTime, tick));
    };
    vector_at(channel->mPositionKeys, channel->mNumPositionKeys, t);
    vector_at(channel->mScalingKeys, channel->mNumScalingKeys, s);
    if (channel->mNumRotationKeys) {
        const unsigned i = key_index(channel->mRotationKeys, channel->mNumRotationKeys, tick);
        const aiQuatKey& a = channel->mRotationKeys[i];
        const aiQuatKey& b = channel->mRotationKeys[std::min(i + 1, channel->mNumRotationKeys - 1)];
        aiQuaternion::Interpolate(r, a.mValue, b.mValue, float(blend(a.mTime, b.mTime, tick)));
        r.Normalize();
    }
    return aiMatrix4x4(s, r, t);
}

// A morph channel's weights at `tick` (linear between its keys, held before the first and after the
// last), added into `weights` (one entry per anim mesh of the mesh; a key's values index them).
void add_morph_weights(const aiMeshMorphAnim* channel, double tick, std::vector<double>& weights) {
    if (!channel->mNumKeys || !channel->mKeys) return;
    const unsigned i = key_index(channel->mKeys, channel->mNumKeys, tick);
    const aiMeshMorphKey& a = channel->mKeys[i];
    const aiMeshMorphKey& b = channel->mKeys[std::min(i + 1, channel->mNumKeys - 1)];
    const double t = blend(a.mTime, b.mTime, tick);
    for (const auto& [key, share] : {std::pair{&a, 1.0 - t}, std::pair{&b, t}})
        for (unsigned j = 0; j < key->mNumValuesAndWeights; ++j)
            if (key->mValues[j] < weights.size()) weights[key->mValues[j]] += share * key->mWeights[j];
}

// How a clip's channels are applied to the character's nodes: `scale` empty, as they are;
// otherwise per node, NaN to keep the character's own rest translation (a bone offset), or the
// factor the clip's translations are scaled by (1 where the node is no root joint).
struct Retarget {
    std::vector<double> scale;
};

struct Flat {
    std::vector<const aiNode*> nodes;  // parents first
    std::vector<int> parent;
    std::map<std::string, size_t> by_name;
};

// Depth first, children in order, without recursion (a hostile file may nest very deeply).
void flatten(const aiNode* root, Flat& flat) {
    std::vector<std::pair<const aiNode*, int>> stack{{root, -1}};
    while (!stack.empty()) {
        const auto [node, parent] = stack.back();
        stack.pop_back();
        const size_t id = flat.nodes.size();
        flat.nodes.push_back(node);
        flat.parent.push_back(parent);
        flat.by_name.emplace(node->mName.C_Str(), id);
        for (unsigned c = node->mNumChildren; c-- > 0;) stack.push_back({node->mChildren[c], int(id)});
    }
}

// Assimp's file access, but only to regular files, through RegularFile (animorder/regular_file.h):
// a side file an importer opens as it reads (an OBJ's mtllib, say) that is a FIFO or a device
// would never end; for assimp it is then missing. A file is read whole into memory (no larger
// than the loading budget), so nothing blocks once it is open. Every file it looks for or opens
// goes to `looked_at` (once), found or not: a material file missing today changes the mesh when
// it appears.
class RegularFilesOnly : public Assimp::DefaultIOSystem {
public:
    RegularFilesOnly(std::vector<std::string>& looked_at, uint64_t budget) : looked_at_(looked_at), budget_(budget) {}
    bool Exists(const char* file) const override { return note(file); }
    Assimp::IOStream* Open(const char* file, const char* mode) override {
        if (!note(file) || !mode || std::strpbrk(mode, "wa+")) return nullptr;  // importers only read
        RegularFile regular(file);
        if (!regular.ok() || regular.size() > budget_) return nullptr;
        const size_t size = size_t(regular.size());
        std::unique_ptr<uint8_t[]> bytes(new uint8_t[size > 0 ? size : 1]);
        if (regular.read(bytes.get(), size) != size) return nullptr;
        return new Assimp::MemoryIOStream(bytes.release(), size, true);  // Close() deletes it, and it the bytes
    }

private:
    // Records the file; whether it is a regular file.
    bool note(const char* file) const {
        if (!file) return false;
        if (listed_.insert(file).second) looked_at_.push_back(file);
        struct stat st {};
        return ::stat(file, &st) == 0 && S_ISREG(st.st_mode);
    }
    std::vector<std::string>& looked_at_;
    mutable std::unordered_set<std::string> listed_;
    uint64_t budget_;
};

const aiScene* import(Assimp::Importer& importer, const std::string& path, std::vector<std::string>& opened,
                      const LoadOptions& options) {
    const uint64_t budget = options.file_budget();
    if (!std::filesystem::exists(path)) throw LoadError(path + ": cannot open file");
    const RegularFile file(path);
    if (file.ok() && file.size() > budget)
        throw LoadError(path + ": is larger than the loading budget of " + std::to_string(budget) +
                        " bytes (raise it with --max-memory)");
    importer.SetIOHandler(new RegularFilesOnly(opened, budget));  // the importer owns it
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    // An FBX joint's pivots and pre-rotation (Mixamo's joint orientations) folded into the joint's
    // own node. Kept as helper nodes ("J_$AssimpFbx$_PreRotation", ...), libassimp 5.2.5 still keys
    // the whole chain on J's channel, so each key applied its translation and pre-rotation twice:
    // a Mixamo run put the witch's left foot above her hips.
    importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
    io::begin_parsing(file.ok() ? file.size() : 0, options);  // a file assimp loops on is stopped
    const aiScene* scene =
        importer.ReadFile(path, aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_JoinIdenticalVertices |
                                    aiProcess_ValidateDataStructure);
    io::end_parsing();
    if (!scene || !scene->mRootNode) {
        std::string why = importer.GetErrorString();
        std::replace(why.begin(), why.end(), '\n', ' ');
        if (why.find("No meshes remaining") != std::string::npos)  // SortByPType left out every point and line
            throw LoadError(path +
                            ": no triangle mesh in the file (points and lines cannot be reordered for overdraw)");
        throw LoadError(path + ": not readable by assimp: " + why);
    }
    return scene;
}

// assimp reads a cut .md5mesh without a word, keeping what came before the cut. Its header's
// numMeshes against the mesh blocks the text holds, and each block's numverts, numtris and
// numweights against its vert, tri and weight lines (outside comments), say so.
void refuse_truncated_md5mesh(const std::string& path) {
    const std::string extension = io::lower_extension(path);
    if (extension != ".md5mesh") return;
    std::ifstream in(path, std::ios::binary);
    long declared = -1, blocks = 0;
    std::map<std::string, long> said, seen;  // in the current mesh block
    const auto close_block = [&] {
        for (const char* what : {"vert", "tri", "weight"})
            if (said.count(what) && seen[what] < said[what])
                throw LoadError(path + ": cut short or damaged: mesh " + std::to_string(blocks) + " says " +
                                std::to_string(said[what]) + " " + what + "s, it holds " + std::to_string(seen[what]));
        said.clear(), seen.clear();
    };
    std::string line;
    bool in_mesh = false;
    while (std::getline(in, line)) {
        std::istringstream words(line.substr(0, line.find("//")));
        std::string word, next;
        if (!(words >> word)) continue;
        if (word == "numMeshes" && !(words >> declared)) declared = -1;
        if (word == "mesh" && words >> next && next == "{") ++blocks, in_mesh = true;
        if (!in_mesh) continue;
        long n = 0;
        if (word.rfind("num", 0) == 0 && words >> n) said[word.substr(3, word.size() - 4)] = n;  // numverts: vert
        if (word == "vert" || word == "tri" || word == "weight") ++seen[word];
        if (word == "}") close_block(), in_mesh = false;
    }
    if (in_mesh) {
        close_block();
        throw LoadError(path + ": cut short or damaged: mesh " + std::to_string(blocks) + " does not end");
    }
    if (declared >= 0 && blocks < declared)
        throw LoadError(path + ": cut short or damaged: its header says " + std::to_string(declared) +
                        " meshes, it holds " + std::to_string(blocks));
}

// assimp reads a cut text .stl without a word too, keeping the facets before the cut: a text STL
// (it starts with "solid" and its size is not a binary STL's 84 + 50 · its facet count) ends with
// "endsolid" and a name, then nothing but blanks (some exporters add a NUL or a ^Z). Lines may end
// in CR, LF or both, or the whole file be one line: assimp reads it word by word.
void refuse_truncated_ascii_stl(const std::string& path) {
    const std::string extension = io::lower_extension(path);
    if (extension != ".stl") return;
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    const std::streamoff size = in.tellg();
    char head[84] = {};
    in.seekg(0);
    if (size < 5 || !in.read(head, std::min<std::streamoff>(size, 84)) || std::strncmp(head, "solid", 5) != 0) return;
    uint32_t facets = 0;
    std::memcpy(&facets, head + 80, 4);
    if (size >= 84 && uint64_t(size) == 84 + 50 * uint64_t(facets)) return;  // binary, its header saying "solid"
    const std::streamoff tail = std::min<std::streamoff>(size, 4096);
    std::string end(size_t(tail), '\0');
    in.seekg(size - tail);
    in.read(end.data(), tail);
    const size_t at = end.rfind("endsolid");
    bool ends = at != std::string::npos;
    if (ends) {
        const size_t name_end = end.find_first_of("\r\n", at);  // the name runs to the end of its line
        ends = name_end == std::string::npos ||
               end.find_first_not_of(std::string(" \t\r\n\v\f\x1a\0", 8), name_end) == std::string::npos;
    }
    if (!ends) throw LoadError(path + ": cut short or damaged: a text STL ends with 'endsolid', this one does not");
}

// For a file with bones and no geometry (an .md5anim, a .bvh), assimp's SkeletonMeshBuilder adds a
// mesh of its own that draws the bones, with a material it names "SkeletonMaterial": not the
// character.
bool is_skeleton_stand_in(const aiScene* scene, const aiMesh* m) {
    if (m->mMaterialIndex >= scene->mNumMaterials || !scene->mMaterials[m->mMaterialIndex]) return false;
    aiString name;
    return scene->mMaterials[m->mMaterialIndex]->Get(AI_MATKEY_NAME, name) == AI_SUCCESS &&
           std::strcmp(name.C_Str(), "SkeletonMaterial") == 0;
}

// The whole load, in the child process of load_assimp: reading(i) before reading file i (0: the
// character, 1..: clip_files).
AnimatedMesh load_assimp_here(const std::string& path, const std::vector<std::string>& clip_files,
                              const LoadOptions& options, const io::ChildContext& child) {
    const io::ReadingFile& reading = child.reading;
    reading(0);
    Assimp::Importer importer;
    const aiScene* scene = import(importer, path, child.opened, options);
    refuse_truncated_md5mesh(path);
    refuse_truncated_ascii_stl(path);
    Flat flat;
    flatten(scene->mRootNode, flat);

    // Meshes in node order, each with its own vertices (vertex identity kept per mesh).
    struct Part {
        const aiMesh* mesh;
        size_t node;
        size_t vertex_base;
        std::vector<uint16_t> joints;  // 8 influences, the strongest
        std::vector<float> weights;
        std::vector<size_t> bone_node;  // per bone: its node
        std::vector<aiMatrix4x4> offset;
        std::vector<unsigned> unweighted;        // of a skinned mesh: the vertices no bone weighs (rigid with its node)
        std::vector<const aiAnimMesh*> targets;  // its morph targets (anim meshes with positions)
    };
    constexpr size_t kInfluences = 8;
    AnimatedMesh mesh;
    mesh.name = path;
    std::vector<Part> parts;
    bool stand_in = false;  // a mesh assimp drew of a skeleton alone (no geometry in the file)
    for (size_t n = 0; n < flat.nodes.size(); ++n)
        for (unsigned k = 0; k < flat.nodes[n]->mNumMeshes; ++k) {
            const aiMesh* m = scene->mMeshes[flat.nodes[n]->mMeshes[k]];
            if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || m->mNumFaces == 0) continue;
            if (is_skeleton_stand_in(scene, m)) {
                stand_in = true;
                continue;
            }
            Part part{m, n, mesh.vertex_count, {}, {}, {}, {}, {}, {}};
            Primitive prim;
            prim.name = m->mName.length ? m->mName.C_Str() : "mesh" + std::to_string(parts.size());
            prim.first_index = mesh.indices.size();
            prim.vertex_base = mesh.vertex_count;
            prim.vertex_count = m->mNumVertices;
            for (unsigned f = 0; f < m->mNumFaces; ++f) {
                if (m->mFaces[f].mNumIndices != 3) continue;  // leftovers of mixed meshes
                for (int c = 0; c < 3; ++c)
                    mesh.indices.push_back(uint32_t(mesh.vertex_count + m->mFaces[f].mIndices[c]));
            }
            prim.index_count = mesh.indices.size() - prim.first_index;
            // Material flags: AI_MATKEY_TWOSIDED != 0 is double-sided; glTF's alphaMode when
            // assimp kept it, else an opacity below 1 is BLEND (FBX, Collada, OBJ's d/Tr).
            if (m->mMaterialIndex < scene->mNumMaterials && scene->mMaterials[m->mMaterialIndex]) {
                const aiMaterial* material = scene->mMaterials[m->mMaterialIndex];
                int two_sided = 0;
                if (material->Get(AI_MATKEY_TWOSIDED, two_sided) == AI_SUCCESS) prim.double_sided = two_sided != 0;
                aiString alpha_mode;
                float opacity = 1.0f;
                if (material->Get(AI_MATKEY_GLTF_ALPHAMODE, alpha_mode) == AI_SUCCESS) {
                    const std::string mode = alpha_mode.C_Str();
                    prim.alpha_mode = mode == "BLEND"  ? AlphaMode::Blend
                                      : mode == "MASK" ? AlphaMode::Mask
                                                       : AlphaMode::Opaque;
                } else if (material->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && opacity < 1.0f) {
                    prim.alpha_mode = AlphaMode::Blend;
                }
            }
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
                        if (vw.mVertexId >= m->mNumVertices)
                            throw LoadError(path + ": a bone weight names a missing vertex");
                        // Keep the strongest kInfluences weights of the vertex.
                        float* ws = &part.weights[size_t(vw.mVertexId) * kInfluences];
                        uint16_t* js = &part.joints[size_t(vw.mVertexId) * kInfluences];
                        const size_t weakest = size_t(std::min_element(ws, ws + kInfluences) - ws);
                        if (vw.mWeight > ws[weakest]) ws[weakest] = vw.mWeight, js[weakest] = uint16_t(b);
                    }
                }
                for (unsigned v = 0; v < m->mNumVertices; ++v) {
                    const float* ws = &part.weights[size_t(v) * kInfluences];
                    if (!(*std::max_element(ws, ws + kInfluences) > 0.0f)) part.unweighted.push_back(v);
                }
            }
            for (unsigned t = 0; t < m->mNumAnimMeshes && m->mAnimMeshes; ++t) {
                const aiAnimMesh* target = m->mAnimMeshes[t];
                if (target && target->mVertices && target->mNumVertices != m->mNumVertices)
                    throw LoadError(path + ": morph target " + std::to_string(t) + " of mesh '" + prim.name + "' has " +
                                    std::to_string(target->mNumVertices) + " vertices, the mesh " +
                                    std::to_string(m->mNumVertices));
                part.targets.push_back(target && target->mVertices ? target : nullptr);
            }
            mesh.vertex_count += m->mNumVertices;
            mesh.primitives.push_back(prim);
            parts.push_back(std::move(part));
        }
    if (parts.empty() && stand_in)
        throw LoadError(path +
                        ": no mesh in the file, only a skeleton and its animation (an .md5anim, a .bvh): give "
                        "the character's mesh file as the input and this one as --clip");
    if (parts.empty()) throw LoadError(path + ": no triangle mesh in the file");
    for (const Part& part : parts) mesh.morph_target_count = std::max(mesh.morph_target_count, part.targets.size());
    // Whether a morph channel drives a part's targets: it names the part's node or mesh (before a
    // "*N" some importers add, one channel per target).
    auto drives = [&](const aiMeshMorphAnim* channel, const Part& part) {
        if (part.targets.empty() || !channel) return false;
        std::string name = channel->mName.C_Str();
        name = name.substr(0, name.find('*'));
        return name == flat.nodes[part.node]->mName.C_Str() || name == part.mesh->mName.C_Str();
    };
    auto drives_any = [&](const aiMeshMorphAnim* channel) {
        return std::any_of(parts.begin(), parts.end(), [&](const Part& part) { return drives(channel, part); });
    };
    {  // the skeleton's joints: every node some mesh's bone names, once (meshes share them)
        std::vector<size_t> bones;
        for (const Part& part : parts) bones.insert(bones.end(), part.bone_node.begin(), part.bone_node.end());
        std::sort(bones.begin(), bones.end());
        mesh.joint_count = size_t(std::unique(bones.begin(), bones.end()) - bones.begin());
    }

    // Clips: the file's own animations, then those of every clip file (matched by node name).
    struct ClipSource {
        const aiAnimation* animation;
        std::string name;
        std::string file;                // the clip file, or "" for the character's own animations
        const aiScene* scene = nullptr;  // the clip file's
    };
    std::vector<std::unique_ptr<Assimp::Importer>> clip_importers;
    std::vector<ClipSource> sources;
    for (unsigned a = 0; a < scene->mNumAnimations; ++a)
        sources.push_back({scene->mAnimations[a],
                           scene->mAnimations[a]->mName.length ? scene->mAnimations[a]->mName.C_Str()
                                                               : "animation" + std::to_string(a),
                           "", nullptr});
    for (size_t i = 0; i < clip_files.size(); ++i) {
        const std::string& file = clip_files[i];
        reading(i + 1);
        clip_importers.push_back(std::make_unique<Assimp::Importer>());
        const aiScene* clip_scene = import(*clip_importers.back(), file, child.opened, options);
        if (clip_scene->mNumAnimations == 0) throw LoadError(file + ": has no animation");
        for (unsigned a = 0; a < clip_scene->mNumAnimations; ++a) {
            const aiAnimation* anim = clip_scene->mAnimations[a];
            size_t matched = 0;
            for (unsigned c = 0; c < anim->mNumChannels; ++c)
                matched += flat.by_name.count(anim->mChannels[c]->mNodeName.C_Str());
            for (unsigned c = 0; c < anim->mNumMorphMeshChannels; ++c)
                matched += drives_any(anim->mMorphMeshChannels[c]);
            if (matched == 0)
                throw LoadError(file + ": none of its " + std::to_string(anim->mNumChannels) +
                                " animated joints is a joint of " + path);
            sources.push_back({anim,
                               std::filesystem::path(file).stem().string() +
                                   (clip_scene->mNumAnimations > 1 ? "/" + std::to_string(a) : ""),
                               file, clip_scene});
        }
    }

    // Every node's global transform with `anim` (or none: the rest pose) at `tick`.
    // A retargeted clip (`retarget`) keeps the character's bone offsets and scales its root joints'
    // translations (retarget_for below).
    auto globals = [&](const aiAnimation* anim, double tick, const Retarget& retarget) {
        std::vector<aiMatrix4x4> local(flat.nodes.size()), global(flat.nodes.size());
        for (size_t n = 0; n < flat.nodes.size(); ++n) local[n] = flat.nodes[n]->mTransformation;
        if (anim)
            for (unsigned c = 0; c < anim->mNumChannels; ++c) {
                const auto found = flat.by_name.find(anim->mChannels[c]->mNodeName.C_Str());
                if (found == flat.by_name.end()) continue;
                aiMatrix4x4& m = local[found->second];
                m = interpolate(anim->mChannels[c], tick, m);
                if (retarget.scale.empty()) continue;
                const double scale = retarget.scale[found->second];
                const aiMatrix4x4& own = flat.nodes[found->second]->mTransformation;
                if (std::isnan(scale))
                    m.a4 = own.a4, m.b4 = own.b4, m.c4 = own.c4;
                else
                    m.a4 = ai_real(m.a4 * scale), m.b4 = ai_real(m.b4 * scale), m.c4 = ai_real(m.c4 * scale);
            }
        for (size_t n = 0; n < flat.nodes.size(); ++n)
            global[n] = flat.parent[n] >= 0 ? global[size_t(flat.parent[n])] * local[n] : local[n];
        return global;
    };
    // Per part, whether its node's global transform mirrored it (a negative determinant) in some
    // keyframe and whether it did not in some (0, flattened, says neither): as in the glTF loader,
    // a mirrored mesh's file winding is clockwise-front (engines flip their culling for it).
    std::vector<uint8_t> mirrored_in_some(parts.size(), 0), upright_in_some(parts.size(), 0);
    // Per part, the morph channels of `anim` that drive it, their keys checked.
    using MorphChannels = std::vector<std::vector<const aiMeshMorphAnim*>>;
    auto morph_channels = [&](const aiAnimation* anim) {
        MorphChannels of(parts.size());
        for (unsigned c = 0; anim && c < anim->mNumMorphMeshChannels; ++c)
            for (size_t i = 0; i < parts.size(); ++i) {
                const aiMeshMorphAnim* channel = anim->mMorphMeshChannels[c];
                if (!drives(channel, parts[i])) continue;
                for (unsigned k = 0; k < channel->mNumKeys && channel->mKeys; ++k) {
                    const aiMeshMorphKey& key = channel->mKeys[k];
                    const std::string channel_name = path + ": morph channel '" + channel->mName.C_Str() + "'";
                    if (key.mNumValuesAndWeights && (!key.mValues || !key.mWeights))
                        throw LoadError(channel_name + " has a key without values");
                    if (!std::isfinite(key.mTime)) throw LoadError(channel_name + " has a key time that is not finite");
                    for (unsigned j = 0; j < key.mNumValuesAndWeights; ++j) {
                        if (!(std::fabs(key.mWeights[j]) <= 1e6))
                            throw LoadError(channel_name + " keys a weight of " + std::to_string(key.mWeights[j]) +
                                            ", absurd for a morph target");
                        if (key.mValues[j] >= parts[i].targets.size())
                            throw LoadError(channel_name + " keys target " + std::to_string(key.mValues[j]) +
                                            ", but mesh '" + parts[i].mesh->mName.C_Str() + "' has " +
                                            std::to_string(parts[i].targets.size()) + " morph targets");
                    }
                }
                of[i].push_back(channel);
            }
        return of;
    };
    auto add_keyframe = [&](const aiAnimation* anim, const MorphChannels& morphs, double tick,
                            const Retarget& retarget) {
        const std::vector<aiMatrix4x4> global = globals(anim, tick, retarget);
        for (size_t i = 0; i < parts.size(); ++i) {
            const ai_real det = global[parts[i].node].Determinant();  // an affine transform's: its 3 × 3 block's
            mirrored_in_some[i] |= det < 0;
            upright_in_some[i] |= det > 0;
        }
        const size_t first = mesh.keyframe_positions.size();
        mesh.keyframe_positions.resize(first + mesh.vertex_count * 3);
        float* out = mesh.keyframe_positions.data() + first;
        for (size_t i = 0; i < parts.size(); ++i) {
            const Part& part = parts[i];
            const aiMesh* m = part.mesh;
            std::vector<float> bind(size_t(m->mNumVertices) * 3);
            std::vector<double> weights(part.targets.size(), 0.0);
            for (const aiMeshMorphAnim* channel : morphs[i]) add_morph_weights(channel, tick, weights);
            // Targets are whole positions (FBX, glTF: assimp adds the file's offsets to the base),
            // except for Collada's RELATIVE morphs, whose targets are the offsets themselves.
            const double relative = m->mMethod == aiMorphingMethod_MORPH_RELATIVE ? 0.0 : 1.0;
            for (unsigned v = 0; v < m->mNumVertices; ++v) {
                const aiVector3D& base = m->mVertices[v];
                double p[3] = {base.x, base.y, base.z};
                for (size_t t = 0; t < weights.size(); ++t)
                    if (weights[t] != 0.0 && part.targets[t]) {
                        const aiVector3D& target = part.targets[t]->mVertices[v];
                        p[0] += weights[t] * (double(target.x) - relative * base.x);
                        p[1] += weights[t] * (double(target.y) - relative * base.y);
                        p[2] += weights[t] * (double(target.z) - relative * base.z);
                    }
                for (int k = 0; k < 3; ++k) bind[3 * v + size_t(k)] = float(p[k]);
            }
            if (!part.bone_node.empty()) {
                std::vector<Mat4> joints(part.bone_node.size());
                for (size_t b = 0; b < joints.size(); ++b) {
                    const aiMatrix4x4 j = global[part.bone_node[b]] * part.offset[b];
                    const float rows[4][4] = {{j.a1, j.a2, j.a3, j.a4},
                                              {j.b1, j.b2, j.b3, j.b4},
                                              {j.c1, j.c2, j.c3, j.c4},
                                              {j.d1, j.d2, j.d3, j.d4}};
                    for (int c = 0; c < 4; ++c)
                        for (int r = 0; r < 4; ++r) joints[b][size_t(c * 4 + r)] = rows[r][c];  // to column-major
                }
                try {
                    skin_positions(out + 3 * part.vertex_base, bind.data(), m->mNumVertices, part.joints.data(),
                                   part.weights.data(), kInfluences, joints.data(), joints.size());
                } catch (const InvalidInput& e) {
                    throw LoadError(path + ": " + e.what());
                }
                // A vertex no bone weighs (FBX and .X allow it) stays with its mesh's node, as at
                // the bind pose, rather than at its mesh-space coordinates.
                for (const unsigned v : part.unweighted) {
                    const aiVector3D p = global[part.node] * aiVector3D(bind[3 * v], bind[3 * v + 1], bind[3 * v + 2]);
                    float* o = out + 3 * (part.vertex_base + v);
                    o[0] = p.x, o[1] = p.y, o[2] = p.z;
                }
            } else {
                const aiMatrix4x4& g = global[part.node];
                for (unsigned v = 0; v < m->mNumVertices; ++v) {
                    const aiVector3D p = g * aiVector3D(bind[3 * v], bind[3 * v + 1], bind[3 * v + 2]);
                    float* o = out + 3 * (part.vertex_base + v);
                    o[0] = p.x, o[1] = p.y, o[2] = p.z;
                }
            }
        }
    };

    // A clip file made for another skeleton (Mixamo rigs share their joint names, not their bone
    // lengths) is retargeted as engines play such clips: joints bound by name, the clip's rotations
    // (and scales) put on the character's own bone offsets, and the translations of the skeleton's
    // top (the hips: on the path from the scene's root to the first skinned joint, the first node
    // the clip moves with a rest offset in both skeletons) and of the nodes above it (an engine's
    // root motion) scaled by the ratio of the top's rest offsets (the hip heights), so the
    // character walks its own stride. A clip file is applied as it is when every node of its skeleton that the
    // character has too, below one of the character's joints, has the character's rest translation
    // within kSameSkeleton of the character's size (the diagonal of its joints' rest-pose bounding
    // box: exporters round); otherwise it is retargeted, with a note naming the largest difference
    // (Clip::retargeted), and refused only when its skeleton lacks one of the character's skinned
    // joints (a clip for the character's own skeleton may lack some: they stay at rest). On
    // ../shared/data a character's own clip files differ by 0 (identical rest skeletons), another
    // character's by 3.9% to 24%.
    constexpr double kSameSkeleton = 1e-3;
    std::vector<bool> is_bone(flat.nodes.size(), false), below_bone(flat.nodes.size(), false);
    for (const Part& part : parts)
        for (size_t n : part.bone_node) is_bone[n] = true;
    for (size_t n = 0; n < flat.nodes.size(); ++n)  // parents first
        if (flat.parent[n] >= 0) below_bone[n] = is_bone[size_t(flat.parent[n])] || below_bone[size_t(flat.parent[n])];
    // The first skinned joint below no other, and the path from the scene's root down to it.
    std::vector<size_t> to_first_joint;
    for (size_t n = 0; n < flat.nodes.size() && to_first_joint.empty(); ++n)
        if (is_bone[n] && !below_bone[n])
            for (long up = long(n); up >= 0; up = flat.parent[size_t(up)])
                to_first_joint.insert(to_first_joint.begin(), size_t(up));
    double size = 0;
    {
        std::vector<aiMatrix4x4> rest(flat.nodes.size());
        aiVector3D low(INFINITY, INFINITY, INFINITY), high(-INFINITY, -INFINITY, -INFINITY);
        for (size_t n = 0; n < flat.nodes.size(); ++n) {
            rest[n] = flat.parent[n] >= 0 ? rest[size_t(flat.parent[n])] * flat.nodes[n]->mTransformation
                                          : flat.nodes[n]->mTransformation;
            if (!is_bone[n]) continue;
            const aiVector3D p(rest[n].a4, rest[n].b4, rest[n].c4);
            low = aiVector3D(std::min(low.x, p.x), std::min(low.y, p.y), std::min(low.z, p.z));
            high = aiVector3D(std::max(high.x, p.x), std::max(high.y, p.y), std::max(high.z, p.z));
        }
        size = double((high - low).Length());
    }
    auto translation = [](const aiMatrix4x4& m) { return aiVector3D(m.a4, m.b4, m.c4); };
    // An .md5anim is exempt: its baseframe is no bind pose (it holds what its frames do not key,
    // and Doom 3's key every channel of a moving joint), so a character's own animation, given as
    // a clip file, differs there (Bob's 'lamp' by 8.8%): applied as it is.
    auto retarget_for = [&](const ClipSource& source, std::string& note) {
        Retarget retarget;
        if (!source.scene || !(size > 0) || !std::isfinite(size)) return retarget;
        if (io::lower_extension(source.file) == ".md5anim") return retarget;
        std::map<std::string, const aiNode*> theirs_by_name;
        double worst = 0;
        const aiNode* worst_node = nullptr;
        size_t worst_char = 0;
        std::vector<const aiNode*> stack{source.scene->mRootNode};
        while (!stack.empty()) {
            const aiNode* node = stack.back();
            stack.pop_back();
            for (unsigned c = 0; c < node->mNumChildren; ++c) stack.push_back(node->mChildren[c]);
            theirs_by_name.emplace(node->mName.C_Str(), node);
            const auto found = flat.by_name.find(node->mName.C_Str());
            if (found == flat.by_name.end() || !below_bone[found->second]) continue;
            const double d =
                double((translation(node->mTransformation) - translation(flat.nodes[found->second]->mTransformation))
                           .Length());
            if (!(d <= worst)) worst = d, worst_node = node, worst_char = found->second;
        }
        if (!worst_node || worst <= kSameSkeleton * size) return retarget;
        size_t missing = 0;
        std::string first_missing;
        for (size_t n = 0; n < flat.nodes.size(); ++n)
            if (is_bone[n] && !theirs_by_name.count(flat.nodes[n]->mName.C_Str()))
                if (missing++ == 0) first_missing = flat.nodes[n]->mName.C_Str();
        if (missing)
            throw LoadError(source.file + ": made for another skeleton than " + path + "'s: it has no joint '" +
                            printable(first_missing) + "' (" + std::to_string(missing) + " of the character's " +
                            std::to_string(std::count(is_bone.begin(), is_bone.end(), true)) +
                            " skinned joints missing), so it cannot drive the character");
        // The skeleton's top and the ratio of its rest offsets: the first node on the way that the
        // clip moves and that has an offset in both (1, and the first joint, when none has).
        std::set<std::string> moved;
        for (unsigned c = 0; c < source.animation->mNumChannels; ++c)
            if (source.animation->mChannels[c]->mNumPositionKeys)
                moved.insert(source.animation->mChannels[c]->mNodeName.C_Str());
        size_t top = to_first_joint.empty() ? 0 : to_first_joint.back();
        double ratio = 1;
        for (const size_t n : to_first_joint) {
            const auto theirs = theirs_by_name.find(flat.nodes[n]->mName.C_Str());
            if (theirs == theirs_by_name.end() || !moved.count(flat.nodes[n]->mName.C_Str())) continue;
            const double mine_length = double(translation(flat.nodes[n]->mTransformation).Length()),
                         their_length = double(translation(theirs->second->mTransformation).Length());
            if (mine_length > 1e-6 * size && their_length > 1e-6 * size && std::isfinite(mine_length / their_length)) {
                top = n, ratio = mine_length / their_length;
                break;
            }
        }
        // Below the top (or below a joint): the character's offsets; the top and the nodes above it
        // on the way: scaled; elsewhere as the clip has them.
        retarget.scale.assign(flat.nodes.size(), 1.0);
        std::vector<bool> below_top(flat.nodes.size(), false);
        for (size_t n = 0; n < flat.nodes.size(); ++n) {  // parents first
            const long parent = flat.parent[n];
            below_top[n] = parent >= 0 && (size_t(parent) == top || below_top[size_t(parent)]);
            if (below_top[n] || below_bone[n]) retarget.scale[n] = NAN;
        }
        for (const size_t n : to_first_joint) {
            retarget.scale[n] = ratio;
            if (n == top) break;
        }
        std::string scaled;
        if (!to_first_joint.empty() && std::fabs(ratio - 1) > 1e-6) {
            char factor[64];
            std::snprintf(factor, sizeof factor, "' scaled by %.4g", ratio);
            scaled = "; root translation of '" + printable(flat.nodes[top]->mName.C_Str()) + factor;
        }
        // + 0: "0" for a zero of either sign.
        const aiVector3D t = translation(worst_node->mTransformation) + aiVector3D(0, 0, 0),
                         m = translation(flat.nodes[worst_char]->mTransformation) + aiVector3D(0, 0, 0);
        char numbers[200];
        std::snprintf(numbers, sizeof numbers,
                      "(%.4g, %.4g, %.4g) in the clip and (%.4g, %.4g, %.4g) in the character: %.1f%% of its size %.4g",
                      t.x, t.y, t.z, m.x, m.y, m.z, 100 * worst / size, size);
        note = "retargeted onto the character's bone offsets (largest difference: joint '" +
               printable(worst_node->mName.C_Str()) + "' at " + numbers + ")" + scaled;
        return retarget;
    };

    // Every clip's time range and keyframe count first, so that the loading budget is checked
    // before any keyframe is sampled.
    struct Sampling {
        double first, last, ticks_per_second;
        size_t keyframes;
    };
    std::vector<Sampling> sampling;
    size_t total_keyframes = sources.empty() ? 1 : 0;
    for (const ClipSource& source : sources) {
        const aiAnimation* anim = source.animation;
        const double ticks_per_second =
            anim->mTicksPerSecond > 0 && std::isfinite(anim->mTicksPerSecond) ? anim->mTicksPerSecond : 25.0;
        double first = INFINITY, last = -INFINITY;
        for (unsigned c = 0; c < anim->mNumChannels; ++c) {
            const aiNodeAnim* ch = anim->mChannels[c];
            for (unsigned k = 0; k < ch->mNumPositionKeys; ++k)
                first = std::min(first, ch->mPositionKeys[k].mTime), last = std::max(last, ch->mPositionKeys[k].mTime);
            for (unsigned k = 0; k < ch->mNumRotationKeys; ++k)
                first = std::min(first, ch->mRotationKeys[k].mTime), last = std::max(last, ch->mRotationKeys[k].mTime);
            for (unsigned k = 0; k < ch->mNumScalingKeys; ++k)
                first = std::min(first, ch->mScalingKeys[k].mTime), last = std::max(last, ch->mScalingKeys[k].mTime);
        }
        for (unsigned c = 0; c < anim->mNumMorphMeshChannels; ++c) {
            const aiMeshMorphAnim* ch = anim->mMorphMeshChannels[c];
            if (!drives_any(ch) || !ch->mKeys) continue;
            for (unsigned k = 0; k < ch->mNumKeys; ++k)
                first = std::min(first, ch->mKeys[k].mTime), last = std::max(last, ch->mKeys[k].mTime);
        }
        if (!(first <= last)) throw LoadError(path + ": clip '" + source.name + "' animates nothing");
        const double keyframes = std::round((last - first) / ticks_per_second * options.sample_rate) + 1;
        if (!(keyframes <= 100000)) throw LoadError(path + ": clip '" + source.name + "' is absurdly long");
        sampling.push_back({first, last, ticks_per_second, size_t(keyframes)});
        if (!io::checked_add(total_keyframes, size_t(keyframes), total_keyframes))
            throw LoadError(path + ": the clips' keyframe count overflows");
    }
    io::check_keyframe_budget(path, total_keyframes, mesh.vertex_count, options);
    mesh.keyframe_positions.reserve(std::max<size_t>(total_keyframes, 1) * mesh.vertex_count * 3);  // no regrowth
    std::vector<Retarget> retargets(sources.size());
    std::vector<std::string> retarget_notes(sources.size());
    for (size_t i = 0; i < sources.size(); ++i)
        if (!sources[i].file.empty()) retargets[i] = retarget_for(sources[i], retarget_notes[i]);

    if (sources.empty()) {
        add_keyframe(nullptr, morph_channels(nullptr), 0, Retarget{});
        mesh.clips.push_back({"static", 0.0, options.sample_rate, 0, 1});
    }
    for (size_t s = 0; s < sources.size(); ++s) {
        const Sampling& at = sampling[s];
        Clip clip;
        clip.name = sources[s].name;
        clip.duration_s = (at.last - at.first) / at.ticks_per_second;
        clip.sample_rate = options.sample_rate;
        clip.first_keyframe = mesh.keyframe_count();
        clip.keyframe_count = at.keyframes;
        clip.retargeted = retarget_notes[s];
        const MorphChannels morphs = morph_channels(sources[s].animation);
        for (size_t f = 0; f < clip.keyframe_count; ++f)
            add_keyframe(sources[s].animation, morphs,
                         std::min(at.first + double(f) / options.sample_rate * at.ticks_per_second, at.last),
                         retargets[s]);
        mesh.clips.push_back(clip);
    }
    for (size_t i = 0; i < parts.size(); ++i) {
        if (mirrored_in_some[i] && upright_in_some[i])
            throw LoadError(path + ": node '" + std::string(flat.nodes[parts[i].node]->mName.C_Str()) +
                            "' mirrors its mesh in some keyframes and not in others (a scale that changes sign), " +
                            "but one index buffer has one winding");
        mesh.primitives[i].mirrored = mirrored_in_some[i] != 0;
    }
    to_file_winding(mesh, mesh.indices.data());  // to counter-clockwise front faces
    try {
        validate_animated_mesh(mesh);
    } catch (const InvalidInput& e) {
        throw LoadError(path + ": " + e.what());
    }
    return mesh;
}

// load_assimp_here in the child, run from the character's folder on its bare file name. Importers
// make the names of the side files they look for from the path they are given (assimp's MD5
// reader tries "chars/chars/Bob.md5anim" for "chars/Bob.md5mesh", and names cut from the whole
// path), so the files looked at (OptimizeProduct's files_read, the batch reports' side files)
// would depend on how the path was spelled and on the current folder. The files looked at come
// back named from the current folder again, clip files are made absolute first, and errors name
// the files as the caller did.
AnimatedMesh load_from_its_folder(const std::string& path, const std::vector<std::string>& clip_files,
                                  const LoadOptions& options, const io::ChildContext& child) {
    namespace fs = std::filesystem;
    const fs::path folder = fs::path(path).parent_path();
    std::error_code error;
    if (folder.empty() || !fs::is_directory(folder, error)) return load_assimp_here(path, clip_files, options, child);
    std::vector<std::pair<std::string, std::string>> as_given;  // (as the child names it, as the caller did)
    std::vector<std::string> clips;
    for (const std::string& c : clip_files) {
        clips.push_back(fs::absolute(c, error).string());
        if (error || clips.back().empty()) clips.back() = c;
        if (clips.back() != c) as_given.emplace_back(clips.back(), c);
    }
    const std::string name = fs::path(path).filename().string();
    if (::chdir(folder.c_str()) != 0)
        return load_assimp_here(path, clip_files, options, child);  // the child's own folder
    std::vector<std::string> looked_at;
    const io::ChildContext here{child.reading, looked_at};
    try {
        AnimatedMesh mesh = load_assimp_here(name, clips, options, here);
        for (const std::string& file : looked_at)
            child.opened.push_back(fs::path(file).is_absolute() ? file : (folder / file).string());
        return mesh;
    } catch (const LoadError& e) {
        // Each name as a whole word of the message (not inside a longer path), the longest first,
        // in one pass (a name as given is never read again).
        as_given.emplace_back(name, path);
        std::sort(as_given.begin(), as_given.end(),
                  [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
        const auto in_a_path = [](char c) {
            return std::isalnum(uint8_t(c)) || c == '/' || c == '.' || c == '_' || c == '-';
        };
        const std::string said = e.what();
        std::string message;
        for (size_t at = 0; at < said.size();) {
            bool replaced = false;
            for (const auto& [shown, given] : as_given) {
                const size_t end = at + shown.size();
                if (said.compare(at, shown.size(), shown) != 0 || (at > 0 && in_a_path(said[at - 1]))) continue;
                const bool sentence_end =
                    end < said.size() && said[end] == '.' && (end + 1 == said.size() || said[end + 1] == ' ');
                if (end < said.size() && in_a_path(said[end]) && !sentence_end) continue;
                message += given;
                at = end;
                replaced = true;
                break;
            }
            if (!replaced) message += said[at++];
        }
        throw LoadError(message);
    }
}

}  // namespace

AnimatedMesh load_assimp(const std::string& path, const std::vector<std::string>& clip_files,
                         const LoadOptions& options) {
    if (!(options.sample_rate > 0 && options.sample_rate <= 1000))
        throw LoadError(path + ": sample rate must be in (0, 1000]");
    if (!std::filesystem::exists(path)) throw LoadError(path + ": cannot open file");
    std::vector<std::string> files{path};
    files.insert(files.end(), clip_files.begin(), clip_files.end());
    return io::load_isolated(files, options, [&](const io::ChildContext& child) {
        return load_from_its_folder(path, clip_files, options, child);
    });
}

}  // namespace animorder
