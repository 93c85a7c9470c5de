// Buffer views and accessors for the glTF writers (gltf_writer.cpp, gltf_animated_writer.cpp,
// gltf_extension.cpp), and a glTF file read into a tinygltf model and written back
// (gltf_buffer.cpp). Internal to src/io.
#pragma once

#include "gltf_prune.h"

#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace animorder::io {

// Appends bytes to buffer 0 (created when the model has none), 4-byte aligned, as a new buffer
// view with the given target (0: none); returns the view's index.
int append_buffer_view(tinygltf::Model& model, const void* data, size_t bytes, int target);

// Appends an accessor over buffer view `view` (from its first byte) of `count` elements of the
// given component type and type, named `name`; returns the accessor's index.
int append_accessor(tinygltf::Model& model, int view, int component, int type, size_t count, const std::string& name);

// tinygltf's file access, through RegularFile (animorder/regular_file.h): a FIFO, a device or a
// folder is never opened (FileExists is false for it: tinygltf then looks in the current folder,
// or says the file was not found), and no file larger than *user_data bytes (the loading budget)
// is read whole into memory. `limit` (that budget) must outlive the loads made with the
// callbacks.
tinygltf::FsCallbacks regular_file_callbacks(const uint64_t* limit);

// The first four bytes of a regular file ("glTF" for a GLB; fewer when it is shorter, as a
// 2-byte "[]" is, which the JSON reader then names); LoadError naming the path when it is missing,
// not a regular file, or empty.
std::string magic_of(const std::string& path);

// The JSON text of a glTF (.gltf: the file; .glb: its first chunk, which must be JSON); empty
// when the file is not a regular file or its sizes do not hold; a LoadError when the text exceeds
// 1 GiB (its external files could not be known).
std::string gltf_json_text(const std::string& path);

// LoadError when the glTF's JSON nests arrays and objects deeper than kMaxJsonDepth
// (gltf_diagnose.h; brackets inside strings do not count): tinygltf converts extension and extras
// values recursively, and some tens of thousands of levels (a 1 MB file) overflow the stack; real
// files nest a few levels. Called before tinygltf reads the file. A file whose JSON cannot be
// found is left to the loader to report.
void check_json_depth(const std::string& path);

// tinygltf's load of `path`, and its error made one line: a LoadError naming the undecodable
// extension the file requires when there is one (tinygltf then fails on its compressed bytes, or
// reads them as plain ones), else tinygltf's own message.
void finish_load(bool ok, std::string error, const tinygltf::Model& model, const std::string& path);

// glTF 2.0 lets an animation channel's target name no node (KHR_animation_pointer's animate what
// their pointer names: a material, a light, a camera). tinygltf 2.7 drops such a channel, and an
// animation left without one, renumbering the animations after it; its writer would then leave
// them out of the output. The file's JSON with a placeholder "node" put into each such target,
// kPlaceholderNode (tinygltf keeps it; the glTF loader knows it as no node, see pointed_channel;
// restore_what_tinygltf_drops takes it out again on writing), or "" when it has none (or is no
// JSON). The placeholder is no index a file could mean: a channel naming a missing node stays that.
inline constexpr int kPlaceholderNode = INT32_MAX;
std::string json_with_placeholder_nodes(const std::string& text);

// tinygltf's load of `path` into `model` (with json_with_placeholder_nodes' JSON when it has
// channels without a node; `budget` bounds the file then read whole, as the loader's file
// callbacks do), an exception it throws (a buffer of byteLength 0 makes it index an empty vector)
// taken as a failed load with that message.
bool load_gltf_file(tinygltf::TinyGLTF& loader, tinygltf::Model& model, std::string& error, std::string& warning,
                    const std::string& path, bool binary, const uint64_t* budget);

// The glTF file at `path` (binary when it starts with "glTF"), images left undecoded; LoadError
// when it is no readable glTF 2.0 file, or it or a file it references is no regular file.
tinygltf::Model read_model(const std::string& path);

// The model read from input_path as a file at output_path: buffers embedded (every buffer's URI
// cleared), relative image URIs re-pointed from output_path's folder, images never re-encoded,
// and what tinygltf drops put back (restore_from_input, through the writer's `renumbering`). GLB
// bytes when `binary`, else glTF JSON text.
std::string write_model(tinygltf::Model& model, const std::string& input_path, const std::string& output_path,
                        bool binary, const Renumbering& renumbering = {});

}  // namespace animorder::io
