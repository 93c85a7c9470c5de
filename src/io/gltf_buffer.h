// Buffer views for the glTF writers (gltf_writer.cpp, gltf_animated_writer.cpp). Internal to
// src/io.
#pragma once

#include <tiny_gltf.h>

#include <cstddef>
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

}  // namespace animorder::io
