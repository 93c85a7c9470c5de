// Buffer views for the glTF writers (gltf_writer.cpp, gltf_animated_writer.cpp). Internal to
// src/io.
#pragma once

#include "animorder/load.h"

#include <tiny_gltf.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace animorder::io {

// Appends bytes to buffer 0 (created when the model has none), 4-byte aligned, as a new buffer
// view with the given target (0: none); returns the view's index.
inline int append_buffer_view(tinygltf::Model& model, const void* data, size_t bytes, int target) {
    if (model.buffers.empty()) model.buffers.emplace_back();
    std::vector<unsigned char>& buffer = model.buffers[0].data;
    while (buffer.size() % 4) buffer.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = bytes;
    view.target = target;
    const unsigned char* p = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), p, p + bytes);
    model.bufferViews.push_back(view);
    return int(model.bufferViews.size() - 1);
}

// tinygltf's file access, but to regular files only, checked on the open file (O_NONBLOCK, then
// fstat): a FIFO or a device never ends, and a file swapped for one after a check must not hang
// the read. For a missing or irregular file, FileExists is false (tinygltf then looks elsewhere or
// says the file was not found).
inline bool regular_file_exists(const std::string& path, void*) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

inline bool read_regular_file(std::vector<unsigned char>* out, std::string* error, const std::string& path, void*) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st {};
    const bool regular = fd >= 0 && ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
    size_t got = 0;
    if (regular) {
        out->resize(size_t(st.st_size));
        while (got < out->size()) {
            const ssize_t n = ::read(fd, out->data() + got, out->size() - got);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            got += size_t(n);
        }
    }
    if (fd >= 0) ::close(fd);
    const char* why = fd < 0               ? "cannot open"
                      : !regular           ? "not a regular file"
                      : got != out->size() ? "cannot read all of"
                      : out->empty()       ? "empty file"
                                           : nullptr;
    if (why && error) *error += std::string(why) + " : " + path + "\n";
    return !why;
}

inline tinygltf::FsCallbacks regular_file_callbacks() {
    return {regular_file_exists, tinygltf::ExpandFilePath, read_regular_file, tinygltf::WriteWholeFile, nullptr};
}

// The glTF file at `path` (binary when it starts with "glTF"), images left undecoded; LoadError
// when it is no readable glTF 2.0 file, or it or a file it references is no regular file.
inline tinygltf::Model read_model(const std::string& path) {
    require_regular_files(path);
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks(regular_file_callbacks());
    loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*,
                             int, void*) { return true; },
                          nullptr);
    std::string error, warning;
    std::string magic(4, '\0');
    if (FILE* f = std::fopen(path.c_str(), "rb")) {
        if (std::fread(magic.data(), 1, 4, f) != 4) magic.clear();
        std::fclose(f);
    }
    const bool ok = magic == "glTF" ? loader.LoadBinaryFromFile(&model, &error, &warning, path)
                                    : loader.LoadASCIIFromFile(&model, &error, &warning, path);
    if (!ok) {
        for (char& c : error)
            if (c == '\n' || c == '\r') c = ' ';
        throw LoadError(path + ": not a readable glTF 2.0 file: " + error);
    }
    return model;
}

// The model read from input_path as a file at output_path: buffers embedded (every buffer's URI
// cleared), relative image URIs re-pointed from output_path's folder, images never re-encoded.
// GLB bytes when `binary`, else glTF JSON text.
inline std::string write_model(tinygltf::Model& model, const std::string& input_path, const std::string& output_path,
                               bool binary) {
    for (tinygltf::Buffer& b : model.buffers) b.uri.clear();
    namespace fs = std::filesystem;
    const fs::path from = fs::absolute(fs::path(input_path)).parent_path();
    const fs::path to = fs::absolute(fs::path(output_path)).parent_path();
    for (tinygltf::Image& image : model.images)
        if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0 && image.uri.find("://") == std::string::npos &&
            fs::path(image.uri).is_relative() && from != to)
            image.uri = fs::relative(from / image.uri, to).generic_string();
    tinygltf::TinyGLTF writer;
    writer.SetImageWriter(
        [](const std::string*, const std::string*, const tinygltf::Image* image, bool, std::string* uri, void*) {
            *uri = image->uri;  // never decoded, never rewritten: external images keep their URIs
            return true;
        },
        nullptr);
    std::ostringstream out;
    if (!writer.WriteGltfSceneToStream(&model, out, !binary, binary))
        throw LoadError(input_path + ": writing the glTF output failed");
    return out.str();
}

}  // namespace animorder::io
