// `animorder subdivide`: load the input (or the bundled character), apply `--levels` levels of
// Loop subdivision to every keyframe (subdivide_animated_mesh) and write the result as a new
// glTF/GLB whose keyframes are morph targets (gltf_animated_mesh), atomically.
#include "commands.h"
#include "input.h"

#include "animorder/atomic_write.h"
#include "animorder/gltf_animated_writer.h"
#include "animorder/load.h"
#include "animorder/subdivide_animated_mesh.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace animorder::tool {
namespace {

std::string megabytes(size_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MB", double(bytes) / 1e6);
    return text;
}

}  // namespace

int run_subdivide(const SubdivideOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const std::string extension = file_extension(options.output);
    if (extension != ".glb" && extension != ".gltf")
        throw std::runtime_error(options.output + ": the output must be a .glb or .gltf file");
    if (options.levels > kMaxSubdivisionLevels)
        throw std::runtime_error("--levels " + std::to_string(options.levels) + ": at most " +
                                 std::to_string(kMaxSubdivisionLevels) + " (each level multiplies the triangles by 4)");
    check_outputs_before_loading({options.output}, options.common);

    std::string input_name;
    std::vector<std::string> files_read;
    const AnimatedMesh mesh = load_animated_input(options.common, input_name, &files_read);
    check_output_paths({options.output}, files_read);
    // Every keyframe is a morph target of 12 bytes per vertex: say how big before building it,
    // and refuse what neither the loading budget (--max-memory) nor a GLB can hold.
    double estimate = 0;
    AnimatedMesh result = subdivide_animated_mesh(mesh, options.levels, [&](size_t vertices, size_t keyframes) {
        estimate = double(vertices) * double(keyframes) * 12.0;
        const std::string size = "about " + megabytes(size_t(estimate)) + " of morph targets (" +
                                 std::to_string(vertices) + " vertices, " + std::to_string(keyframes) + " keyframes)";
        if (estimate > double(options.common.max_memory))
            throw std::runtime_error("the output would hold " + size + ", more than the loading budget of " +
                                     megabytes(options.common.max_memory) +
                                     " (--max-memory); keep fewer clips with --clip NAME, or fewer --levels");
        if (estimate > 4.0e9)
            throw std::runtime_error("the output would hold " + size +
                                     ", more than a GLB can; keep fewer clips with --clip NAME");
    });
    if (!options.common.input.empty()) result.name = std::filesystem::path(options.common.input).stem().string();
    note(options.common, "subdivided " + std::to_string(options.levels) + " level(s); writing " +
                             std::to_string(result.keyframe_count()) + " keyframes as morph targets (about " +
                             megabytes(size_t(estimate)) + (estimate > 5e8 ? "; --clip NAME keeps fewer" : "") + ")");
    const std::string bytes = gltf_animated_mesh(result, extension == ".glb");
    write_file_atomically(options.output, bytes);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    std::printf("%s: %u level(s) of Loop subdivision\n", input_name.c_str(), options.levels);
    std::printf("  triangles %zu -> %zu\n", mesh.triangle_count(), result.triangle_count());
    std::printf("  vertices  %zu -> %zu\n", mesh.vertex_count, result.vertex_count);
    std::printf("  clips %zu  keyframes %zu\n", result.clips.size(), result.keyframe_count());
    std::printf("  wrote %s (%s, %zu bytes) in %.2f s\n", options.output.c_str(), megabytes(bytes.size()).c_str(),
                bytes.size(), seconds);
    return 0;
}

}  // namespace animorder::tool
