// animorder — the sidecar (sidecar.cpp): k index buffers and the runtime lookup tables in one little-endian
// binary that include/animorder_runtime.h reads (its comment is the format's specification).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/methods.h"
#include "animorder/viewpoints.h"

#include <cstdint>
#include <string>

namespace animorder {

// Bytes of NAME.animorder.bin: every buffer of `buffers` applied to mesh.indices, and per clip its
// table, buffer base and keyframe centres (from framing).
std::string serialize_sidecar(const AnimatedMesh& mesh, const MethodBuffers& buffers, const Framing& framing);

// Text of NAME.animorder.json: the same sidecar described for people and tools (method, buffer
// count, fallback buffer, primitives' index ranges, clips with their buffer bases and table
// grids). binary_name: the file name of the binary it describes.
std::string sidecar_json(const AnimatedMesh& mesh, const MethodBuffers& buffers, const std::string& method,
                         uint32_t fallback, const std::string& binary_name);

}  // namespace animorder
