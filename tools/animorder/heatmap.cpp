// `animorder heatmap`: one node (keyframe, view) rasterised, a single-buffer method's order
// scored, and the fragments that pass the depth test per pixel drawn as a PNG (Figure 1's kind).
#include "commands.h"
#include "heatmap_image.h"
#include "input.h"

#include "animorder/atomic_write.h"
#include "animorder/camera.h"
#include "animorder/overdraw.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace animorder::tool {

namespace {

// `heatmap --blend`: the transparent pass of one node (DESIGN.md "Blend error"), each pixel the
// number of its blended fragment pairs drawn nearer-before-farther by the method's order (its
// blended primitives reversed where run_method reverses them: BlendOrder::Reversed).
int draw_blend_heatmap(const HeatmapOptions& options, const AnimatedMesh& mesh, Method method,
                       std::vector<uint32_t> order) {
    if (!has_blended_primitives(mesh))
        throw std::runtime_error("--blend: the input has no blended primitive (alphaMode BLEND)");
    if (method_blend_order(method) == BlendOrder::Reversed) reverse_blended_primitives(mesh, order);
    const double length =
        std::sqrt(double(options.view[0]) * options.view[0] + double(options.view[1]) * options.view[1] +
                  double(options.view[2]) * options.view[2]);
    const float direction[3] = {float(options.view[0] / length), float(options.view[1] / length),
                                float(options.view[2] / length)};
    const Framing framing = about_input(options.common, [&] { return frame_animated_mesh(mesh); });
    std::vector<float> clip(mesh.vertex_count * 4);
    transform_to_clip(clip.data(), mesh.keyframe(options.keyframe), mesh.vertex_count,
                      &framing.centres[3 * options.keyframe], node_view_projection(direction, framing.radius));
    NodeRasterizer rasterizer;
    const std::vector<uint8_t> modes = full_pass_modes(mesh);
    rasterizer.rasterize(clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), options.resolution,
                         modes.empty() ? nullptr : modes.data());
    std::vector<uint8_t> blended(mesh.triangle_count(), 0);
    for (const Primitive& p : mesh.primitives)
        if (p.alpha_mode == AlphaMode::Blend)
            for (size_t t = p.first_index / 3; t < (p.first_index + p.index_count) / 3; ++t) blended[t] = 1;
    const BlendFragments fragments = rasterizer.export_blend_fragments(blended.data());
    const std::vector<uint32_t> ranks = make_rank_table({order.data()}, mesh.triangle_count());
    BlendCounts counts;
    score_blend(&counts, fragments, ranks.data(), 1);
    const double pixels = counts.covered ? double(counts.missorted_pixels) / double(counts.covered) : 0.0;
    char caption[256];
    std::snprintf(caption, sizeof caption, "%s blend  keyframe %zu  view (%.2f, %.2f, %.2f)  mis-sorted pixels %.3f",
                  method_name(method), options.keyframe, direction[0], direction[1], direction[2], pixels);
    write_file_atomically(options.output,
                          heatmap_png(missorted_per_pixel(fragments, options.resolution, ranks.data(), 1, 0),
                                      options.resolution, caption));
    note(options.common, "wrote " + options.output);
    std::printf("%s blend: covered %llu, pairs %llu, mis-sorted pairs %llu, mis-sorted pixels %llu (%.4f)\n",
                method_name(method), (unsigned long long)counts.covered, (unsigned long long)counts.pairs,
                (unsigned long long)counts.missorted_pairs, (unsigned long long)counts.missorted_pixels, pixels);
    return 0;
}

}  // namespace

int run_heatmap(const HeatmapOptions& options) {
    if (!std::isfinite(options.lambda)) throw std::runtime_error("--lambda must be a finite number");
    if (options.view.size() != 3) throw std::runtime_error("--view takes three numbers: x,y,z");
    const double length =
        std::sqrt(double(options.view[0]) * options.view[0] + double(options.view[1]) * options.view[1] +
                  double(options.view[2]) * options.view[2]);
    if (!(length > 1e-9) || !std::isfinite(length))
        throw std::runtime_error("--view must be a non-zero finite direction");
    if (options.output.empty()) throw std::runtime_error("heatmap needs an output file (-o out.png)");
    const Method method = parse_static_method(options.method);
    check_outputs_before_loading({options.output}, options.common);

    std::string input_name;
    std::vector<std::string> files_read;
    const AnimatedMesh mesh = load_drawable_input(options.common, input_name, &files_read);
    check_output_paths({options.output}, files_read);
    if (options.keyframe >= mesh.keyframe_count())
        throw std::runtime_error("keyframe " + std::to_string(options.keyframe) + " does not exist (the mesh has " +
                                 std::to_string(mesh.keyframe_count()) + ")");
    StaticMethodSettings settings;
    settings.lambda = options.lambda;
    settings.cache_size = options.common.cache_size;
    const StaticMethodResult result =
        about_input(options.common, [&] { return run_static_method(mesh, method, settings); });

    if (options.blend) return draw_blend_heatmap(options, mesh, method, result.order);
    const Framing framing = about_input(options.common, [&] { return frame_animated_mesh(mesh); });
    const float direction[3] = {float(options.view[0] / length), float(options.view[1] / length),
                                float(options.view[2] / length)};
    std::vector<float> clip(mesh.vertex_count * 4);
    transform_to_clip(clip.data(), mesh.keyframe(options.keyframe), mesh.vertex_count,
                      &framing.centres[3 * options.keyframe], node_view_projection(direction, framing.radius));
    NodeRasterizer rasterizer;
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);
    rasterizer.rasterize(clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), options.resolution,
                         modes.empty() ? nullptr : modes.data());
    const std::vector<uint32_t> ranks = make_rank_table({result.order.data()}, mesh.triangle_count());
    uint64_t passed = 0;
    rasterizer.score(&passed, ranks.data(), 1);
    const double ovr = rasterizer.visible_pixels() ? double(passed) / double(rasterizer.visible_pixels()) : 0.0;

    char caption[256];
    std::snprintf(caption, sizeof caption, "%s  keyframe %zu  view (%.2f, %.2f, %.2f)  OVR %.3f", method_name(method),
                  options.keyframe, direction[0], direction[1], direction[2], ovr);
    write_file_atomically(options.output,
                          heatmap_png(rasterizer.passed_per_pixel(ranks.data(), 1, 0), options.resolution, caption));
    note(options.common, "wrote " + options.output);
    std::printf("%s: visible %llu, shaded %llu, OVR %.4f\n", method_name(method),
                (unsigned long long)rasterizer.visible_pixels(), (unsigned long long)passed, ovr);
    return 0;
}

}  // namespace animorder::tool
