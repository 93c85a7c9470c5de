// animorder — the sidecar: k index buffers and the runtime lookup tables in one little-endian
// binary that include/animorder_runtime.h reads (its comment is the format's specification).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/clustering.h"
#include "animorder/evaluation.h"
#include "animorder/overdraw.h"

#include <string>

namespace animorder {

// Bytes of NAME.animorder.bin: every buffer of `buffers` applied to mesh.indices, and per clip its
// table, buffer base and keyframe centres (from framing).
std::string serialize_sidecar(const AnimatedMesh& mesh, const MethodBuffers& buffers, const Framing& framing);

}  // namespace animorder
