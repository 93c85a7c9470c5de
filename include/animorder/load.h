// animorder — reading characters from files into the AnimatedMesh every algorithm takes (load.cpp):
// the error and options every loader shares, and the loader chosen by file extension.
#pragma once

#include "animorder/animated_mesh.h"

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace animorder {

// Thrown for a file that cannot be read as asked: what() starts with the file name and says
// what is wrong, in one line.
class LoadError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct LoadOptions {
    double sample_rate = 30;  // keyframes per second of every clip (DESIGN.md)
    // Budget for the sampled animation: keyframes × vertices × 12 bytes of positions. A file
    // whose clips would need more fails with a LoadError naming the need and this budget before
    // anything that size is allocated (`--max-memory` raises it). No file a loader reads whole
    // (a glTF buffer, an assimp file) may be larger than file_budget(): this, or its default when
    // that is more.
    size_t max_keyframe_bytes = size_t(4) << 30;
    size_t file_budget() const { return std::max(max_keyframe_bytes, LoadOptions{}.max_keyframe_bytes); }
    // Clips to sample, by name; empty: every clip. A hint that saves the sampling (and memory) of
    // the others: glTF files honour it when every name is one of the file's clips (otherwise all
    // are sampled, so that select_clips names the file's clips in its error); other formats
    // sample every clip. Callers still call select_clips for the order and the error.
    std::vector<std::string> clips;
    // Threads that evaluate the keyframes (glTF files; 0: all cores). The keyframes are the same
    // bits whatever the count.
    unsigned threads = 0;
    // When set, receives every file the load read: files_load_reads' and the side files an
    // importer opened or looked for as it read (an OBJ's .mtl, found or not), each once, in the
    // order first met.
    std::vector<std::string>* files_read = nullptr;
    // Processor time a third-party parser (assimp) may spend on one file: this many seconds, plus
    // as many again per MiB of the file; a file that makes it loop is then stopped with a
    // LoadError, not waited on for ever (isolated_import.h).
    double parse_seconds = 20;
};

// A file name's extension in lower case (".glb" for "Hero.GLB"): what load_character dispatches on,
// so that a caller deciding by extension (glTF output or not, a manifest's format) agrees with it.
std::string file_extension(const std::string& path);

// Whether a file of this name carries its own clips (glTF, MD2, IQM), so that clip files do not
// apply to it (load_character refuses them): a clip given for it is a clip name.
bool carries_its_clips(const std::string& path);

// By extension: .gltf/.glb → load_gltf (gltf_loader.h), .md2 → load_md2, .iqm → load_iqm (no
// clip files), anything else → load_assimp. A folder in
// clip_files stands for the files in it, in name order. Throws LoadError when a file it would
// read exists but is not a regular file (require_regular_files).
AnimatedMesh load_character(const std::string& path, const std::vector<std::string>& clip_files = {},
                            const LoadOptions& options = {});

// The files load_character(path, clip_files) reads, as far as they are known before loading: the
// file; for .gltf/.glb its external buffers and images, by URI, resolved as the glTF loader
// resolves them (percent-decoded, '+' a space; beside the file, else in the current folder when
// only there; empty URIs and the data URIs tinygltf decodes name no file); each clip file, and
// the files of each clip folder in name order. Not the side files an assimp format may open as it
// reads (an OBJ's .mtl). Reads only the glTF's JSON, from a regular file; a file it cannot parse
// lists no external file (loading it says what is wrong). LoadError for a clip folder that cannot
// be listed or is empty, or glTF JSON over 1 GiB.
std::vector<std::string> files_load_reads(const std::string& path, const std::vector<std::string>& clip_files = {});

// A .gltf's or .glb's external buffers and images, each by its URI as the file writes it and the
// file files_load_reads resolves it to, in the file's order (buffers, then images).
struct ExternalFile {
    std::string uri, file;
};
std::vector<ExternalFile> gltf_external_uris(const std::string& path);

// Appends to files_read those of `more` it does not hold yet, in order (LoadOptions::files_read).
void add_files_read(std::vector<std::string>& files_read, const std::vector<std::string>& more);

// Throws LoadError when a file of files_load_reads(path, clip_files) exists but is not a regular
// file: a FIFO or a device (a glTF buffer URI of /dev/zero) would never end, a folder is no file.
// Missing files are left to the loaders, which name them.
void require_regular_files(const std::string& path, const std::vector<std::string>& clip_files = {});

}  // namespace animorder
