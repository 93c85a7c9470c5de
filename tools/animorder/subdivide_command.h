// `animorder subdivide`: Loop subdivision of the input's animated mesh, written as a new glTF.
#pragma once

#include "commands.h"

#include <string>

namespace animorder::tool {

struct SubdivideOptions {
    CommonOptions common;
    unsigned levels = 1;
    std::string output;  // OUT.glb or OUT.gltf
};

int run_subdivide(const SubdivideOptions& options);

}  // namespace animorder::tool
