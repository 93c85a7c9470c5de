// animorder — every format assimp reads (assimp_loader.cpp).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/load.h"

#include <string>
#include <vector>

namespace animorder {

// Any format assimp reads (FBX, Collada, .X, .b3d, MD5, OBJ, …): meshes in node order with their
// own vertices (identical vertices joined), bones (8 strongest weights, normalised), node
// animations sampled at sample_rate. clip_files: Mixamo-style animation-only files whose
// channels drive the character's joints by node name; each adds its animations as clips (named
// after the file), and a file none of whose joints the character has is an error. A clip file whose
// rest skeleton differs from the character's (by more than 0.1% of its size) is retargeted as
// engines do: the clip's rotations on the character's own bone offsets, root joints' translations
// scaled by the ratio of their rest offsets (hip heights), with a note naming the largest
// difference (Clip::retargeted); it is refused only when its skeleton lacks one of the character's
// skinned joints. An .md5anim is applied as it is (its baseframe is no bind pose). A mesh's vertex no bone weighs stays
// with its node. A mesh whose node transform mirrors it is flipped to counter-clockwise front
// faces (Primitive::mirrored). assimp runs in a child process, so a crash inside it is a LoadError, never a signal.
AnimatedMesh load_assimp(const std::string& path, const std::vector<std::string>& clip_files = {},
                         const LoadOptions& options = {});

}  // namespace animorder
