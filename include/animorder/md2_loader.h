// animorder — Quake II MD2 with every frame (md2_loader.cpp).
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/load.h"

#include <string>

namespace animorder {

// Quake II MD2 with every frame (assimp reads only the first): frames grouped into clips by name
// ("run1".."run6" → "run"), played at MD2's 10 frames per second and resampled at sample_rate.
AnimatedMesh load_md2(const std::string& path, const LoadOptions& options = {});

}  // namespace animorder
