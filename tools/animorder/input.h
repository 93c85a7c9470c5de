// What every subcommand shares: notes and progress on stderr, the input character (a file or
// the bundled one), and the method settings built from the options.
#pragma once

#include "commands.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"

#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace animorder::tool {

// Progress and notes go to stderr ("animorder: TEXT"), unless --quiet, so stdout stays clean
// for text or JSON a script may read.
void note(const CommonOptions& common, const std::string& text);

// A progress line on stderr that rewrites itself (at most two updates a second); none if --quiet.
std::function<void(size_t, size_t)> progress_printer(const CommonOptions& common, const std::string& stage);
// The same for work in stages (ClusteringSettings::progress): "PREFIX: STAGE: done/total nodes".
std::function<void(const std::string&, size_t, size_t)> staged_progress_printer(const CommonOptions& common,
                                                                                const std::string& prefix);

// Whether a --clip value names a clip file or folder (else the name of a clip to keep): never for a
// character that carries its clips (glTF, MD2, IQM, the bundled one).
bool clip_is_file(const CommonOptions& common, const std::string& clip);

// Every file a run on these options reads, as far as known before loading (files_load_reads):
// the character, a glTF's external buffers and images, the clip files and the files of clip
// folders.
std::vector<std::string> input_files(const CommonOptions& common);

// The --clip values that are folders: a run reads every file in them.
std::vector<std::string> input_folders(const CommonOptions& common);

// check_output_paths, then what killed runs left beside the outputs removed
// (remove_stale_temporaries): every command's check of its outputs before any work.
void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs,
                   const std::vector<std::string>& input_folders = {});

// check_outputs of the outputs against input_files and input_folders: called before any
// work, so that no output overwrites an input (a .gltf's .bin, a clip file) or lands in a clip
// folder, whichever subcommand writes it. Then what killed runs left beside the outputs is
// removed (remove_stale_temporaries).
void check_outputs_before_loading(const std::vector<std::string>& outputs, const CommonOptions& common);

// The input named on the command line (or the bundled character, saying so). --clip values that
// exist on disk are clip files or folders (Mixamo style) (clip_is_file); the others name the clips to keep.
// files_read, when given, receives every file the load read (LoadOptions::files_read).
AnimatedMesh load_animated_input(const CommonOptions& common, std::string& input_name,
                                 std::vector<std::string>* files_read = nullptr);

// load_animated_input's mesh, validated, and refused when it has nothing to draw (every
// triangle of zero area at every keyframe).
AnimatedMesh load_drawable_input(const CommonOptions& common, std::string& input_name,
                                 std::vector<std::string>* files_read = nullptr);

// `work` on the character loaded from common.input: an InvalidInput it throws (an algorithm's word
// on the character: a corner too far for float clip coordinates, say) names the file, as the
// loaders' errors do. The options were checked before loading, so such an error is about the file.
template <typename Work>
auto about_input(const CommonOptions& common, Work&& work) -> decltype(work()) {
    try {
        return work();
    } catch (const InvalidInput& e) {
        if (common.input.empty()) throw;
        throw std::runtime_error(common.input + ": " + e.what());
    }
}

// The library's settings for one method from the options (names of the k-means variants
// parsed, --cache-size, log and progress lines on stderr labelled with the method's name).
MethodSettings method_settings(const MethodOptions& options, const CommonOptions& common, Method method);

// Numbers in labels and tables: the shortest form that reads back the same ("0.85", "3").
std::string format_number(double value);

}  // namespace animorder::tool
