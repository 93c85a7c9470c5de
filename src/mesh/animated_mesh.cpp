// The invariants of an AnimatedMesh, checked once where a mesh enters the algorithms, so that a
// loader's mistake or a corrupt file is an error naming the problem rather than a crash later.
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

namespace animorder {

const char* alpha_mode_name(AlphaMode mode) {
    switch (mode) {
        case AlphaMode::Mask: return "MASK";
        case AlphaMode::Blend: return "BLEND";
        case AlphaMode::Opaque: break;
    }
    return "OPAQUE";
}

std::vector<uint8_t> double_sided_triangles(const AnimatedMesh& mesh) {
    bool any = false;
    for (const Primitive& p : mesh.primitives) any = any || p.double_sided;
    if (!any) return {};
    std::vector<uint8_t> flags(mesh.triangle_count(), 0);
    for (const Primitive& p : mesh.primitives)
        if (p.double_sided)
            for (size_t t = p.first_index / 3; t < (p.first_index + p.index_count) / 3 && t < flags.size(); ++t)
                flags[t] = 1;
    return flags;
}

void to_file_winding(const AnimatedMesh& mesh, uint32_t* indices) {
    for (const Primitive& p : mesh.primitives)
        if (p.mirrored)
            for (size_t i = p.first_index; i + 2 < p.first_index + p.index_count; i += 3)
                std::swap(indices[i + 1], indices[i + 2]);
}

bool has_mirrored_primitives(const AnimatedMesh& mesh) {
    for (const Primitive& p : mesh.primitives)
        if (p.mirrored) return true;
    return false;
}

bool has_blended_primitives(const AnimatedMesh& mesh) {
    for (const Primitive& p : mesh.primitives)
        if (p.alpha_mode == AlphaMode::Blend) return true;
    return false;
}

void validate_mesh_topology(const AnimatedMesh& mesh) {
    if (mesh.indices.size() % 3 != 0)
        throw InvalidInput("index count " + std::to_string(mesh.indices.size()) + " is not a multiple of 3");
    size_t next = 0;
    for (const Primitive& p : mesh.primitives) {
        if (p.first_index != next || p.index_count % 3 != 0)
            throw InvalidInput("primitive '" + p.name + "' does not continue the index buffer in whole triangles");
        for (size_t i = p.first_index; i < p.first_index + p.index_count; ++i)
            if (i >= mesh.indices.size() || mesh.indices[i] >= mesh.vertex_count)
                throw InvalidInput("index " + std::to_string(i - p.first_index) + " of primitive '" + p.name + "' is " +
                                   (i < mesh.indices.size() ? std::to_string(mesh.indices[i]) : "past the end") +
                                   ", vertex count is " + std::to_string(mesh.vertex_count));
        next += p.index_count;
    }
    if (next != mesh.indices.size())
        throw InvalidInput("primitives cover " + std::to_string(next) + " of " + std::to_string(mesh.indices.size()) +
                           " indices");
    if (mesh.vertex_count == 0 ? !mesh.keyframe_positions.empty()
                               : mesh.keyframe_positions.size() % (3 * mesh.vertex_count) != 0)
        throw InvalidInput("keyframe positions (" + std::to_string(mesh.keyframe_positions.size()) +
                           " floats) are not a whole number of keyframes of " + std::to_string(mesh.vertex_count) +
                           " vertices");
    const size_t keyframes = mesh.keyframe_count();
    for (const Clip& c : mesh.clips)
        if (c.keyframe_count == 0 || c.first_keyframe + c.keyframe_count > keyframes)
            throw InvalidInput("clip '" + c.name + "' spans keyframes " + std::to_string(c.first_keyframe) + ".." +
                               std::to_string(c.first_keyframe + c.keyframe_count) + ", the mesh has " +
                               std::to_string(keyframes));
}

namespace {

// Throws for the first position of `count` floats from keyframe `keyframe` on that is not finite.
// Blocks of positions are tested without a branch (a float is not finite when its exponent bits
// are all ones: a loop the compiler vectorises); a block with one is searched for the first.
void validate_positions(const AnimatedMesh& mesh, size_t keyframe, size_t count) {
    const float* positions = mesh.keyframe_positions.data() + keyframe * 3 * mesh.vertex_count;
    constexpr size_t kBlock = 4096;
    for (size_t first = 0; first < count; first += kBlock) {
        const size_t end = std::min(count, first + kBlock);
        uint32_t not_finite = 0;
        for (size_t i = first; i < end; ++i) {
            uint32_t bits;
            std::memcpy(&bits, &positions[i], sizeof bits);
            not_finite |= uint32_t((bits & 0x7f800000u) == 0x7f800000u);
        }
        if (!not_finite) continue;
        for (size_t i = first; i < end; ++i)
            if (!std::isfinite(positions[i]))
                throw InvalidInput("keyframe " + std::to_string(keyframe + i / (3 * mesh.vertex_count)) +
                                   ": position of vertex " + std::to_string(i / 3 % mesh.vertex_count) +
                                   " is not finite");
    }
}

}  // namespace

void validate_animated_mesh(const AnimatedMesh& mesh) {
    validate_mesh_topology(mesh);
    validate_positions(mesh, 0, mesh.keyframe_positions.size());
}

void validate_animated_mesh(const AnimatedMesh& mesh, const std::vector<uint32_t>& keyframes) {
    validate_mesh_topology(mesh);
    for (const uint32_t k : keyframes) {
        if (k >= mesh.keyframe_count())
            throw InvalidInput("keyframe " + std::to_string(k) + " does not exist (the mesh has " +
                               std::to_string(mesh.keyframe_count()) + ")");
        validate_positions(mesh, k, 3 * mesh.vertex_count);
    }
}

AnimatedMesh select_clips(const AnimatedMesh& mesh, const std::vector<std::string>& names) {
    AnimatedMesh out = mesh;
    out.clips.clear();
    out.keyframe_positions.clear();
    const size_t frame_floats = mesh.vertex_count * 3;
    for (size_t n = 0; n < names.size(); ++n) {
        const std::string& name = names[n];
        if (std::find(names.begin(), names.begin() + ptrdiff_t(n), name) != names.begin() + ptrdiff_t(n))
            continue;        // named twice: kept once
        bool found = false;  // every clip of that name, in the mesh's order (Mixamo names each "mixamo.com")
        for (const Clip& clip : mesh.clips) {
            if (clip.name != name) continue;
            found = true;
            Clip c = clip;
            c.first_keyframe = out.keyframe_count();
            out.keyframe_positions.insert(
                out.keyframe_positions.end(),
                mesh.keyframe_positions.begin() + ptrdiff_t(clip.first_keyframe * frame_floats),
                mesh.keyframe_positions.begin() +
                    ptrdiff_t((clip.first_keyframe + clip.keyframe_count) * frame_floats));
            out.clips.push_back(c);
        }
        if (!found) {
            std::string known;
            for (const Clip& c : mesh.clips) known += (known.empty() ? "" : ", ") + c.name;
            throw InvalidInput("no clip named '" + name + "' (clips: " + known + ")");
        }
    }
    return out;
}

}  // namespace animorder
