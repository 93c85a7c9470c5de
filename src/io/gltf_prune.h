// What the glTF writers (gltf_writer.cpp, gltf_extension.cpp) replaced, left out of the file they
// write: without it, every run over a file that already holds orders (optimising an optimised
// file, reapply after a pipeline) would carry the previous orders, tables and index buffers on as
// unused accessors and bytes, the file growing run after run. Internal to src/io.
#pragma once

#include <tiny_gltf.h>

#include <string>
#include <utility>
#include <vector>

namespace animorder::io {

// Where the accessors, buffer views and buffers of the model a writer read ended up in the model
// it wrote: old index -> new index, -1 for one left out; an empty list when none moved (so that
// restore_from_input in gltf_buffer.cpp can put back on each what tinygltf does not write).
struct Renumbering {
    std::vector<int> accessors, views, buffers;
};

// The accessors a writer is about to stop referring to: each primitive's `indices` in `primitives`
// (mesh, primitive) and every accessor the ANIMORDER_animated_triangle_orders extension names in
// `model` (its primitives' orders, its clips' tables and centres). Read before the writer replaces
// them.
std::vector<int> accessors_to_replace(const tinygltf::Model& model, const std::vector<std::pair<int, int>>& primitives);

// Leaves out of `model` each accessor of `replaced` that nothing refers to any more, then the
// buffer views only they used, then those views' bytes (bytes another view covers stay), then a
// buffer left without a byte that no view names (glTF forbids an empty buffer). Nothing
// else is left out, whatever else is unused. The last accessors and views move into the freed
// places (fewest indices changed) and every reference to a moved one follows it; later bytes of a
// buffer move down by multiples of 4, so every alignment holds.
//
// A model that uses an extension whose references to accessors or buffer views this does not
// know (anything beyond core glTF, the KHR material and texture extensions, KHR_mesh_quantization,
// KHR_lights_punctual, KHR_materials_variants, KHR_xmp_json_ld, KHR_animation_pointer,
// EXT_mesh_gpu_instancing, EXT_texture_webp/avif, MSFT_texture_dds and animorder's own) is left
// as it is: renumbering could break what such an extension points at. Returns false then, and
// `unknown` (when given) gets the first such extension's name; true when it pruned or had
// nothing to prune.
// `renumbering` (when given) gets where each accessor, view and buffer went.
bool drop_replaced_accessors(tinygltf::Model& model, const std::vector<int>& replaced, std::string* unknown = nullptr,
                             Renumbering* renumbering = nullptr);

// The two ends of a writer's work on the model read from `path`. begin_replacing, before it
// writes: accessors_to_replace for the primitives it rewrites, and every primitive's orders
// extension object erased (the writer names its own; stale ones on a primitive it does not
// rewrite would contradict them). finish_replacing, after: drop_replaced_accessors, and when that
// left the model as it was, `note` (when given) says why. Returns the renumbering.
std::vector<int> begin_replacing(tinygltf::Model& model, const std::vector<std::pair<int, int>>& primitives);
Renumbering finish_replacing(tinygltf::Model& model, const std::vector<int>& replaced, const std::string& path,
                             std::string* note);

}  // namespace animorder::io
