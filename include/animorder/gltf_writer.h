// animorder — a glTF file with a method's orders (gltf_writer.cpp).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/methods.h"
#include "animorder/viewpoints.h"

#include <cstdint>
#include <string>

namespace animorder {

// Throws LoadError when gltf_with_orders cannot write `mesh`'s orders into `input_path`: a
// primitive not read from that file. Callers run it before the method, so that the refusal comes
// before the work. (A mesh several nodes draw is written once, from its first instance: run_method
// gives the instances one order.)
void check_gltf_output(const std::string& input_path, const AnimatedMesh& mesh);

// The glTF file `input_path` (which `mesh` was loaded from) with the method's orders in the
// ANIMORDER_animated_triangle_orders extension (docs/extension/README.md): each primitive's
// `indices` holds buffer `fallback`, its extension object names one accessor with the k orders one
// after the other, and the root extension object holds the clips' lookup tables and frame centres
// as accessors. All other content is written back unchanged; buffers are embedded; relative image
// URIs are rewritten to point, from output_path's folder, at the same files. What the orders
// replace (the drawn indices, orders an earlier run wrote) leaves the file, unless the file uses
// an extension whose references are unknown here: then it stays, and `note` (when given) says
// why. A primitive without triangles (a strip of two indices) is left as the file has it.
// Returns GLB bytes when `binary`, else glTF JSON text.
std::string gltf_with_orders(const std::string& input_path, const std::string& output_path, const AnimatedMesh& mesh,
                             const MethodBuffers& buffers, uint32_t fallback, const Framing& framing,
                             const std::string& method, bool binary, std::string* note = nullptr);

}  // namespace animorder
