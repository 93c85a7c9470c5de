// `animorder inspect`: what the input holds (triangles, vertices, primitives, clips with their
// bounding radius) and the ACMR of its current order, as text or JSON.
#include "commands.h"
#include "input.h"
#include "report.h"

#include "animorder/viewpoints.h"

#include <algorithm>
#include <cstdio>

namespace animorder::tool {
namespace {

// The view radius R of every clip (DESIGN.md framing): the largest per-keyframe bounding radius.
std::vector<float> clip_radii(const AnimatedMesh& mesh) {
    const Framing all = frame_animated_mesh(mesh);
    std::vector<float> radii;
    for (const Clip& c : mesh.clips) {
        float r = 0;
        for (size_t f = 0; f < c.keyframe_count; ++f) r = std::max(r, all.radii[c.first_keyframe + f]);
        radii.push_back(r);
    }
    return radii;
}

// A name as the text shows it: as it is, or, when it is empty or holds a space or a control
// character (a tab or a line break would cut its line), as a JSON string: quoted and escaped.
std::string shown_name(const std::string& name) {
    const bool plain = !name.empty() && std::none_of(name.begin(), name.end(),
                                                     [](char c) { return uint8_t(c) <= 0x20 || uint8_t(c) == 0x7f; });
    return plain ? name : nlohmann::json(name).dump();
}

void print_inspect_text(const AnimatedMesh& mesh, const std::string& input_name, const VertexCacheStats& cache,
                        unsigned cache_size) {
    std::printf("%s\n", input_name.c_str());
    std::printf("  triangles %zu  vertices %zu  joints %zu  morph targets %zu  keyframes %zu\n", mesh.triangle_count(),
                mesh.vertex_count, mesh.joint_count, mesh.morph_target_count, mesh.keyframe_count());
    std::printf("  ACMR %.4f  ATVR %.4f  (FIFO cache of %u, current order)\n", cache.acmr, cache.atvr, cache_size);
    for (const Primitive& p : mesh.primitives)
        std::printf("  primitive %-12s triangles %zu  %s  %s%s\n", shown_name(p.name).c_str(), p.index_count / 3,
                    p.double_sided ? "double-sided" : "single-sided", alpha_mode_name(p.alpha_mode),
                    p.mirrored ? "  mirrored (clockwise front faces in the file)" : "");
    const std::vector<float> radii = clip_radii(mesh);
    for (size_t i = 0; i < mesh.clips.size(); ++i) {
        const Clip& c = mesh.clips[i];
        std::printf("  clip %-12s %.3f s  %zu keyframes at %g/s  bounding radius %.4g\n", shown_name(c.name).c_str(),
                    c.duration_s, c.keyframe_count, c.sample_rate, radii[i]);
    }
}

}  // namespace

int run_inspect(const InspectOptions& options) {
    std::string input_name;
    const AnimatedMesh mesh = load_drawable_input(options.common, input_name);
    const VertexCacheStats cache = analyze_mesh_vertex_cache(mesh, mesh.indices, options.common.cache_size);
    if (!options.json) {
        print_inspect_text(mesh, input_name, cache, options.common.cache_size);
        return 0;
    }
    nlohmann::ordered_json report = report_header(mesh, input_name);
    report["joints"] = mesh.joint_count;
    report["morph_targets"] = mesh.morph_target_count;
    report["keyframes"] = mesh.keyframe_count();
    report["cache_size"] = options.common.cache_size;
    report["input_order"] = cache_stats_json(cache);
    for (const Primitive& p : mesh.primitives) {
        std::vector<uint8_t> used(mesh.vertex_count, 0);
        size_t vertices = 0;
        for (size_t i = p.first_index; i < p.first_index + p.index_count; ++i)
            vertices += used[mesh.indices[i]] ? 0 : (used[mesh.indices[i]] = 1);
        report["primitives"].push_back({{"name", p.name},
                                        {"triangles", p.index_count / 3},
                                        {"vertices", vertices},
                                        {"double_sided", p.double_sided},
                                        {"alpha_mode", alpha_mode_name(p.alpha_mode)},
                                        {"mirrored", p.mirrored}});
    }
    const std::vector<float> radii = clip_radii(mesh);
    for (size_t i = 0; i < mesh.clips.size(); ++i)
        report["clips"].push_back({{"name", mesh.clips[i].name},
                                   {"duration_s", mesh.clips[i].duration_s},
                                   {"keyframes", mesh.clips[i].keyframe_count},
                                   {"sample_rate", mesh.clips[i].sample_rate},
                                   {"bounding_radius", radii[i]}});
    std::fputs(report_text(report).c_str(), stdout);
    return 0;
}

}  // namespace animorder::tool
