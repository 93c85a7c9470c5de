#include "input.h"

#include "animorder/atomic_write.h"
#include "animorder/load.h"
#include "animorder/procedural_character.h"

#include <unistd.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

namespace animorder::tool {

void note(const CommonOptions& common, const std::string& text) {
    if (!common.quiet) std::fprintf(stderr, "animorder: %s\n", text.c_str());
}

// Progress on stderr: on a terminal one line rewritten in place (\r), at most twice a second;
// into a file or a pipe (a farm's log) whole lines only, at most every 10 s, and each stage's end.
std::function<void(const std::string&, size_t, size_t)> staged_progress_printer(const CommonOptions& common,
                                                                                const std::string& prefix) {
    if (common.quiet) return {};
    using Clock = std::chrono::steady_clock;
    struct State {
        Clock::time_point start = Clock::now();
        double last = -1;
        std::string stage;
        bool open = false;   // a terminal line not yet ended
        bool ended = false;  // the stage's end is shown (a stage may go over its nodes twice)
    };
    auto state = std::make_shared<State>();
    const bool terminal = ::isatty(2) == 1;
    return [prefix, state, terminal](const std::string& stage, size_t done, size_t total) {
        State& s = *state;
        const double now = std::chrono::duration<double>(Clock::now() - s.start).count();
        if (stage != s.stage) {
            if (s.open) std::fputc('\n', stderr);
            s.stage = stage, s.open = false, s.last = -1, s.ended = false;
            s.start = Clock::now();  // seconds within the stage
        }
        if (s.ended || (done != total && now - s.last < (terminal ? 0.5 : 10.0))) return;  // a stage's end once
        s.ended = done == total;
        s.last = now;
        const std::string name = prefix + (stage.empty() ? "" : (prefix.empty() ? "" : ": ") + stage);
        std::fprintf(stderr, "%sanimorder: %s: %zu/%zu nodes, %.1f s%s", terminal ? "\r" : "", name.c_str(), done,
                     total, now, terminal && done != total ? "" : "\n");
        s.open = terminal && done != total;
        std::fflush(stderr);
    };
}

std::function<void(size_t, size_t)> progress_printer(const CommonOptions& common, const std::string& stage) {
    auto staged = staged_progress_printer(common, stage);
    if (!staged) return {};
    return [staged](size_t done, size_t total) { staged("", done, total); };
}

bool clip_is_file(const CommonOptions& common, const std::string& clip) {
    // A character that carries its clips takes clip names only: a file of that name in the
    // current folder does not make it a clip file.
    if (common.input.empty() || carries_its_clips(common.input)) return false;
    return common.clip_files_absolute ? std::filesystem::path(clip).is_absolute() : std::filesystem::exists(clip);
}

std::vector<std::string> input_files(const CommonOptions& common) {
    std::vector<std::string> clip_files;
    for (const std::string& c : common.clips)
        if (clip_is_file(common, c)) clip_files.push_back(c);
    if (common.input.empty()) return clip_files;  // the bundled character takes none (loading says so)
    try {
        return files_load_reads(common.input, clip_files);
    } catch (const LoadError&) {  // an empty clip folder: loading says so
        clip_files.insert(clip_files.begin(), common.input);
        return clip_files;
    }
}

std::vector<std::string> input_folders(const CommonOptions& common) {
    std::vector<std::string> folders;
    for (const std::string& c : common.clips) {
        std::error_code error;
        if (clip_is_file(common, c) && std::filesystem::is_directory(c, error)) folders.push_back(c);
    }
    return folders;
}

void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs,
                   const std::vector<std::string>& input_folders) {
    check_output_paths(outputs, inputs, input_folders);
    for (const std::string& output : outputs) remove_stale_temporaries(output);
}

void check_outputs_before_loading(const std::vector<std::string>& outputs, const CommonOptions& common) {
    check_outputs(outputs, input_files(common), input_folders(common));
}

AnimatedMesh load_animated_input(const CommonOptions& common, std::string& input_name,
                                 std::vector<std::string>* files_read) {
    std::vector<std::string> clip_files, clip_names;
    for (const std::string& c : common.clips) (clip_is_file(common, c) ? clip_files : clip_names).push_back(c);
    AnimatedMesh mesh;
    if (common.input.empty()) {
        if (!clip_files.empty()) throw std::runtime_error("clip files need an input character file");
        note(common, "no input file given: using the bundled procedural character");
        input_name = kProceduralCharacterName;
        mesh = make_procedural_character();
    } else {
        input_name = common.input;
        LoadOptions options;
        options.max_keyframe_bytes = common.max_memory;
        options.clips = clip_names;  // only these are sampled (select_clips below still picks and orders them)
        options.files_read = files_read;
        options.threads = common.threads;
        mesh = load_character(common.input, clip_files, options);
        note(common, "loaded " + common.input + ": " + std::to_string(mesh.triangle_count()) + " triangles, " +
                         std::to_string(mesh.clips.size()) + " clips, " + std::to_string(mesh.keyframe_count()) +
                         " keyframes");
        for (const Clip& clip : mesh.clips)
            if (!clip.retargeted.empty()) note(common, "clip '" + clip.name + "': " + clip.retargeted);
    }
    if (!clip_names.empty()) mesh = select_clips(mesh, clip_names);
    return mesh;
}

AnimatedMesh load_drawable_input(const CommonOptions& common, std::string& input_name,
                                 std::vector<std::string>* files_read) {
    AnimatedMesh mesh = load_animated_input(common, input_name, files_read);
    validate_animated_mesh(mesh);
    // A mesh with no area at any keyframe has nothing to draw, so nothing to reorder. One that has
    // none at some keyframes only (a node or joint scaled from 0, a clip that hides the mesh) is
    // drawn at the others; the search stops at the first triangle with area.
    double area = 0;
    for (size_t k = 0; k < mesh.keyframe_count() && area == 0; ++k) {
        const float* p = mesh.keyframe(k);
        for (size_t t = 0; t < mesh.indices.size() && area == 0; t += 3) {
            const float *a = p + 3 * mesh.indices[t], *b = p + 3 * mesh.indices[t + 1],
                        *c = p + 3 * mesh.indices[t + 2];
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            area += std::fabs(u[1] * v[2] - u[2] * v[1]) + std::fabs(u[2] * v[0] - u[0] * v[2]) +
                    std::fabs(u[0] * v[1] - u[1] * v[0]);
        }
    }
    if (area == 0)
        throw std::runtime_error(input_name + ": every triangle has zero area at every keyframe: nothing to reorder");
    return mesh;
}

MethodSettings method_settings(const MethodOptions& options, const CommonOptions& common, Method method) {
    MethodSettings settings = options.settings;
    settings.cache_size = common.cache_size;
    // Errors name the option the user typed; the library checks the same again in run_method.
    if (options.distance != distance_name(DistanceVariant::Jcgt) &&
        options.distance != distance_name(DistanceVariant::I3d))
        throw std::runtime_error("--distance must be jcgt or i3d, not '" + options.distance + "'");
    if (options.update != update_name(UpdateRule::Monotone) && options.update != update_name(UpdateRule::Paper))
        throw std::runtime_error("--update must be monotone or paper, not '" + options.update + "'");
    if (!(settings.clustering.min_separation_deg >= 0 && settings.clustering.min_separation_deg <= 180))
        throw std::runtime_error("--min-separation must be between 0 and 180 degrees");
    settings.clustering.distance = parse_distance(options.distance);
    settings.clustering.update = parse_update(options.update);
    const std::string name = method_name(method);
    settings.clustering.log = [common, name](const std::string& line) { note(common, name + ": " + line); };
    settings.clustering.progress = staged_progress_printer(common, name);
    return settings;
}

std::string format_number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return text;
}

}  // namespace animorder::tool
