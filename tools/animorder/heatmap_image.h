// The overdraw heatmap picture (the paper's Figure 1): shaded fragments per pixel on a colour
// scale, with a legend and a caption, written as PNG.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace animorder::tool {

// counts: resolution × resolution shaded-fragment counts, row 0 at the top. 0 is background.
// Returns PNG bytes. The colour scale runs from 1 to max(max count, 4).
std::string heatmap_png(const std::vector<uint32_t>& counts, unsigned resolution, const std::string& caption);

}  // namespace animorder::tool
