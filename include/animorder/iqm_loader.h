// animorder — Inter-Quake Models with their skeletal animations (iqm_loader.cpp).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/load.h"

#include <string>

namespace animorder {

// Inter-Quake Models (IQM v2) with their skeletal animations (assimp reads only the mesh).
AnimatedMesh load_iqm(const std::string& path, const LoadOptions& options = {});

}  // namespace animorder
