// The sidecar binary (format: include/animorder_runtime.h). Written byte by byte in
// little-endian order, so the file is the same on every host and byte-identical for the same
// input and options.
#include "animorder/sidecar.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/methods.h"
#include "animorder/selection_table.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include <nlohmann/json.hpp>

#include <cstring>

namespace animorder {
namespace {

void put_u32(std::string& out, uint32_t v) {
    for (int b = 0; b < 4; ++b) out.push_back(char((v >> (8 * b)) & 0xff));
}
void put_f32(std::string& out, float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    put_u32(out, u);
}

}  // namespace

std::string serialize_sidecar(const AnimatedMesh& mesh, const MethodBuffers& buffers, const Framing& framing) {
    if (buffers.tables.size() != mesh.clips.size() || buffers.table_base.size() != mesh.clips.size())
        throw InvalidInput("the sidecar needs one lookup table per clip");
    const size_t header = 20, clip_record = 32;
    const size_t buffers_end =
        header + clip_record * mesh.clips.size() + buffers.orders.size() * mesh.indices.size() * 4;
    std::string out;
    size_t tables_bytes = 0;
    for (size_t c = 0; c < mesh.clips.size(); ++c)
        tables_bytes += buffers.tables[c].cells.size() + size_t(mesh.clips[c].keyframe_count) * 12;
    out.reserve(buffers_end + tables_bytes);  // one allocation: the buffers are most of the file
    out.append("AOR1", 4);
    put_u32(out, 1);
    put_u32(out, uint32_t(buffers.orders.size()));
    put_u32(out, uint32_t(mesh.indices.size()));
    put_u32(out, uint32_t(mesh.clips.size()));
    size_t offset = buffers_end;
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const SelectionTable& t = buffers.tables[c];
        if (t.keyframes != mesh.clips[c].keyframe_count) throw InvalidInput("a lookup table does not match its clip");
        put_u32(out, t.keyframes);
        put_u32(out, t.theta_steps);
        put_u32(out, t.phi_steps);
        put_f32(out, float(mesh.clips[c].sample_rate));
        put_u32(out, buffers.table_base[c]);
        put_u32(out, uint32_t(offset));
        put_u32(out, uint32_t(offset + t.cells.size()));
        put_u32(out, 0);
        offset += t.cells.size() + size_t(t.keyframes) * 12;
    }
    std::vector<uint32_t> indices(mesh.indices.size());
    for (const auto& order : buffers.orders) {
        apply_triangle_order(indices.data(), mesh.indices.data(), order.data(), mesh.triangle_count());
        to_file_winding(mesh, indices.data());  // a mirrored primitive's triangles as the input file has them
        const size_t at = out.size();
        out.resize(at + 4 * indices.size());
        char* bytes = &out[at];
        for (size_t i = 0; i < indices.size(); ++i)  // put_u32's bytes, stored in place (no growth check)
            for (int b = 0; b < 4; ++b) bytes[4 * i + size_t(b)] = char((indices[i] >> (8 * b)) & 0xff);
    }
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        out.append(reinterpret_cast<const char*>(buffers.tables[c].cells.data()), buffers.tables[c].cells.size());
        for (size_t f = 0; f < mesh.clips[c].keyframe_count; ++f)
            for (int d = 0; d < 3; ++d) put_f32(out, framing.centres[3 * (mesh.clips[c].first_keyframe + f) + d]);
    }
    if (out.size() > UINT32_MAX) throw InvalidInput("sidecar larger than 4 GiB");
    return out;
}

std::string sidecar_json(const AnimatedMesh& mesh, const MethodBuffers& buffers, const std::string& method,
                         uint32_t fallback, const std::string& binary_name) {
    if (buffers.tables.size() != mesh.clips.size() || buffers.table_base.size() != mesh.clips.size())
        throw InvalidInput("the sidecar needs one lookup table per clip");
    nlohmann::ordered_json j;
    j["format"] = "animorder-sidecar";
    j["version"] = 1;
    j["binary"] = binary_name;
    j["method"] = method;
    j["buffers"] = buffers.orders.size();
    j["fallback"] = fallback;
    j["index_count"] = mesh.indices.size();
    j["primitives"] = nlohmann::ordered_json::array();
    for (const Primitive& p : mesh.primitives)
        j["primitives"].push_back({{"name", p.name}, {"first_index", p.first_index}, {"index_count", p.index_count}});
    j["clips"] = nlohmann::ordered_json::array();
    for (size_t c = 0; c < mesh.clips.size(); ++c)
        j["clips"].push_back({{"name", mesh.clips[c].name},
                              {"keyframes", mesh.clips[c].keyframe_count},
                              {"sample_rate", mesh.clips[c].sample_rate},
                              {"buffer_base", buffers.table_base[c]},
                              {"theta_steps", buffers.tables[c].theta_steps},
                              {"phi_steps", buffers.tables[c].phi_steps}});
    j["table"] =
        "cell (f, i, j): theta = i*pi/(theta_steps-1) from +Y, phi = j*2*pi/phi_steps from +Z towards +X; "
        "buffer = buffer_base + cell (see animorder_runtime.h)";
    return j.dump(2) + "\n";
}

}  // namespace animorder
